//! The one error type of scene loading and validation.

use std::path::PathBuf;

/// Everything that can be wrong with a scene, a model file or a manifest.
///
/// Every variant names the file it came from (`builtin:<name>` for the
/// procedural scenes) and the element at fault, so that the message alone
/// tells the user what to fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The file could not be read at all.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The file's extension names no format we load.
    #[error("{}: unsupported model format `{extension}` (expected .gltf, .glb, .obj or .ply)", file.display())]
    UnsupportedFormat {
        /// The file.
        file: PathBuf,
        /// Its extension, possibly empty.
        extension: String,
    },
    /// The file is valid, or may be, but uses something the loader does not decode
    /// (glTF 1.0, a compression extension, UTF-16 text...).
    #[error("{}: {what} is not supported: {hint}", file.display())]
    Unsupported {
        /// The file.
        file: PathBuf,
        /// What the file uses, as `glTF 1.0` or `the glTF extension KHR_draco_mesh_compression`.
        what: String,
        /// What to do instead, as `convert the file to glTF 2.0`.
        hint: String,
    },
    /// A file that the model file refers to (a glTF buffer) cannot be read.
    #[error("{}: {element} refers to `{}`, which cannot be read: {source}", file.display(), referenced.display())]
    MissingReference {
        /// The model file.
        file: PathBuf,
        /// The element holding the reference, as `buffer 0`.
        element: String,
        /// The file it refers to, resolved against the model's folder.
        referenced: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The file is not valid in its format (truncated, wrong types, missing buffers...).
    #[error("{}: invalid {format} file: {message}", file.display())]
    Malformed {
        /// The file.
        file: PathBuf,
        /// `glTF`, `OBJ`, `PLY` or `manifest`.
        format: &'static str,
        /// What the parser said.
        message: String,
    },
    /// A triangle index points past the end of its mesh's vertex array.
    #[error("{}: mesh `{mesh}`: index {index} (entry {position} of the index list) is out of range: the mesh has {count} vertices", file.display())]
    InvalidIndex {
        /// The file.
        file: PathBuf,
        /// The mesh's name.
        mesh: String,
        /// The offending index value.
        index: u64,
        /// Where it sits in the index list.
        position: usize,
        /// The mesh's vertex count.
        count: usize,
    },
    /// The index list does not describe whole triangles.
    #[error("{}: mesh `{mesh}`: {count} indices is not a whole number of triangles", file.display())]
    PartialTriangle {
        /// The file.
        file: PathBuf,
        /// The mesh's name.
        mesh: String,
        /// Number of indices.
        count: usize,
    },
    /// A vertex position or normal is NaN or infinite.
    #[error("{}: mesh `{mesh}`: vertex {vertex} has a non-finite {attribute} {value:?}", file.display())]
    NonFiniteVertex {
        /// The file.
        file: PathBuf,
        /// The mesh's name.
        mesh: String,
        /// The vertex's index.
        vertex: usize,
        /// `position` or `normal`.
        attribute: &'static str,
        /// The value found.
        value: [f32; 3],
    },
    /// A mesh's normal array does not match its position array.
    #[error("{}: mesh `{mesh}`: {normals} normals for {positions} positions", file.display())]
    NormalCountMismatch {
        /// The file.
        file: PathBuf,
        /// The mesh's name.
        mesh: String,
        /// Number of normals.
        normals: usize,
        /// Number of positions.
        positions: usize,
    },
    /// An instance's transform is non-finite or singular.
    #[error("{}: instance `{instance}`: the transform is {problem}", file.display())]
    InvalidTransform {
        /// The file.
        file: PathBuf,
        /// The instance's name.
        instance: String,
        /// `not finite` or `singular`.
        problem: &'static str,
    },
    /// An instance refers to a mesh that does not exist.
    #[error("{}: instance `{instance}` refers to mesh {mesh}, but the scene has {count} meshes", file.display())]
    MissingMesh {
        /// The file.
        file: PathBuf,
        /// The instance's name.
        instance: String,
        /// The mesh index.
        mesh: usize,
        /// Number of meshes.
        count: usize,
    },
    /// The node hierarchy of a glTF file loops back on itself.
    #[error("{}: node {node} (`{name}`) is its own ancestor: the node hierarchy has a cycle", file.display())]
    NodeCycle {
        /// The file.
        file: PathBuf,
        /// The node index.
        node: usize,
        /// The node's name, or empty.
        name: String,
    },
    /// There is nothing to draw, or nothing to light it.
    #[error("{}: the scene is empty: {what}", file.display())]
    EmptyScene {
        /// The file.
        file: PathBuf,
        /// What is missing.
        what: &'static str,
    },
    /// A light is malformed (non-finite, negative size, degenerate axes...).
    #[error("{}: light {index}: {problem}", file.display())]
    InvalidLight {
        /// The file.
        file: PathBuf,
        /// The light's position in the scene's list.
        index: usize,
        /// What is wrong.
        problem: String,
    },
    /// The camera is malformed.
    #[error("{}: camera: {problem}", file.display())]
    InvalidCamera {
        /// The file.
        file: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// A manifest field has a value outside what it allows.
    #[error("{}: {element}: {problem}", file.display())]
    InvalidManifest {
        /// The manifest.
        file: PathBuf,
        /// The element, as `object 2` or `light 0`.
        element: String,
        /// What is wrong.
        problem: String,
    },
    /// No built-in scene has this name.
    #[error("unknown built-in scene `{name}`; the built-in scenes are: {known}")]
    UnknownBuiltin {
        /// The name asked for.
        name: String,
        /// The names that exist, comma-separated.
        known: String,
    },
    /// A built-in scene's parameter is unknown, not a number, or out of its range.
    #[error("built-in scene `{scene}`: {problem}")]
    BuiltinParameter {
        /// The scene, as given (`forest:triangles=...`).
        scene: String,
        /// What is wrong, naming the parameter and what it accepts.
        problem: String,
    },
}

/// Shorthand for results of this crate.
pub type Result<T, E = SceneError> = std::result::Result<T, E>;
