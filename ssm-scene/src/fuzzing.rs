//! The one entry point of the fuzz targets (`fuzz/`) and of the test that
//! replays their corpora (`tests/fuzz_regressions.rs`), so that both load an
//! input exactly as `ssm render --scene FILE` does: written to a file with the
//! target's extension, then given to [`Scene::load`].
//!
//! Not part of the API: hidden from the documentation, and may change.

use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::Scene;

/// Which loader an input is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// `.gltf`, or `.glb` when the input starts with the binary magic `glTF`.
    Gltf,
    /// `.obj`.
    Obj,
    /// `.ply`.
    Ply,
    /// A `.toml` scene manifest; it may refer to the fixtures `cube.obj`,
    /// `tetra.ply`, `square.gltf` (with `square.bin`) and `square.glb`.
    Manifest,
}

impl Target {
    /// Every target.
    pub const ALL: [Self; 4] = [Self::Gltf, Self::Obj, Self::Ply, Self::Manifest];

    /// The target's name: its folder under `fuzz/seeds/` and `fuzz/regressions/`, and its fuzz target.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Gltf => "gltf",
            Self::Obj => "obj",
            Self::Ply => "ply",
            Self::Manifest => "manifest",
        }
    }

    fn extension(self, data: &[u8]) -> &'static str {
        match self {
            Self::Gltf if data.starts_with(b"glTF") => "glb",
            Self::Gltf => "gltf",
            Self::Obj => "obj",
            Self::Ply => "ply",
            Self::Manifest => "toml",
        }
    }
}

/// Files the scratch folder holds for manifests and external glTF buffers to refer to.
const CUBE_OBJ: &str = "o cube\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";
const TETRA_PLY: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
const SQUARE_GLTF: &str = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
"nodes": [{"name": "square", "mesh": 0}], "meshes": [{"name": "square", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
"buffers": [{"uri": "square.bin", "byteLength": 60}],
"bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
"accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]},
{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]}"#;

/// Four corners of a unit square in XZ and two triangles facing +Y, as `square.gltf` lays them out.
fn square_bin() -> Vec<u8> {
    let mut bytes: Vec<u8> =
        [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]].iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    bytes.extend([0u16, 2, 1, 0, 3, 2].iter().flat_map(|i| i.to_le_bytes()));
    bytes
}

/// `square.gltf` with its buffer embedded, as a `.glb`.
fn square_glb() -> Vec<u8> {
    let mut json = SQUARE_GLTF.replace(r#""uri": "square.bin", "#, "").into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let bin = square_bin();
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    for word in [0x4654_6C67u32, 2, total as u32, json.len() as u32, 0x4E4F_534A] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&json);
    for word in [bin.len() as u32, 0x004E_4942] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&bin);
    out
}

/// This process's scratch folder, created with the fixtures on first use.
fn scratch() -> &'static Path {
    static SCRATCH: OnceLock<PathBuf> = OnceLock::new();
    SCRATCH.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("ssm-scene-fuzz-{}", std::process::id()));
        let fixtures: [(&str, Vec<u8>); 5] = [
            ("cube.obj", CUBE_OBJ.into()),
            ("tetra.ply", TETRA_PLY.into()),
            ("square.gltf", SQUARE_GLTF.into()),
            ("square.bin", square_bin()),
            ("square.glb", square_glb()),
        ];
        // Without the folder every load fails early, which the caller sees as errors, not as a crash.
        let _ = std::fs::create_dir_all(&dir);
        for (name, bytes) in fixtures {
            let _ = std::fs::write(dir.join(name), bytes);
        }
        dir
    })
}

/// A small number for this thread, so that threads loading at once use distinct input files.
fn thread_number() -> usize {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    thread_local!(static NUMBER: Cell<Option<usize>> = const { Cell::new(None) });
    NUMBER.with(|n| {
        let number = n.get().unwrap_or_else(|| NEXT.fetch_add(1, Ordering::Relaxed));
        n.set(Some(number));
        number
    })
}

/// Writes `data` as this thread's input file for `target` (reused from call to call) and loads
/// it with [`Scene::load`], as `ssm render --scene FILE` does. Returns the error's message.
///
/// # Errors
/// The message of the [`crate::SceneError`], or of the failure to write the input file.
pub fn load(target: Target, data: &[u8]) -> Result<(), String> {
    let path = scratch().join(format!("input-{}.{}", thread_number(), target.extension(data)));
    std::fs::write(&path, data).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    let spec = path.to_str().ok_or_else(|| format!("{}: not UTF-8", path.display()))?;
    Scene::load(spec).map(|_| ()).map_err(|e| e.to_string())
}
