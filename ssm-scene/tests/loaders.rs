//! Loader round-trips and bad input: every fixture is written here, so the
//! tests say exactly what each file holds. Every bad file must give a typed
//! error naming the file, never a panic or a silently wrong scene.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use glam::Vec3;
use ssm_scene::{Role, Scene, SceneError, load_model, stage_model};

/// A fresh directory for one test's files.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssm-scene-loaders-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The error's message names the file.
fn names_file(error: &SceneError, path: &Path) -> bool {
    error.to_string().contains(&path.display().to_string())
}

const CUBE_OBJ: &str = "o cube
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 3 4 8 7
f 2 3 7 6
f 1 5 8 4
";

#[test]
fn obj_quads_are_triangulated_with_generated_normals() {
    let dir = scratch("obj");
    let path = write(&dir, "cube.obj", CUBE_OBJ);
    let model = load_model(&path).unwrap();
    assert_eq!(model.meshes.len(), 1);
    let mesh = &model.meshes[0];
    assert_eq!((mesh.positions.len(), mesh.triangle_count()), (8, 12));
    assert_eq!(mesh.name, "cube");
    // Smooth normals of a cube's corner point along the diagonal.
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        assert!(n.dot(p.normalize()) > 0.99, "{p} {n}");
    }
    assert!(ssm_scene::Adjacency::of(mesh).is_closed_manifold());
}

#[test]
fn obj_bad_input() {
    let dir = scratch("obj-bad");
    let out_of_range = write(&dir, "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    let e = load_model(&out_of_range).unwrap_err();
    assert!(names_file(&e, &out_of_range), "{e}");
    let nan = write(&dir, "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    let e = load_model(&nan).unwrap_err();
    assert!(matches!(e, SceneError::NonFiniteVertex { vertex: 1, .. }), "{e}");
    let inf = write(&dir, "inf.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n");
    assert!(matches!(load_model(&inf).unwrap_err(), SceneError::NonFiniteVertex { .. }));
    let empty = write(&dir, "empty.obj", "# nothing\n");
    assert!(matches!(load_model(&empty).unwrap_err(), SceneError::EmptyScene { .. }));
    let garbage = write(&dir, "garbage.obj", "v a b c\nf 1 2 3\n");
    let e = load_model(&garbage).unwrap_err();
    assert!(names_file(&e, &garbage), "{e}");
}

const TETRA_ASCII_PLY: &str = "ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 4
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
0 1 0
0 0 1
3 0 2 1
3 0 1 3
3 0 3 2
3 1 2 3
";

fn binary_ply(vertices: &[[f32; 3]], faces: &[&[i32]], truncate: usize) -> Vec<u8> {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    )
    .into_bytes();
    for v in vertices {
        for c in v {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in faces {
        bytes.push(f.len() as u8);
        for i in *f {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    bytes.truncate(bytes.len() - truncate);
    bytes
}

#[test]
fn ply_ascii_and_binary_load_the_same_mesh() {
    let dir = scratch("ply");
    let ascii = load_model(&write(&dir, "tetra.ply", TETRA_ASCII_PLY)).unwrap();
    let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let faces: [&[i32]; 4] = [&[0, 2, 1], &[0, 1, 3], &[0, 3, 2], &[1, 2, 3]];
    let binary = load_model(&write(&dir, "tetra-bin.ply", binary_ply(&vertices, &faces, 0))).unwrap();
    assert_eq!(ascii.meshes[0].positions, binary.meshes[0].positions);
    assert_eq!(ascii.meshes[0].indices, binary.meshes[0].indices);
    assert_eq!(ascii.meshes[0].triangle_count(), 4);
    // A quad face is split into two triangles.
    let quad = load_model(&write(&dir, "quad.ply", binary_ply(&vertices, &[&[0, 1, 2, 3]], 0))).unwrap();
    assert_eq!(quad.meshes[0].indices, vec![0, 1, 2, 0, 2, 3]);
}

#[test]
fn ply_bad_input() {
    let dir = scratch("ply-bad");
    let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let truncated = write(&dir, "truncated.ply", binary_ply(&vertices, &[&[0, 1, 2]], 5));
    let e = load_model(&truncated).unwrap_err();
    assert!(matches!(e, SceneError::Malformed { format: "PLY", .. }) && names_file(&e, &truncated), "{e}");
    let range = write(&dir, "range.ply", binary_ply(&vertices, &[&[0, 1, 7]], 0));
    assert!(matches!(load_model(&range).unwrap_err(), SceneError::InvalidIndex { index: 7, count: 3, .. }));
    let negative = write(&dir, "negative.ply", binary_ply(&vertices, &[&[0, 1, -1]], 0));
    assert!(matches!(load_model(&negative).unwrap_err(), SceneError::InvalidIndex { .. }));
    let nan = write(&dir, "nan.ply", binary_ply(&[[0.0, f32::NAN, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[&[0, 1, 2]], 0));
    assert!(matches!(load_model(&nan).unwrap_err(), SceneError::NonFiniteVertex { vertex: 0, .. }));
    let points = write(
        &dir,
        "points.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
    );
    assert!(load_model(&points).unwrap_err().to_string().contains("face"));
    let wrong_type =
        write(&dir, "type.ply", TETRA_ASCII_PLY.replace("property list uchar int vertex_indices", "property float vertex_indices"));
    assert!(names_file(&load_model(&wrong_type).unwrap_err(), &wrong_type));
    // A header that promises 4 billion vertices: a clean error, not an allocation abort.
    let huge = write(&dir, "huge.ply", TETRA_ASCII_PLY.replace("element vertex 4", "element vertex 4000000000"));
    assert!(load_model(&huge).is_err());
}

/// Base64 for data URIs (standard alphabet, padded).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = (u32::from(chunk[0]) << 16) | (u32::from(*chunk.get(1).unwrap_or(&0)) << 8) | u32::from(*chunk.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Four vertices of a unit square in XZ and the given u32 indices, as one buffer.
fn square_buffer(indices: &[u32]) -> Vec<u8> {
    let mut bytes = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]] {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in indices {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes
}

/// A glTF document: one mesh of one primitive in `mode` over [`square_buffer`], placed by a
/// parent node (translated by +2 in y) with a child (scaled by 3), plus a camera node.
fn gltf_json(buffer_uri: Option<&str>, byte_length: usize, index_count: usize, mode: u32, position_type: &str) -> String {
    let uri = buffer_uri.map(|u| format!(r#""uri": "{u}","#)).unwrap_or_default();
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 2]}}],
  "nodes": [
    {{"name": "parent", "translation": [0, 2, 0], "children": [1]}},
    {{"name": "leaf", "mesh": 0, "scale": [3, 3, 3]}},
    {{"name": "eye", "camera": 0, "translation": [0, 1, 10]}}
  ],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "znear": 0.1, "zfar": 100}}}}],
  "meshes": [{{"name": "square", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": {mode}}}]}}],
  "buffers": [{{{uri} "byteLength": {byte_length}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": {index_bytes}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "{position_type}", "min": [0, 0, 0], "max": [1, 0, 1]}},
    {{"bufferView": 1, "componentType": 5125, "count": {index_count}, "type": "SCALAR"}}
  ]
}}"#,
        index_bytes = index_count * 4
    )
}

fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn check_square_model(model: &ssm_scene::LoadedModel, triangles: usize) {
    assert_eq!(model.meshes.len(), 1);
    assert_eq!(model.meshes[0].triangle_count(), triangles);
    assert_eq!(model.placements.len(), 1);
    let placement = &model.placements[0];
    assert_eq!(placement.node_name, "leaf");
    // Parent translation then child scale: (1, 0, 1) lands at (3, 2, 3).
    assert!((placement.transform.transform_point3(Vec3::new(1.0, 0.0, 1.0)) - Vec3::new(3.0, 2.0, 3.0)).length() < 1e-6);
    assert_eq!(model.cameras.len(), 1);
    assert!((model.cameras[0].position - Vec3::new(0.0, 1.0, 10.0)).length() < 1e-6);
    assert!((model.cameras[0].fov_y - 0.8).abs() < 1e-6);
}

#[test]
fn gltf_embedded_external_and_binary_agree() {
    let dir = scratch("gltf");
    let indices = [0, 2, 1, 0, 3, 2];
    let buffer = square_buffer(&indices);
    let data_uri = format!("data:application/octet-stream;base64,{}", base64(&buffer));
    let embedded = write(&dir, "embedded.gltf", gltf_json(Some(&data_uri), buffer.len(), 6, 4, "VEC3"));
    check_square_model(&load_model(&embedded).unwrap(), 2);
    write(&dir, "square.bin", &buffer);
    let external = write(&dir, "external.gltf", gltf_json(Some("square.bin"), buffer.len(), 6, 4, "VEC3"));
    check_square_model(&load_model(&external).unwrap(), 2);
    let binary = write(&dir, "binary.glb", glb(&gltf_json(None, buffer.len(), 6, 4, "VEC3"), &buffer));
    check_square_model(&load_model(&binary).unwrap(), 2);
}

#[test]
fn gltf_strips_and_fans_become_lists() {
    let dir = scratch("gltf-modes");
    let strip = square_buffer(&[0, 1, 3, 2]);
    write(&dir, "strip.bin", &strip);
    let model = load_model(&write(&dir, "strip.gltf", gltf_json(Some("strip.bin"), strip.len(), 4, 5, "VEC3"))).unwrap();
    assert_eq!(model.meshes[0].indices, vec![0, 1, 3, 3, 1, 2]);
    let fan = square_buffer(&[0, 1, 2, 3]);
    write(&dir, "fan.bin", &fan);
    let model = load_model(&write(&dir, "fan.gltf", gltf_json(Some("fan.bin"), fan.len(), 4, 6, "VEC3"))).unwrap();
    assert_eq!(model.meshes[0].indices, vec![0, 1, 2, 0, 2, 3]);
}

#[test]
fn gltf_bad_input() {
    let dir = scratch("gltf-bad");
    let buffer = square_buffer(&[0, 2, 1, 0, 3, 9]);
    // Index out of range.
    write(&dir, "range.bin", &buffer);
    let range = write(&dir, "range.gltf", gltf_json(Some("range.bin"), buffer.len(), 6, 4, "VEC3"));
    let e = load_model(&range).unwrap_err();
    assert!(matches!(e, SceneError::InvalidIndex { index: 9, .. }) && names_file(&e, &range), "{e}");
    // Missing external buffer.
    let missing = write(&dir, "missing.gltf", gltf_json(Some("nowhere.bin"), buffer.len(), 6, 4, "VEC3"));
    let e = load_model(&missing).unwrap_err();
    assert!(names_file(&e, &missing), "{e}");
    // Buffer shorter than declared.
    write(&dir, "short.bin", &buffer[..40]);
    let short = write(&dir, "short.gltf", gltf_json(Some("short.bin"), buffer.len(), 6, 4, "VEC3"));
    assert!(names_file(&load_model(&short).unwrap_err(), &short));
    // Wrong accessor type for POSITION.
    let typed = write(&dir, "type.gltf", gltf_json(Some("range.bin"), buffer.len(), 6, 4, "VEC2"));
    assert!(names_file(&load_model(&typed).unwrap_err(), &typed));
    // Truncated JSON and truncated GLB.
    let text = gltf_json(Some("range.bin"), buffer.len(), 6, 4, "VEC3");
    let cut = write(&dir, "cut.gltf", &text[..text.len() / 2]);
    assert!(matches!(load_model(&cut).unwrap_err(), SceneError::Malformed { format: "glTF", .. }));
    let good = square_buffer(&[0, 2, 1, 0, 3, 2]);
    let mut binary = glb(&gltf_json(None, good.len(), 6, 4, "VEC3"), &good);
    binary.truncate(binary.len() - 10);
    let truncated = write(&dir, "truncated.glb", &binary);
    assert!(names_file(&load_model(&truncated).unwrap_err(), &truncated));
    let mut lying = glb(&gltf_json(None, good.len(), 6, 4, "VEC3"), &good);
    lying[8..12].copy_from_slice(&4u32.to_le_bytes());
    let lying = write(&dir, "lying.glb", &lying);
    assert!(names_file(&load_model(&lying).unwrap_err(), &lying));
    // A node that is its own grandchild: an error, not a hang.
    write(&dir, "good.bin", &good);
    let cyclic_text = gltf_json(Some("good.bin"), good.len(), 6, 4, "VEC3")
        .replace(r#""mesh": 0, "scale": [3, 3, 3]"#, r#""mesh": 0, "scale": [3, 3, 3], "children": [0]"#);
    let cyclic = write(&dir, "cycle.gltf", cyclic_text);
    assert!(names_file(&load_model(&cyclic).unwrap_err(), &cyclic));
    // NaN in a node transform reaches the scene as a non-finite transform: rejected on validation.
    let nan_text =
        gltf_json(Some("good.bin"), good.len(), 6, 4, "VEC3").replace(r#""translation": [0, 2, 0]"#, r#""translation": [0, 1e39, 0]"#);
    let nan = write(&dir, "nan.gltf", nan_text);
    if let Ok(model) = load_model(&nan) {
        let manifest = format!(
            "[[light]]\ncentre = [0, 4, 0]\nnormal = [0, -1, 0]\nsize = [1, 1]\n[[object]]\nmodel = \"{}\"\n",
            nan.file_name().unwrap().to_str().unwrap()
        );
        let manifest_path = write(&dir, "nan.toml", manifest);
        assert!(!model.placements.is_empty());
        assert!(Scene::load(manifest_path.to_str().unwrap()).is_err());
    }
}

#[test]
fn unsupported_and_missing_files() {
    let dir = scratch("misc");
    let stl = write(&dir, "model.stl", "solid");
    assert!(matches!(load_model(&stl).unwrap_err(), SceneError::UnsupportedFormat { .. }));
    let missing = dir.join("absent.obj");
    let e = load_model(&missing).unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }) && names_file(&e, &missing), "{e}");
    let e = Scene::load("no-such-scene").unwrap_err();
    assert!(e.to_string().contains("parallel-square"), "unknown names list the built-ins: {e}");
    // A manifest pointing at a missing model names the model.
    let manifest =
        write(&dir, "scene.toml", "[[light]]\ncentre = [0, 4, 0]\nnormal = [0, -1, 0]\nsize = [1, 1]\n[[object]]\nmodel = \"gone.ply\"\n");
    let e = Scene::load(manifest.to_str().unwrap()).unwrap_err();
    assert!(e.to_string().contains("gone.ply"), "{e}");
    // An unknown role override is a typo, not a silent no-op.
    write(&dir, "cube.obj", CUBE_OBJ);
    let typo = write(
        &dir,
        "typo.toml",
        "[[light]]\ncentre = [0, 4, 0]\nnormal = [0, -1, 0]\nsize = [1, 1]\n[[object]]\nmodel = \"cube.obj\"\nroles = { cueb = \"occluder\" }\n",
    );
    let e = Scene::load(typo.to_str().unwrap()).unwrap_err();
    assert!(e.to_string().contains("cueb"), "{e}");
}

#[test]
fn a_bare_model_is_staged_and_the_staging_round_trips() {
    let dir = scratch("stage");
    let model = write(&dir, "cube.obj", CUBE_OBJ);
    let manifest = stage_model(&model).unwrap();
    let (scene, _) = Scene::load(model.to_str().unwrap()).unwrap();
    assert_eq!(scene.instances.len(), 2);
    assert_eq!(scene.instances[0].role, Role::Both);
    assert_eq!(scene.instances[1].role, Role::Receiver);
    // The ground lies under the model; the light is above it, facing down; the camera sees the model.
    let ground = scene.bounds_where(|r| r == Role::Receiver);
    assert!(ground.max.y <= -1.0 + 1e-3 && ground.size().x >= 6.0);
    assert!(scene.lights[0].centre.y > 1.0 && scene.lights[0].normal().y < -0.5);
    // It faces the model's centre.
    assert!(scene.lights[0].normal().dot((Vec3::ZERO - scene.lights[0].centre).normalize()) > 0.999);
    let to_model = (Vec3::ZERO - scene.camera.position).normalize();
    assert!(to_model.dot((scene.camera.target - scene.camera.position).normalize()) > 0.99);
    // Saved beside the model, the printed manifest builds the same scene.
    let saved = write(&dir, "staged.toml", manifest.to_toml());
    let (again, _) = Scene::load(saved.to_str().unwrap()).unwrap();
    assert_eq!(again.instances.len(), scene.instances.len());
    assert_eq!(again.lights, scene.lights);
    assert_eq!(again.bounds(), scene.bounds());
}
