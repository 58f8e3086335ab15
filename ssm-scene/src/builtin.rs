//! Procedural scenes that need no files: the analytic case and the classic stress cases.

use std::path::PathBuf;

use glam::{Mat4, Quat, Vec2, Vec3};

use crate::camera::Camera;
use crate::error::{Result, SceneError};
use crate::light::RectLight;
use crate::mesh::Mesh;
use crate::primitives::{cuboid, plane, sphere};
use crate::scene::{Instance, Role, Scene};

/// A built-in scene's name, what it exercises, and its parameters.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinScene {
    /// Name used on the command line.
    pub name: &'static str,
    /// One line saying what it is and what it tests.
    pub summary: &'static str,
    /// Its parameters, set as `name:param=value,param=value` (none for most scenes).
    pub params: &'static [BuiltinParam],
    build: fn(&BuiltinArgs) -> Scene,
}

/// One numeric parameter of a built-in scene.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinParam {
    /// Its name.
    pub name: &'static str,
    /// What it sets.
    pub doc: &'static str,
    /// Its value when not set.
    pub default: f64,
    /// Smallest accepted value.
    pub min: f64,
    /// Largest accepted value.
    pub max: f64,
}

/// The values of a built-in scene's parameters for one build.
#[derive(Clone, Debug, PartialEq)]
pub struct BuiltinArgs {
    values: Vec<(&'static str, f64)>,
}

impl BuiltinArgs {
    /// The value of `name`.
    ///
    /// # Panics
    /// If the scene declares no such parameter (a bug in the scene's builder).
    #[must_use]
    pub fn get(&self, name: &str) -> f64 {
        self.values.iter().find(|(n, _)| *n == name).map(|(_, v)| *v).unwrap_or_else(|| panic!("undeclared built-in parameter `{name}`"))
    }
}

impl BuiltinScene {
    /// Builds the scene with its default parameters.
    #[must_use]
    pub fn build(&self) -> Scene {
        (self.build)(&self.defaults())
    }

    /// The default value of every parameter.
    #[must_use]
    pub fn defaults(&self) -> BuiltinArgs {
        BuiltinArgs { values: self.params.iter().map(|p| (p.name, p.default)).collect() }
    }

    /// Builds the scene with `assignments` (`param=value`, comma-separated; empty: the defaults).
    /// The scene's origin records the assignments, `builtin:<name>:<assignments>`.
    ///
    /// # Errors
    /// As [`BuiltinScene::args`].
    pub fn build_with(&self, assignments: &str) -> Result<Scene> {
        let args = self.args(assignments)?;
        let mut scene = (self.build)(&args);
        if !assignments.trim().is_empty() {
            scene.origin = PathBuf::from(format!("builtin:{}:{}", self.name, assignments.trim()));
        }
        Ok(scene)
    }

    /// The parameter values `assignments` (`param=value`, comma-separated) give, over the
    /// defaults; a parameter assigned twice takes its last value. Checks without building.
    ///
    /// # Errors
    /// [`SceneError::BuiltinParameter`] for an unknown parameter, a value that is not a finite
    /// number, or one outside the parameter's range.
    pub fn args(&self, assignments: &str) -> Result<BuiltinArgs> {
        let problem = |problem: String| SceneError::BuiltinParameter { scene: format!("{}:{assignments}", self.name), problem };
        let mut args = self.defaults();
        for assignment in assignments.split(',').map(str::trim).filter(|a| !a.is_empty()) {
            let Some((name, value)) = assignment.split_once('=') else {
                return Err(problem(format!("`{assignment}` is not `param=value`")));
            };
            let known = || self.params.iter().map(|p| p.name).collect::<Vec<_>>().join(", ");
            let Some(param) = self.params.iter().find(|p| p.name == name.trim()) else {
                let known = if self.params.is_empty() { "none".to_owned() } else { known() };
                return Err(problem(format!("unknown parameter `{}`; its parameters: {known}", name.trim())));
            };
            let value: f64 = value.trim().parse().map_err(|_| problem(format!("{}: `{}` is not a number", param.name, value.trim())))?;
            if !value.is_finite() || value < param.min || value > param.max {
                return Err(problem(format!("{} = {value} is outside {}..={}", param.name, param.min, param.max)));
            }
            if let Some(slot) = args.values.iter_mut().find(|(n, _)| *n == param.name) {
                slot.1 = value;
            }
        }
        Ok(args)
    }
}

/// A built-in scene from `name` or `name:param=value,...`; `None` when the name before the colon
/// is no built-in scene's (a file path, say).
///
/// # Errors
/// As [`BuiltinScene::build_with`].
pub fn parse_builtin(spec: &str) -> Option<Result<(&'static BuiltinScene, Scene)>> {
    let (name, assignments) = spec.split_once(':').unwrap_or((spec, ""));
    let entry = BUILTIN_SCENES.iter().find(|s| s.name == name)?;
    Some(entry.build_with(assignments).map(|scene| (entry, scene)))
}

/// Every built-in scene, in a stable order.
pub const BUILTIN_SCENES: &[BuiltinScene] = &[
    BuiltinScene {
        name: "parallel-square",
        summary: "1x1 square light at y=4, 1x1 occluder square at y=2, 8x8 receiver at y=0: the analytic case of Atty et al. (Sec. 5.2)",
        params: &[],
        build: |_| parallel_square(),
    },
    BuiltinScene {
        name: "floating-sphere",
        summary: "a closed sphere floating above a receiver plane",
        params: &[
            BuiltinParam { name: "segments", doc: "segments around the sphere", default: 48.0, min: 3.0, max: 2048.0 },
            BuiltinParam {
                name: "rings",
                doc: "rings from pole to pole (2·segments·(rings − 1) triangles; 4 and 3 give 16, 512 and 256 give 261,632)",
                default: 24.0,
                min: 2.0,
                max: 2048.0,
            },
        ],
        build: floating_sphere,
    },
    BuiltinScene {
        name: "contact",
        summary: "a box and a sphere resting on the plane: contact hardening, occluder touching receiver",
        params: &[],
        build: |_| contact(),
    },
    BuiltinScene {
        name: "sphere-cube",
        summary: "a 5x5x5 cube of small spheres above a plane: overlapping penumbrae (Forest et al., Fig. 1)",
        params: &[
            BuiltinParam {
                name: "spheres",
                doc: "spheres along each side of the cube, 0.3 apart (the cube grows)",
                default: 5.0,
                min: 1.0,
                max: 40.0,
            },
            BuiltinParam { name: "segments", doc: "segments around each sphere", default: 16.0, min: 3.0, max: 256.0 },
            BuiltinParam {
                name: "rings",
                doc: "rings from pole to pole of each sphere (2·segments·(rings − 1) triangles; 20 and 20 give Forest et al.'s 760)",
                default: 8.0,
                min: 2.0,
                max: 256.0,
            },
        ],
        build: sphere_cube,
    },
    BuiltinScene {
        name: "leaves",
        summary: "300 thin quads at varied heights over the ground: occluder fusion and depth discontinuities (Buades et al.'s plant)",
        params: &[],
        build: |_| leaves(),
    },
    BuiltinScene {
        name: "bar-grid",
        summary: "70 thin bars 0.1 apart, parallel to a large floor under a small light, the camera low and looking along it: high-frequency hard shadows that alias in the distance (Shen et al., Fig. 11)",
        params: &[],
        build: |_| bar_grid(),
    },
    BuiltinScene {
        name: "forest",
        summary: "instanced trees (a trunk and a crown of leaf cards) on a grid over the ground, the triangle count a parameter: a large, complex scene (Shen et al., Table 2)",
        params: &[
            BuiltinParam {
                name: "triangles",
                doc: "triangles in all, ground included (leaf cards are added to reach it)",
                default: 20_000.0,
                min: 100.0,
                max: 20_000_000.0,
            },
            BuiltinParam { name: "trees", doc: "trees, on a square grid 2 units apart", default: 16.0, min: 1.0, max: 4096.0 },
        ],
        build: forest,
    },
];

/// Looks up a built-in scene by name.
///
/// # Errors
/// [`SceneError::UnknownBuiltin`] listing the names that exist.
pub fn builtin(name: &str) -> Result<&'static BuiltinScene> {
    BUILTIN_SCENES.iter().find(|s| s.name == name).ok_or_else(|| SceneError::UnknownBuiltin {
        name: name.into(),
        known: BUILTIN_SCENES.iter().map(|s| s.name).collect::<Vec<_>>().join(", "),
    })
}

/// The camera every built-in scene shares: at (0, 5, 6) looking at the origin, 45° vertical field of view.
fn standard_camera() -> Camera {
    Camera { position: Vec3::new(0.0, 5.0, 6.0), target: Vec3::ZERO, up: Vec3::Y, fov_y: 45f32.to_radians(), near: 0.1, far: 50.0 }
}

/// A square light of side `size` centred at `centre`, facing down, first side along +X.
fn downward_light(centre: Vec3, size: f32) -> RectLight {
    RectLight { centre, u_axis: Vec3::X, v_axis: Vec3::Z, half_size: Vec2::splat(size * 0.5), intensity: 1.0, colour: Vec3::ONE }
}

struct SceneBuilder {
    scene: Scene,
}

impl SceneBuilder {
    fn new(name: &str, light: RectLight) -> Self {
        let origin = PathBuf::from(format!("builtin:{name}"));
        Self { scene: Scene { origin, meshes: Vec::new(), instances: Vec::new(), lights: vec![light], camera: standard_camera() } }
    }

    fn mesh(&mut self, mesh: Mesh) -> usize {
        self.scene.meshes.push(mesh);
        self.scene.meshes.len() - 1
    }

    fn place(&mut self, name: impl Into<String>, mesh: usize, transform: Mat4, role: Role) {
        self.scene.instances.push(Instance { name: name.into(), mesh, transform, role });
    }

    fn ground(mut self, size: f32) -> Self {
        let ground = self.mesh(plane("ground", Vec2::splat(size)));
        self.place("ground", ground, Mat4::IDENTITY, Role::Receiver);
        self
    }
}

fn parallel_square() -> Scene {
    let mut b = SceneBuilder::new("parallel-square", downward_light(Vec3::new(0.0, 4.0, 0.0), 1.0)).ground(8.0);
    let occluder = b.mesh(plane("occluder", Vec2::ONE));
    b.place("occluder", occluder, Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)), Role::Occluder);
    b.scene
}

fn floating_sphere(args: &BuiltinArgs) -> Scene {
    let mut b = SceneBuilder::new("floating-sphere", downward_light(Vec3::new(0.0, 4.0, 0.0), 1.0)).ground(8.0);
    let ball = b.mesh(sphere("sphere", 0.6, args.get("segments") as u32, args.get("rings") as u32));
    b.place("sphere", ball, Mat4::from_translation(Vec3::new(0.0, 1.4, 0.0)), Role::Occluder);
    b.scene
}

fn contact() -> Scene {
    let mut b = SceneBuilder::new("contact", downward_light(Vec3::new(1.0, 4.0, -0.5), 1.2)).ground(8.0);
    let block = b.mesh(cuboid("box", Vec3::new(1.0, 1.2, 0.6)));
    let transform = Mat4::from_rotation_translation(Quat::from_rotation_y(0.5), Vec3::new(-0.6, 0.6, 0.0));
    b.place("box", block, transform, Role::Both);
    let ball = b.mesh(sphere("ball", 0.45, 40, 20));
    b.place("ball", ball, Mat4::from_translation(Vec3::new(0.9, 0.45, 0.6)), Role::Both);
    b.scene
}

fn sphere_cube(args: &BuiltinArgs) -> Scene {
    let mut b = SceneBuilder::new("sphere-cube", downward_light(Vec3::new(0.0, 4.5, 0.0), 1.0)).ground(8.0);
    let (count, segments, rings) = (args.get("spheres") as u32, args.get("segments") as u32, args.get("rings") as u32);
    let ball = b.mesh(sphere("small-sphere", 0.11, segments, rings));
    // Spheres 0.3 apart whatever their number: the cube grows with it (Forest et al., Fig. 12).
    let middle = (count as f32 - 1.0) * 0.5;
    for i in 0..count {
        for j in 0..count {
            for k in 0..count {
                let offset = (Vec3::new(i as f32, j as f32, k as f32) - Vec3::splat(middle)) * 0.3;
                b.place(format!("sphere-{i}-{j}-{k}"), ball, Mat4::from_translation(Vec3::new(0.0, 1.6, 0.0) + offset), Role::Occluder);
            }
        }
    }
    b.scene
}

fn leaves() -> Scene {
    let mut b = SceneBuilder::new("leaves", downward_light(Vec3::new(0.0, 4.5, 0.0), 1.0)).ground(8.0);
    let leaf = b.mesh(plane("leaf", Vec2::new(0.3, 0.12)));
    // A fixed xorshift sequence: the scene is the same on every machine and every run.
    let mut state = 0x9E37_79B9_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    for index in 0..300 {
        let position = Vec3::new(next() * 3.0 - 1.5, 0.4 + next() * 2.2, next() * 3.0 - 1.5);
        let rotation = Quat::from_rotation_y(next() * std::f32::consts::TAU) * Quat::from_rotation_x((next() - 0.5) * 1.2);
        b.place(format!("leaf-{index}"), leaf, Mat4::from_rotation_translation(rotation, position), Role::Occluder);
    }
    b.scene
}

fn bar_grid() -> Scene {
    let mut b = SceneBuilder::new("bar-grid", downward_light(Vec3::new(0.0, 6.0, 0.0), 0.05)).ground(16.0);
    let bar = b.mesh(cuboid("bar", Vec3::new(6.0, 0.02, 0.03)));
    for index in 0..70 {
        let z = -3.5 + index as f32 * 0.1;
        b.place(format!("bar-{index}"), bar, Mat4::from_translation(Vec3::new(0.0, 3.0, z)), Role::Occluder);
    }
    // Low and narrow, so that the bars stay above the view and the floor recedes to a grazing angle.
    b.scene.camera =
        Camera { position: Vec3::new(0.0, 1.0, 6.0), target: Vec3::new(0.0, 0.0, -1.0), fov_y: 30f32.to_radians(), ..standard_camera() };
    b.scene
}

/// `parts` transformed and joined into one mesh (the transforms rigid or uniformly scaled).
fn merged(name: &str, parts: &[(&Mesh, Mat4)]) -> Mesh {
    let mut mesh = Mesh { name: name.into(), positions: Vec::new(), normals: Vec::new(), indices: Vec::new() };
    for (part, transform) in parts {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(part.positions.iter().map(|p| transform.transform_point3(*p)));
        mesh.normals.extend(part.normals.iter().map(|n| transform.transform_vector3(*n).normalize_or(Vec3::Y)));
        mesh.indices.extend(part.indices.iter().map(|i| base + i));
    }
    mesh
}

fn forest(args: &BuiltinArgs) -> Scene {
    let trees = args.get("trees") as u32;
    let side = (f64::from(trees).sqrt().ceil() as u32).max(1);
    let extent = side as f32 * 2.0;
    let mut b =
        SceneBuilder::new("forest", downward_light(Vec3::new(0.0, 6.0 + extent * 0.5, 0.0), 1.0 + extent * 0.1)).ground(extent + 4.0);
    let trunk = cuboid("trunk", Vec3::new(0.12, 1.2, 0.12));
    let card = plane("leaf", Vec2::new(0.25, 0.12));
    let trunk_triangles = (trunk.indices.len() / 3) as f64;
    let per_tree = ((args.get("triangles") - 2.0) / f64::from(trees) - trunk_triangles).max(2.0);
    let cards = (per_tree / 2.0).floor().max(1.0) as u32;
    // A fixed xorshift sequence: the scene is the same on every machine and every run.
    let mut state = 0x2545_F491_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    // Three crowns, instanced over the grid with different turns and sizes.
    let variants: Vec<usize> = (0..3)
        .map(|variant| {
            let mut parts = vec![(&trunk, Mat4::from_translation(Vec3::new(0.0, 0.6, 0.0)))];
            let leaves: Vec<Mat4> = (0..cards)
                .map(|_| {
                    // Uniform in a ball of radius 0.8 centred 1.8 up: the crown.
                    let direction = Vec3::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0).normalize_or(Vec3::Y);
                    let position = Vec3::new(0.0, 1.8, 0.0) + direction * 0.8 * next().cbrt();
                    let rotation = Quat::from_rotation_y(next() * std::f32::consts::TAU) * Quat::from_rotation_x((next() - 0.5) * 2.0);
                    Mat4::from_rotation_translation(rotation, position)
                })
                .collect();
            parts.extend(leaves.iter().map(|t| (&card, *t)));
            b.mesh(merged(&format!("tree-{variant}"), &parts))
        })
        .collect();
    for index in 0..trees {
        let (column, row) = (index % side, index / side);
        let centre = Vec3::new(column as f32 * 2.0 - extent * 0.5 + 1.0, 0.0, row as f32 * 2.0 - extent * 0.5 + 1.0);
        let jitter = Vec3::new(next() - 0.5, 0.0, next() - 0.5) * 0.6;
        let transform = Mat4::from_scale_rotation_translation(
            Vec3::splat(0.8 + 0.4 * next()),
            Quat::from_rotation_y(next() * std::f32::consts::TAU),
            centre + jitter,
        );
        b.place(format!("tree-{index}"), variants[index as usize % variants.len()], transform, Role::Both);
    }
    b.scene.camera =
        Camera { position: Vec3::new(0.0, 3.0 + extent * 0.5, 4.0 + extent * 0.9), target: Vec3::new(0.0, 1.0, 0.0), ..standard_camera() };
    b.scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_validates() {
        for s in BUILTIN_SCENES {
            let scene = s.build();
            scene.validate().unwrap_or_else(|e| panic!("{}: {e}", s.name));
            assert_eq!(scene.origin.to_str(), Some(format!("builtin:{}", s.name).as_str()));
        }
    }

    #[test]
    fn parallel_square_has_the_documented_geometry() {
        let scene = builtin("parallel-square").unwrap().build();
        let light = scene.lights[0];
        assert_eq!(light.centre, Vec3::new(0.0, 4.0, 0.0));
        assert_eq!(light.half_size, Vec2::splat(0.5));
        assert!((light.normal() + Vec3::Y).length() < 1e-6);
        let occluder = scene.bounds_where(|r| r == Role::Occluder);
        assert_eq!((occluder.min, occluder.max), (Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, 0.5)));
        let receiver = scene.bounds_where(|r| r == Role::Receiver);
        assert_eq!((receiver.min, receiver.max), (Vec3::new(-4.0, 0.0, -4.0), Vec3::new(4.0, 0.0, 4.0)));
        assert_eq!(scene.camera.position, Vec3::new(0.0, 5.0, 6.0));
        assert!((scene.camera.fov_y.to_degrees() - 45.0).abs() < 1e-4);
    }

    #[test]
    fn parameters_are_parsed_checked_and_recorded() {
        let (entry, scene) = parse_builtin("forest:triangles=50000, trees=9").unwrap().unwrap();
        assert_eq!(entry.name, "forest");
        let triangles: usize = scene.instances.iter().map(|i| scene.meshes[i.mesh].indices.len() / 3).sum();
        assert!((triangles as f64 - 50_000.0).abs() < 50_000.0 * 0.01, "{triangles} triangles");
        assert_eq!(scene.instances.len(), 10, "nine trees and the ground");
        assert_eq!(scene.origin.to_str(), Some("builtin:forest:triangles=50000, trees=9"));
        scene.validate().unwrap();
        let default = builtin("forest").unwrap().build();
        let default_triangles: usize = default.instances.iter().map(|i| default.meshes[i.mesh].indices.len() / 3).sum();
        assert!((default_triangles as f64 - 20_000.0).abs() < 200.0, "{default_triangles}");
        let cube = parse_builtin("sphere-cube:spheres=3,segments=20,rings=20").unwrap().unwrap().1;
        assert_eq!(cube.instances.len(), 27 + 1);
        assert_eq!(cube.meshes.iter().find(|m| m.name == "small-sphere").unwrap().indices.len() / 3, 760);
        for (spec, needle) in [
            ("forest:leaves=3", "unknown parameter `leaves`; its parameters: triangles, trees"),
            ("sphere-cube:spheres=3,size=2", "its parameters: spheres, segments, rings"),
            ("forest:trees=many", "`many` is not a number"),
            ("forest:trees=0", "trees = 0 is outside 1..=4096"),
            ("forest:trees=nan", "outside"),
            ("forest:trees", "is not `param=value`"),
            ("leaves:size=2", "its parameters: none"),
        ] {
            let error = parse_builtin(spec).unwrap().unwrap_err().to_string();
            assert!(error.contains(needle) && error.contains(spec.split(':').next().unwrap()), "{spec}: {error}");
        }
        assert!(parse_builtin("models/thing.toml").is_none());
    }

    #[test]
    fn unknown_builtin_lists_the_known_ones() {
        let err = builtin("nope").unwrap_err().to_string();
        assert!(err.contains("parallel-square") && err.contains("leaves"), "{err}");
    }
}
