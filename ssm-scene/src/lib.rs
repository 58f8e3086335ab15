//! Scenes for soft-shadow research, with no GPU code: reuse it anywhere.
//!
//! - [`Scene`]: meshes placed by [`Instance`]s with a shadow [`Role`], lit by
//!   one-sided rectangular [`RectLight`]s, seen by a [`Camera`].
//! - Loading: [`Scene::load`] takes a built-in scene name, a TOML [`Manifest`],
//!   or a bare `.gltf`/`.glb`/`.obj`/`.ply` model, which it stages with a
//!   ground plane, a light and a camera ([`stage_model`]).
//! - [`Adjacency`] (edge–face, on welded positions) is computed only when asked.
//!
//! Every failure is a [`SceneError`] that names the file and the element.
//!
//! # Example
//!
//! A glTF model (one triangle, its buffer inline), placed by a TOML manifest over a ground
//! plane under a square area light; then the world-space triangles and the lights:
//!
//! ```
//! use ssm_scene::Scene;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let folder = std::env::temp_dir().join(format!("ssm-scene-example-{}", std::process::id()));
//! std::fs::create_dir_all(&folder)?;
//! std::fs::write(
//!     folder.join("triangle.gltf"),
//!     r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
//!         "nodes": [{"name": "leaf", "mesh": 0}],
//!         "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
//!         "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
//!                        "min": [-0.5, 1.0, -0.5], "max": [0.5, 1.0, 0.5]}],
//!         "bufferViews": [{"buffer": 0, "byteLength": 36}],
//!         "buffers": [{"byteLength": 36,
//!                      "uri": "data:application/octet-stream;base64,AAAAvwAAgD8AAAC/AAAAAAAAgD8AAAA/AAAAPwAAgD8AAAC/"}]}"#,
//! )?;
//! std::fs::write(
//!     folder.join("scene.toml"),
//!     r#"
//!     [[light]]
//!     centre = [0.0, 3.0, 0.0]
//!     normal = [0.0, -1.0, 0.0]
//!     size = [0.5, 0.5]
//!
//!     [[object]]
//!     model = "triangle.gltf"    # relative to the manifest
//!     scale = 2.0
//!     role = "occluder"
//!
//!     [[object]]
//!     primitive = "plane"
//!     size = [8.0, 8.0]
//!     role = "receiver"
//!     "#,
//! )?;
//!
//! // A manifest, a bare model (staged with a ground, a light and a camera) or a built-in name.
//! let (scene, _source) = Scene::load(&folder.join("scene.toml").to_string_lossy())?;
//! let mut casting = 0;
//! for triangle in scene.world_triangles() {
//!     // World-space corners and normals, and the role of the instance it belongs to.
//!     let [a, b, c] = triangle.corners;
//!     assert!((b - a).cross(c - a).length() > 0.0);
//!     casting += usize::from(triangle.role.casts());
//! }
//! assert_eq!((scene.triangle_count(), casting), (3, 1));
//! for light in &scene.lights {
//!     // A one-sided rectangle: centre, unit axes, half extents, normal.
//!     println!("light at {} facing {}, area {}", light.centre, light.normal(), light.area());
//! }
//! assert_eq!(scene.lights[0].area(), 0.25);
//! std::fs::remove_dir_all(&folder)?;
//! # Ok(())
//! # }
//! ```

mod adjacency;
mod builtin;
mod camera;
mod error;
#[doc(hidden)]
pub mod fuzzing;
mod light;
mod loaders;
mod manifest;
mod mesh;
mod polygon;
pub mod primitives;
mod scene;

use std::path::Path;

pub use adjacency::{Adjacency, Edge, NO_FACE};
pub use builtin::{BUILTIN_SCENES, BuiltinArgs, BuiltinParam, BuiltinScene, builtin, parse_builtin};
pub use camera::Camera;
pub use error::{Result, SceneError};
pub use light::{RectLight, sum_of_uniforms_cdf};
pub use loaders::{LoadedModel, Placement, load_model};
pub use manifest::{CameraSpec, LightSpec, Manifest, ObjectSpec, Scale, framing_camera, stage_model};
pub use mesh::{Mesh, fan_to_list, generate_normals, strip_to_list};
pub use scene::{Aabb, Instance, Role, Scene, WorldTriangle, normal_matrix};

/// How a scene argument was understood by [`Scene::load`].
#[derive(Clone, Debug)]
pub enum SceneSource {
    /// A built-in scene.
    Builtin(&'static BuiltinScene),
    /// A TOML manifest.
    Manifest,
    /// A bare model, staged; the staging manifest is kept so it can be printed.
    StagedModel(Manifest),
}

impl Scene {
    /// Loads a scene from a built-in name (with parameters: `forest:triangles=800000,trees=64`), a
    /// `.toml` manifest, or a model file.
    ///
    /// # Errors
    /// Any [`SceneError`]; the scene is validated before it is returned.
    pub fn load(spec: &str) -> Result<(Self, SceneSource)> {
        if let Some(parsed) = builtin::parse_builtin(spec) {
            let (builtin, scene) = parsed?;
            return Ok((scene, SceneSource::Builtin(builtin)));
        }
        let path = Path::new(spec);
        let extension = path.extension().and_then(|e| e.to_str()).unwrap_or_default().to_ascii_lowercase();
        let base_dir = path.parent().unwrap_or_else(|| Path::new("."));
        match extension.as_str() {
            "toml" => Ok((Manifest::read(path)?.build(path, base_dir)?, SceneSource::Manifest)),
            "gltf" | "glb" | "obj" | "ply" => {
                let manifest = stage_model(path)?;
                let scene = manifest.build(path, base_dir)?;
                Ok((scene, SceneSource::StagedModel(manifest)))
            }
            "" if !path.exists() => Err(builtin::builtin(spec)
                .err()
                .unwrap_or(SceneError::Io { file: path.into(), source: std::io::ErrorKind::NotFound.into() })),
            _ => Err(SceneError::UnsupportedFormat { file: path.into(), extension }),
        }
    }
}
