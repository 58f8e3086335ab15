//! Model-file loaders: glTF 2.0, Wavefront OBJ and Stanford PLY.
//!
//! Each returns a [`LoadedModel`]: meshes in object space, their placements
//! and any cameras the file defines. Materials, textures and animations are
//! not decoded: shadows need geometry only. The OBJ and PLY parsers are our
//! own, and the glTF loader deserializes the `gltf` crate's document model one
//! element at a time and decodes the buffers itself, so that every malformed
//! input is a typed error naming the file and the element (each module says
//! what it takes from the usual crate, or why it does not use it).

mod gltf;
mod obj;
mod ply;

use std::path::Path;

use glam::Mat4;

use crate::camera::Camera;
use crate::error::{Result, SceneError};
use crate::mesh::Mesh;

/// What a model file holds, before roles and scene-level transforms are applied.
#[derive(Clone, Debug, Default)]
pub struct LoadedModel {
    /// Meshes in object space; validated.
    pub meshes: Vec<Mesh>,
    /// Placements: mesh index, object-to-model transform, node name (or mesh name).
    pub placements: Vec<Placement>,
    /// Cameras the file defines, in file order (glTF only).
    pub cameras: Vec<Camera>,
}

/// One placement of a loaded mesh.
#[derive(Clone, Debug)]
pub struct Placement {
    /// Index into [`LoadedModel::meshes`].
    pub mesh: usize,
    /// Object-to-model transform (the node's world transform in glTF).
    pub transform: Mat4,
    /// The node's name, else the mesh's name.
    pub node_name: String,
}

/// A format's parser: the file's path (for messages) and its bytes.
type Parser = fn(&Path, &[u8]) -> Result<LoadedModel>;

/// Loads a model file, picking the format from the extension.
///
/// # Errors
/// [`SceneError::UnsupportedFormat`] for an unknown extension, [`SceneError::Io`]
/// when the file cannot be read, and a typed error naming the file and the
/// element for anything malformed.
pub fn load_model(path: &Path) -> Result<LoadedModel> {
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or_default().to_ascii_lowercase();
    let (format, load): (&'static str, Parser) = match extension.as_str() {
        "gltf" | "glb" => ("glTF", gltf::load),
        "obj" => ("OBJ", obj::load),
        "ply" => ("PLY", ply::load),
        _ => return Err(SceneError::UnsupportedFormat { file: path.into(), extension }),
    };
    let io = |source| SceneError::Io { file: path.into(), source };
    // A device or a pipe (`/dev/zero`) would be read forever.
    if !std::fs::metadata(path).map_err(io)?.is_file() {
        return Err(io(std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a regular file")));
    }
    let bytes = std::fs::read(path).map_err(io)?;
    let model = guard(path, format, || load(path, &bytes))?;
    for mesh in &model.meshes {
        mesh.validate(path)?;
    }
    if model.meshes.iter().all(|m| m.indices.is_empty()) {
        return Err(SceneError::EmptyScene { file: path.into(), what: "the file has no triangles" });
    }
    Ok(model)
}

/// Runs a third-party parser so that a panic inside it becomes a typed error.
///
/// Our own checks come first (sizes, indices, finiteness), but a hostile file
/// may still reach an arithmetic overflow inside a dependency; the user must
/// get a message naming the file, never an abort.
fn guard(path: &Path, format: &'static str, parse: impl FnOnce() -> Result<LoadedModel>) -> Result<LoadedModel> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse))
        .unwrap_or_else(|_| Err(SceneError::Malformed { file: path.into(), format, message: "the parser failed on malformed data".into() }))
}

/// A malformed-file error for `path` in `format`.
fn malformed(path: &Path, format: &'static str, message: impl std::fmt::Display) -> SceneError {
    SceneError::Malformed { file: path.into(), format, message: message.to_string() }
}
