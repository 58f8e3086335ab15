//! The TOML scene manifest, and the staging of a bare model file into one.
//!
//! A manifest names model files (or built-in primitives) with their transforms
//! and roles, the lights, and optionally the camera. The project's docs/scenes.md documents the
//! format with a complete example; [`Manifest::to_toml`] writes one back.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{EulerRot, Mat4, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::error::{Result, SceneError};
use crate::light::RectLight;
use crate::loaders::load_model;
use crate::primitives::{cuboid, plane, sphere};
use crate::scene::{Aabb, Instance, Role, Scene};

/// A parsed manifest file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The camera; when absent, the first camera of a glTF model, else one framing the scene.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraSpec>,
    /// The lights; at least one.
    #[serde(default, rename = "light")]
    pub lights: Vec<LightSpec>,
    /// The objects; at least one.
    #[serde(default, rename = "object")]
    pub objects: Vec<ObjectSpec>,
}

/// `[camera]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position.
    pub position: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Up direction; default +Y.
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view in degrees; default 45.
    #[serde(default = "default_fov")]
    pub fov_y_degrees: f32,
    /// Near clip distance; default from the scene's size.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub near: Option<f32>,
    /// Far clip distance; default from the scene's size.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub far: Option<f32>,
}

/// `[[light]]`: a rectangle facing `normal`, `size` = full width and height (`[0, 0]`: point light).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Centre of the rectangle.
    pub centre: [f32; 3],
    /// Direction the light faces (emits towards).
    pub normal: [f32; 3],
    /// Direction of the first side; default: world X (or Z when X is parallel to `normal`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub u_axis: Option<[f32; 3]>,
    /// Full width and height.
    pub size: [f32; 2],
    /// Intensity; default 1.
    #[serde(default = "default_intensity")]
    pub intensity: f32,
    /// Linear RGB colour of the light in the shaded image; default white, `[1, 1, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour: Option<[f32; 3]>,
}

/// `[[object]]`: a model file or a primitive, placed and given a role.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Model file, relative to the manifest (`.gltf`, `.glb`, `.obj`, `.ply`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<PathBuf>,
    /// Built-in primitive instead of a file: `plane` (size `[w, d]`, in XZ facing +Y),
    /// `box` (size `[x, y, z]`), `sphere` (size `[radius]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub primitive: Option<String>,
    /// Primitive size, see `primitive`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub size: Vec<f32>,
    /// Role of every mesh of the object; default `both`.
    #[serde(default)]
    pub role: Role,
    /// Per-node (or per-mesh) role overrides, by name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub roles: BTreeMap<String, Role>,
    /// Translation, applied last.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub translate: [f32; 3],
    /// Rotation in degrees about X, then Y, then Z.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rotate_degrees: [f32; 3],
    /// Scale: one number or one per axis, applied first.
    #[serde(default, skip_serializing_if = "Scale::is_one")]
    pub scale: Scale,
}

/// A uniform or per-axis scale.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Scale {
    /// Same on every axis.
    Uniform(f32),
    /// Per axis.
    PerAxis([f32; 3]),
}

impl Default for Scale {
    fn default() -> Self {
        Self::Uniform(1.0)
    }
}

impl Scale {
    fn vector(self) -> Vec3 {
        match self {
            Self::Uniform(s) => Vec3::splat(s),
            Self::PerAxis(s) => Vec3::from_array(s),
        }
    }

    fn is_one(&self) -> bool {
        self.vector() == Vec3::ONE
    }
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f32 {
    45.0
}
fn default_intensity() -> f32 {
    1.0
}
fn is_zero(v: &[f32; 3]) -> bool {
    *v == [0.0; 3]
}

impl ObjectSpec {
    fn transform(&self) -> Mat4 {
        let [x, y, z] = self.rotate_degrees.map(f32::to_radians);
        Mat4::from_scale_rotation_translation(
            self.scale.vector(),
            Quat::from_euler(EulerRot::XYZ, x, y, z),
            Vec3::from_array(self.translate),
        )
    }
}

impl Manifest {
    /// Parses manifest text; `file` is only used in messages.
    ///
    /// # Errors
    /// [`SceneError::Malformed`] with the TOML parser's line and column.
    pub fn parse(text: &str, file: &Path) -> Result<Self> {
        toml::from_str(text).map_err(|e| SceneError::Malformed { file: file.into(), format: "manifest", message: e.to_string() })
    }

    /// Reads and parses a manifest file.
    ///
    /// # Errors
    /// As [`Manifest::parse`], plus [`SceneError::Io`].
    pub fn read(file: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(file).map_err(|source| SceneError::Io { file: file.into(), source })?;
        Self::parse(&text, file)
    }

    /// The manifest as TOML text.
    #[must_use]
    pub fn to_toml(&self) -> String {
        // Serialising plain structs of numbers, strings and maps cannot fail.
        toml::to_string(self).unwrap_or_default()
    }

    /// Builds and validates the scene; model paths are resolved against `base_dir`.
    /// `origin` names the manifest in messages.
    ///
    /// # Errors
    /// Any loader or validation error, naming the manifest or the model file and the element.
    pub fn build(&self, origin: &Path, base_dir: &Path) -> Result<Scene> {
        let invalid = |element: String, problem: String| SceneError::InvalidManifest { file: origin.into(), element, problem };
        if self.objects.is_empty() {
            return Err(SceneError::EmptyScene { file: origin.into(), what: "the manifest has no [[object]]" });
        }
        if self.lights.is_empty() {
            return Err(SceneError::EmptyScene { file: origin.into(), what: "the manifest has no [[light]]" });
        }
        let mut scene = Scene {
            origin: origin.into(),
            meshes: Vec::new(),
            instances: Vec::new(),
            lights: Vec::new(),
            camera: Camera { position: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y: 1.0, near: 0.1, far: 10.0 },
        };
        let mut file_camera = None;
        for (index, object) in self.objects.iter().enumerate() {
            let element = format!("object {index}");
            let transform = object.transform();
            if !transform.is_finite() {
                return Err(invalid(element, "translate, rotate_degrees or scale is not finite".into()));
            }
            match (&object.model, &object.primitive) {
                (Some(model), None) => {
                    let path = base_dir.join(model);
                    let loaded = load_model(&path)?;
                    file_camera = file_camera.or_else(|| loaded.cameras.first().copied());
                    for name in object.roles.keys() {
                        let known = loaded.placements.iter().any(|p| &p.node_name == name || &loaded.meshes[p.mesh].name == name);
                        if !known {
                            return Err(invalid(element, format!("roles: `{name}` names no node or mesh in {}", path.display())));
                        }
                    }
                    let first_mesh = scene.meshes.len();
                    for placement in &loaded.placements {
                        let mesh_name = &loaded.meshes[placement.mesh].name;
                        let role =
                            object.roles.get(&placement.node_name).or_else(|| object.roles.get(mesh_name)).copied().unwrap_or(object.role);
                        scene.instances.push(Instance {
                            name: placement.node_name.clone(),
                            mesh: first_mesh + placement.mesh,
                            transform: transform * placement.transform,
                            role,
                        });
                    }
                    scene.meshes.extend(loaded.meshes);
                }
                (None, Some(kind)) => {
                    let mesh = primitive(kind, &object.size).map_err(|problem| invalid(element.clone(), problem))?;
                    scene.meshes.push(mesh);
                    scene.instances.push(Instance {
                        name: format!("{kind}-{index}"),
                        mesh: scene.meshes.len() - 1,
                        transform,
                        role: object.role,
                    });
                }
                _ => {
                    return Err(invalid(element, "give exactly one of `model` and `primitive`".into()));
                }
            }
        }
        for (index, light) in self.lights.iter().enumerate() {
            let normal = Vec3::from_array(light.normal);
            let u_hint =
                light.u_axis.map(Vec3::from_array).unwrap_or(if normal.normalize_or_zero().x.abs() > 0.9 { Vec3::Z } else { Vec3::X });
            let built =
                RectLight::try_facing(Vec3::from_array(light.centre), normal, u_hint, Vec2::from_array(light.size), light.intensity)
                    .ok_or_else(|| SceneError::InvalidLight {
                        file: origin.into(),
                        index,
                        problem: "normal is zero or not finite, or u_axis is parallel to it".into(),
                    })?;
            scene.lights.push(built.with_colour(light.colour.map_or(Vec3::ONE, Vec3::from_array)));
        }
        for mesh in &scene.meshes {
            mesh.validate(origin)?;
        }
        let bounds = scene.bounds();
        scene.camera = match (&self.camera, file_camera) {
            (Some(spec), _) => {
                let framed = framing_camera(&bounds, spec.fov_y_degrees.to_radians());
                Camera {
                    position: Vec3::from_array(spec.position),
                    target: Vec3::from_array(spec.target),
                    up: Vec3::from_array(spec.up),
                    fov_y: spec.fov_y_degrees.to_radians(),
                    near: spec.near.unwrap_or(framed.near),
                    far: spec.far.unwrap_or(framed.far.max(distance_to_far_corner(&bounds, Vec3::from_array(spec.position)))),
                }
            }
            (None, Some(camera)) => camera,
            (None, None) => framing_camera(&bounds, 45f32.to_radians()),
        };
        scene.validate()?;
        Ok(scene)
    }
}

fn primitive(kind: &str, size: &[f32]) -> std::result::Result<crate::mesh::Mesh, String> {
    let positive = size.iter().all(|s| s.is_finite() && *s > 0.0);
    match (kind, size) {
        ("plane", [w, d]) if positive => Ok(plane("plane", Vec2::new(*w, *d))),
        ("box", [x, y, z]) if positive => Ok(cuboid("box", Vec3::new(*x, *y, *z))),
        ("sphere", [r]) if positive => Ok(sphere("sphere", *r, 48, 24)),
        ("plane" | "box" | "sphere", _) => Err(format!(
            "primitive `{kind}` needs size {} of positive numbers, got {size:?}",
            match kind {
                "plane" => "[width, depth]",
                "box" => "[x, y, z]",
                _ => "[radius]",
            }
        )),
        _ => Err(format!("unknown primitive `{kind}` (plane, box, sphere)")),
    }
}

fn distance_to_far_corner(bounds: &Aabb, from: Vec3) -> f32 {
    bounds.corners().iter().map(|c| c.distance(from)).fold(0.0, f32::max) * 1.5
}

/// A camera looking at the bounds from the front and above, with the whole box in view.
#[must_use]
pub fn framing_camera(bounds: &Aabb, fov_y: f32) -> Camera {
    let radius = (bounds.size().length() * 0.5).max(1e-3);
    let distance = radius / (fov_y * 0.5).sin() * 1.05;
    let direction = Vec3::new(0.0, 0.6, 1.0).normalize();
    let target = bounds.centre();
    Camera { position: target + direction * distance, target, up: Vec3::Y, fov_y, near: distance * 0.01, far: distance + radius * 3.0 }
}

/// Stages a bare model: the model as a `both` object, a receiver plane under
/// it, a square light above and to one side of it (so that the shadow falls
/// beside the model, where the camera sees it) and a camera framing the model
/// and the ground around it. Print it with [`Manifest::to_toml`] to save and edit.
///
/// Assumes +Y is up, as in the Stanford scans and most glTF files. The model
/// path is written as its file name: save the manifest beside the model.
///
/// # Errors
/// Any error loading the model.
pub fn stage_model(model: &Path) -> Result<Manifest> {
    let loaded = load_model(model)?;
    let mut bounds = Aabb::EMPTY;
    for placement in &loaded.placements {
        for &p in &loaded.meshes[placement.mesh].positions {
            bounds.extend(placement.transform.transform_point3(p));
        }
    }
    if bounds.is_empty() || !bounds.size().is_finite() {
        return Err(SceneError::EmptyScene { file: model.into(), what: "the model has no placed geometry" });
    }
    let extent = bounds.size().max_element().max(1e-3);
    let centre = bounds.centre();
    let light_centre = Vec3::new(centre.x + 0.6 * extent, bounds.max.y + 1.5 * extent, centre.z + 0.4 * extent);
    // The light faces the model's centre.
    let light_normal = (centre - light_centre).normalize();
    // Frame the model with half its size of ground on every side.
    let mut view = bounds;
    view.extend(Vec3::new(bounds.min.x - 0.5 * extent, bounds.min.y, bounds.min.z - 0.5 * extent));
    view.extend(Vec3::new(bounds.max.x + 0.5 * extent, bounds.min.y, bounds.max.z + 0.5 * extent));
    let camera = framing_camera(&view, 45f32.to_radians());
    let file_name = model.file_name().map_or_else(|| model.to_path_buf(), PathBuf::from);
    let object = |model: Option<PathBuf>, primitive: Option<String>, size: Vec<f32>, role: Role, translate: [f32; 3]| ObjectSpec {
        model,
        primitive,
        size,
        role,
        roles: BTreeMap::new(),
        translate,
        rotate_degrees: [0.0; 3],
        scale: Scale::default(),
    };
    Ok(Manifest {
        camera: Some(CameraSpec {
            position: camera.position.to_array(),
            target: camera.target.to_array(),
            up: [0.0, 1.0, 0.0],
            fov_y_degrees: 45.0,
            near: Some(camera.near),
            far: Some(camera.far),
        }),
        lights: vec![LightSpec {
            centre: light_centre.to_array(),
            normal: light_normal.to_array(),
            u_axis: Some([1.0, 0.0, 0.0]),
            size: [0.3 * extent; 2],
            intensity: 1.0,
            colour: None,
        }],
        objects: vec![
            object(Some(file_name), None, Vec::new(), Role::Both, [0.0; 3]),
            // Slightly below the model's lowest point, so that a model resting on the ground touches it without z-fighting.
            object(
                None,
                Some("plane".into()),
                vec![3.0 * extent, 3.0 * extent],
                Role::Receiver,
                [centre.x, bounds.min.y - 1e-4 * extent, centre.z],
            ),
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXAMPLE: &str = r#"
[camera]
position = [0.0, 5.0, 6.0]
target = [0.0, 0.0, 0.0]
fov_y_degrees = 45.0

[[light]]
centre = [0.0, 4.0, 0.0]
normal = [0.0, -1.0, 0.0]
size = [1.0, 1.0]

[[object]]
primitive = "plane"
size = [8.0, 8.0]
role = "receiver"

[[object]]
primitive = "box"
size = [1.0, 0.1, 1.0]
translate = [0.0, 2.0, 0.0]
rotate_degrees = [0.0, 45.0, 0.0]
scale = 0.5
role = "occluder"
"#;

    #[test]
    fn manifest_round_trips_through_toml() {
        let manifest = Manifest::parse(EXAMPLE, Path::new("m.toml")).unwrap();
        let again = Manifest::parse(&manifest.to_toml(), Path::new("m.toml")).unwrap();
        assert_eq!(manifest, again);
        let scene = manifest.build(Path::new("m.toml"), Path::new(".")).unwrap();
        assert_eq!(scene.instances.len(), 2);
        assert_eq!(scene.instances[1].role, Role::Occluder);
        assert!((scene.lights[0].normal() + Vec3::Y).length() < 1e-6);
        let occluder = scene.bounds_where(|r| r == Role::Occluder);
        assert!((occluder.centre() - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-5);
        // The box is 1 wide, scaled by 0.5 and turned 45° about Y: its half-diagonal is 0.5·√2/2.
        assert!((occluder.max.x - 0.25 * std::f32::consts::SQRT_2).abs() < 1e-4, "{}", occluder.max.x);
        assert_eq!(scene.lights[0].colour, Vec3::ONE, "white unless given");
        let orange = EXAMPLE.replace("size = [1.0, 1.0]", "size = [1.0, 1.0]\ncolour = [1.0, 0.5, 0.25]");
        let manifest = Manifest::parse(&orange, Path::new("m.toml")).unwrap();
        assert_eq!(manifest, Manifest::parse(&manifest.to_toml(), Path::new("m.toml")).unwrap());
        assert_eq!(manifest.build(Path::new("m.toml"), Path::new(".")).unwrap().lights[0].colour, Vec3::new(1.0, 0.5, 0.25));
    }

    #[test]
    fn manifest_errors_name_the_element() {
        let bad = EXAMPLE.replace("primitive = \"box\"", "primitive = \"cone\"");
        let err = Manifest::parse(&bad, Path::new("m.toml")).unwrap().build(Path::new("m.toml"), Path::new(".")).unwrap_err();
        assert!(err.to_string().contains("m.toml") && err.to_string().contains("object 1") && err.to_string().contains("cone"), "{err}");

        let err = Manifest::parse("[[light]]\ncentre = [0, 1]\n", Path::new("m.toml")).unwrap_err();
        assert!(matches!(err, SceneError::Malformed { format: "manifest", .. }), "{err}");

        let err = Manifest::parse("[[object]]\nprimitive = \"plane\"\nsize=[1,1]\ncolour = 3\n", Path::new("m.toml")).unwrap_err();
        assert!(err.to_string().contains("colour"), "{err}");

        let no_light = EXAMPLE.split("[[light]]").next().unwrap().to_owned() + "[[object]]\nprimitive = \"plane\"\nsize = [1.0, 1.0]\n";
        let err = Manifest::parse(&no_light, Path::new("m.toml")).unwrap().build(Path::new("m.toml"), Path::new(".")).unwrap_err();
        assert!(matches!(err, SceneError::EmptyScene { .. }), "{err}");

        let zero_normal = EXAMPLE.replace("normal = [0.0, -1.0, 0.0]", "normal = [0.0, 0.0, 0.0]");
        let err = Manifest::parse(&zero_normal, Path::new("m.toml")).unwrap().build(Path::new("m.toml"), Path::new(".")).unwrap_err();
        assert!(matches!(err, SceneError::InvalidLight { index: 0, .. }), "{err}");

        let dark_red = EXAMPLE.replace("size = [1.0, 1.0]", "size = [1.0, 1.0]\ncolour = [1.0, -0.5, 0.0]");
        let err = Manifest::parse(&dark_red, Path::new("m.toml")).unwrap().build(Path::new("m.toml"), Path::new(".")).unwrap_err();
        assert!(matches!(err, SceneError::InvalidLight { index: 0, .. }) && err.to_string().contains("colour"), "{err}");

        let nan_light = EXAMPLE.replace("size = [1.0, 1.0]", "size = [nan, 1.0]");
        let err = Manifest::parse(&nan_light, Path::new("m.toml")).unwrap().build(Path::new("m.toml"), Path::new(".")).unwrap_err();
        assert!(matches!(err, SceneError::InvalidLight { .. }), "{err}");
    }
}
