//! The loader corpus (`tests/corpus/`): small files written the way real
//! exporters write them (Blender, 3ds Max, Maya, MeshLab, ZBrush, SketchUp,
//! Stanford's scanners, gltfpack) and the awkward cases around them. Each file
//! has its exact expected outcome here: it loads with so many meshes and
//! triangles, through [`load_model`] and through [`Scene::load`] as
//! `ssm render --scene FILE` does, or it fails with a one-line message that
//! names the file and says why.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use glam::Vec3;
use ssm_scene::{LoadedModel, Scene, load_model};

/// What loading a corpus file must give.
enum Expect {
    /// It loads with this many meshes and triangles in all.
    Loads { meshes: usize, triangles: usize },
    /// It fails, and the message holds each of these.
    Fails(&'static [&'static str]),
}

use Expect::{Fails, Loads};

const GLTF_1: &[&str] = &["glTF 1.0 is not supported", "convert the file to glTF 2.0"];
const DRACO: &[&str] = &["KHR_draco_mesh_compression", "is not supported", "re-export"];

const CASES: &[(&str, Expect)] = &[
    // OBJ.
    ("obj/blender-2.69.obj", Loads { meshes: 1, triangles: 12 }),
    ("obj/usemtl-empty.obj", Loads { meshes: 1, triangles: 12 }),
    ("obj/3dsmax.obj", Loads { meshes: 1, triangles: 12 }),
    ("obj/maya.obj", Loads { meshes: 1, triangles: 12 }),
    ("obj/meshlab-colors.obj", Loads { meshes: 1, triangles: 4 }),
    ("obj/zbrush-polypaint.obj", Loads { meshes: 1, triangles: 2 }),
    ("obj/sketchup-concave-ngon.obj", Loads { meshes: 1, triangles: 4 }),
    ("obj/relative-tabs-bom-misc.obj", Loads { meshes: 2, triangles: 3 }),
    ("obj/msvc-nan-normals.obj", Loads { meshes: 1, triangles: 1 }),
    ("obj/msvc-nan-position.obj", Fails(&["line 2", "`-1.#IND00` is not a number", "NaN"])),
    ("obj/mac-cr-vt1.obj", Loads { meshes: 1, triangles: 1 }),
    ("obj/freeform-only.obj", Fails(&["free-form geometry", "is not supported", "no polygonal faces"])),
    ("obj/utf16.obj", Fails(&["UTF-16 text is not supported", "UTF-8"])),
    ("obj/index-zero.obj", Fails(&["line 4", "index 0 is invalid"])),
    ("obj/vertex-index-out-of-range.obj", Fails(&["line 4", "vertex index 9 is out of range", "3 vertices"])),
    ("obj/normal-index-without-normals.obj", Loads { meshes: 1, triangles: 1 }),
    ("obj/bunny-patch.obj", Loads { meshes: 1, triangles: 120 }),
    // PLY.
    ("ply/meshlab-binary-le.ply", Loads { meshes: 1, triangles: 12 }),
    ("ply/blender-2.69-ascii.ply", Loads { meshes: 1, triangles: 12 }),
    ("ply/stanford-big-endian.ply", Loads { meshes: 1, triangles: 2 }),
    ("ply/crlf-ascii.ply", Loads { meshes: 1, triangles: 1 }),
    ("ply/tristrips.ply", Loads { meshes: 1, triangles: 4 }),
    ("ply/concave-ngon-extra-elements.ply", Loads { meshes: 1, triangles: 4 }),
    ("ply/huge-count.ply", Fails(&["element `vertex` declares 4000000000 entries", "bytes follow the header"])),
    ("ply/empty-element.ply", Loads { meshes: 1, triangles: 1 }),
    ("ply/point-cloud.ply", Fails(&["no `face` element"])),
    ("ply/nan.ply", Fails(&["vertex 1 has a non-finite position"])),
    // glTF: gltfpack's outputs of obj/bunny-patch.obj, plain, quantised and meshopt-compressed.
    ("gltf/gltfpack-noq.glb", Loads { meshes: 1, triangles: 120 }),
    ("gltf/gltfpack-quantized.glb", Loads { meshes: 1, triangles: 120 }),
    ("gltf/gltfpack-meshopt.glb", Loads { meshes: 1, triangles: 120 }),
    ("gltf/gltfpack-meshopt-cc-khr.glb", Loads { meshes: 1, triangles: 120 }),
    ("gltf/gltfpack-meshopt-fallback.glb", Loads { meshes: 1, triangles: 120 }),
    ("gltf/gltfpack-meshopt-vpf.glb", Loads { meshes: 1, triangles: 120 }),
    // glTF: hand-written.
    ("gltf/draco-required.gltf", Fails(DRACO)),
    ("gltf/draco-used-no-fallback.gltf", Fails(DRACO)),
    ("gltf/draco-used-with-fallback.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/meshopt-corrupt.gltf", Fails(&["bufferView 0", "EXT_meshopt_compression", "cannot decode"])),
    ("gltf/instancing-required.gltf", Fails(&["the glTF extension EXT_mesh_gpu_instancing", "is not supported"])),
    ("gltf/materials-required.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/unknown-used.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/broken-material.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/no-scene.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/no-nodes.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/missing-bin.gltf", Fails(&["buffer 0 refers to", "does-not-exist.bin", "cannot be read"])),
    ("gltf/escaped-uri.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/data-uri-bom.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/sparse.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/interleaved.gltf", Loads { meshes: 1, triangles: 2 }),
    ("gltf/expanding-shared-accessor.gltf", Fails(&["primitive 4 POSITION: accessor 0", "more than a file of its size can hold"])),
    ("gltf/bad-stride.gltf", Fails(&["accessor 0", "byteStride 4", "smaller than one element"])),
    ("gltf/gltf-1.0.gltf", Fails(GLTF_1)),
    ("gltf/gltf-1.0-no-asset.gltf", Fails(GLTF_1)),
    ("gltf/gltf-1.0-binary.glb", Fails(GLTF_1)),
];

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

fn load(name: &str) -> LoadedModel {
    load_model(&corpus().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn triangles(model: &LoadedModel) -> usize {
    model.meshes.iter().map(|m| m.triangle_count()).sum()
}

/// World-space vertices of every placement.
fn world_vertices(model: &LoadedModel) -> Vec<Vec3> {
    model.placements.iter().flat_map(|p| model.meshes[p.mesh].positions.iter().map(|&v| p.transform.transform_point3(v))).collect()
}

/// Total area of the placed triangles.
fn area(model: &LoadedModel) -> f32 {
    model
        .placements
        .iter()
        .flat_map(|p| {
            model.meshes[p.mesh]
                .triangles()
                .map(move |t| t.map(|i| p.transform.transform_point3(model.meshes[p.mesh].positions[i as usize])))
        })
        .map(|[a, b, c]| (b - a).cross(c - a).length() * 0.5)
        .sum()
}

#[test]
fn every_corpus_file_has_its_expected_outcome() {
    let mut failures = Vec::new();
    for (name, expect) in CASES {
        let path = corpus().join(name);
        let outcome = load_model(&path);
        let staged = Scene::load(path.to_str().unwrap());
        match (expect, outcome, staged) {
            (Loads { meshes, triangles: expected }, Ok(model), Ok(_)) => {
                let got = (model.meshes.len(), triangles(&model));
                if got != (*meshes, *expected) {
                    failures.push(format!("{name}: expected {meshes} meshes and {expected} triangles, got {got:?}"));
                }
            }
            (Loads { .. }, Err(e), _) | (Loads { .. }, _, Err(e)) => failures.push(format!("{name}: expected to load, got: {e}")),
            (Fails(parts), Err(e), Err(staged)) => {
                let message = e.to_string();
                if !message.starts_with(&path.display().to_string()) || message.contains('\n') || message != staged.to_string() {
                    failures.push(format!("{name}: the message must be one line starting with the file's path: {message:?}"));
                }
                if let Some(missing) = parts.iter().find(|p| !message.contains(*p)) {
                    failures.push(format!("{name}: the message lacks `{missing}`: {message}"));
                }
            }
            (Fails(_), Ok(_), _) | (Fails(_), _, Ok(_)) => failures.push(format!("{name}: expected to fail, but it loads")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_corpus_file_is_listed() {
    for folder in ["obj", "ply", "gltf"] {
        for entry in std::fs::read_dir(corpus().join(folder)).unwrap() {
            let name = format!("{folder}/{}", entry.unwrap().file_name().to_string_lossy());
            let is_model = [".obj", ".ply", ".gltf", ".glb"].iter().any(|e| name.ends_with(e));
            assert!(!is_model || CASES.iter().any(|(listed, _)| *listed == name), "{name} has no expected outcome in CASES");
        }
    }
}

#[test]
fn gltfpack_outputs_match_their_source_after_dequantisation_and_decompression() {
    let source = world_vertices(&load("obj/bunny-patch.obj"));
    let source_area = area(&load("obj/bunny-patch.obj"));
    for name in [
        "gltf/gltfpack-noq.glb",
        "gltf/gltfpack-quantized.glb",
        "gltf/gltfpack-meshopt.glb",
        "gltf/gltfpack-meshopt-cc-khr.glb",
        "gltf/gltfpack-meshopt-fallback.glb",
        "gltf/gltfpack-meshopt-vpf.glb",
    ] {
        let model = load(name);
        // 14-bit positions over a patch about 0.1 across: within 1e-4 of a source vertex.
        for v in world_vertices(&model) {
            let nearest = source.iter().map(|s| s.distance(v)).fold(f32::INFINITY, f32::min);
            assert!(nearest < 1e-4, "{name}: {v} is {nearest} from the nearest source vertex");
        }
        assert!((area(&model) - source_area).abs() < 1e-3 * source_area, "{name}: area {} against {source_area}", area(&model));
        // Quantised normals are decoded to unit length.
        assert!(model.meshes[0].normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4), "{name}");
    }
}

#[test]
fn concave_polygons_are_covered_once() {
    for name in ["obj/sketchup-concave-ngon.obj", "ply/concave-ngon-extra-elements.ply"] {
        let model = load(name);
        assert!((area(&model) - 3.0).abs() < 1e-5, "{name}: area {}", area(&model));
        // Every triangle faces +Y, as the polygon does.
        let mesh = &model.meshes[0];
        for [a, b, c] in mesh.triangles().map(|t| t.map(|i| mesh.positions[i as usize])) {
            assert!((b - a).cross(c - a).y > 0.0, "{name}: a triangle faces down");
        }
    }
}

#[test]
fn details_of_single_cases() {
    // Relative indices, a continued face and a face before its vertices: two named objects.
    let model = load("obj/relative-tabs-bom-misc.obj");
    let names: Vec<&str> = model.meshes.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["first quad", "second"]);
    assert!((area(&model) - 1.5).abs() < 1e-6, "{}", area(&model));
    // Maya's empty `g default` gives way to the group that has the faces.
    assert_eq!(load("obj/maya.obj").meshes[0].name, "pCube1");
    // 3ds Max's Latin-1 object name survives as far as it is ASCII.
    let name = load("obj/3dsmax.obj").meshes[0].name.clone();
    assert!(name.starts_with("Bo") && name.ends_with("te001"), "{name}");
    // A NaN normal in the file is replaced by a computed one.
    let mesh = &load("obj/msvc-nan-normals.obj").meshes[0];
    assert!(mesh.normals.iter().all(|n| (*n - Vec3::Y).length() < 1e-6), "{:?}", mesh.normals);
    // The file's own normals are kept: interleaved with the positions, and per corner in OBJ.
    assert!(load("gltf/interleaved.gltf").meshes[0].normals.iter().all(|n| *n == Vec3::Y));
    let cube = &load("obj/blender-2.69.obj").meshes[0];
    assert_eq!(cube.positions.len(), 24, "one vertex per (position, normal) pair");
    // The sparse accessor lifts one corner of the square.
    let lifted = world_vertices(&load("gltf/sparse.gltf"));
    assert_eq!(lifted.iter().filter(|v| v.y == 1.0).count(), 1, "{lifted:?}");
    // Stanford's strips: two strips of two triangles.
    assert_eq!(load("ply/tristrips.ply").meshes[0].indices, vec![0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 3, 5]);
    // Big-endian doubles decode to the unit square.
    let square = load("ply/stanford-big-endian.ply");
    assert!((area(&square) - 1.0).abs() < 1e-6);
}
