//! glTF 2.0 (`.gltf` with external or embedded buffers, and `.glb`) through the `gltf` crate.

use std::path::Path;

use glam::{Mat4, Vec3};
use gltf::mesh::Mode;

use super::{LoadedModel, Placement, malformed};
use crate::camera::Camera;
use crate::error::{Result, SceneError};
use crate::mesh::{Mesh, check_indices, fan_to_list, generate_normals, strip_to_list};

/// Rejects a `.glb` whose header lies about its length before the parser does
/// arithmetic with it.
fn check_glb_header(path: &Path, bytes: &[u8]) -> Result<()> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let Some(length) = bytes.get(8..12).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize) else {
        return Err(malformed(path, "glTF", "binary header is truncated"));
    };
    if length < 12 || length > bytes.len() {
        return Err(malformed(path, "glTF", format!("binary header declares {length} bytes but the file has {}", bytes.len())));
    }
    Ok(())
}

pub(super) fn load(path: &Path, bytes: &[u8]) -> Result<LoadedModel> {
    check_glb_header(path, bytes)?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(bytes).map_err(|e| malformed(path, "glTF", e))?;
    let base = path.parent().unwrap_or_else(|| Path::new("."));
    let buffers = gltf::import_buffers(&document, Some(base), blob).map_err(|e| malformed(path, "glTF", format!("buffers: {e}")))?;

    let mut loaded = LoadedModel::default();
    // glTF meshes map one-to-one onto ours; their primitives are concatenated.
    for gltf_mesh in document.meshes() {
        let name = gltf_mesh.name().map_or_else(|| format!("mesh-{}", gltf_mesh.index()), str::to_owned);
        let mut mesh = Mesh { name: name.clone(), ..Mesh::default() };
        let mut normals_complete = true;
        for primitive in gltf_mesh.primitives() {
            let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(|data| &data.0[..]));
            let Some(positions) = reader.read_positions() else {
                return Err(malformed(path, "glTF", format!("mesh `{name}` primitive {} has no POSITION", primitive.index())));
            };
            let positions: Vec<Vec3> = positions.map(Vec3::from_array).collect();
            let count = positions.len();
            let local: Vec<u32> = match reader.read_indices() {
                Some(indices) => {
                    let indices: Vec<u32> = indices.into_u32().collect();
                    check_indices(path, &name, indices.iter().map(|&i| u64::from(i)), count)?;
                    indices
                }
                None => (0..count as u32).collect(),
            };
            let triangles = match primitive.mode() {
                Mode::Triangles => local.chunks_exact(3).flatten().copied().collect(),
                Mode::TriangleStrip => strip_to_list(&local),
                Mode::TriangleFan => fan_to_list(&local),
                // Points and lines cast no shadows.
                Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => continue,
            };
            let base_vertex = mesh.positions.len() as u32;
            match reader.read_normals() {
                Some(normals) => mesh.normals.extend(normals.map(|n| Vec3::from_array(n).normalize_or(Vec3::Y))),
                None => normals_complete = false,
            }
            mesh.positions.extend(positions);
            mesh.indices.extend(triangles.into_iter().map(|i: u32| i + base_vertex));
        }
        if !normals_complete || mesh.normals.len() != mesh.positions.len() {
            mesh.normals = generate_normals(&mesh.positions, &mesh.indices);
        }
        loaded.meshes.push(mesh);
    }

    let roots: Vec<gltf::Node<'_>> = match document.default_scene().or_else(|| document.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            // No scene: every node that is nobody's child is a root.
            let children: std::collections::HashSet<usize> = document.nodes().flat_map(|n| n.children().map(|c| c.index())).collect();
            document.nodes().filter(|n| !children.contains(&n.index())).collect()
        }
    };
    // Depth-first with an explicit stack (no recursion limit to hit) carrying each node's ancestors, so a cycle is found, not followed.
    let mut stack: Vec<(gltf::Node<'_>, Mat4, Vec<usize>)> = roots.into_iter().map(|n| (n, Mat4::IDENTITY, Vec::new())).collect();
    while let Some((node, parent, ancestors)) = stack.pop() {
        if ancestors.contains(&node.index()) {
            return Err(SceneError::NodeCycle { file: path.into(), node: node.index(), name: node.name().unwrap_or_default().into() });
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        let node_name = node.name().map(str::to_owned);
        if let Some(mesh) = node.mesh() {
            let node_name = node_name.clone().unwrap_or_else(|| loaded.meshes[mesh.index()].name.clone());
            loaded.placements.push(Placement { mesh: mesh.index(), transform: world, node_name });
        }
        if let Some(camera) = node.camera()
            && let gltf::camera::Projection::Perspective(perspective) = camera.projection()
        {
            let position = world.transform_point3(Vec3::ZERO);
            // glTF cameras look down their local -Z with +Y up.
            let forward = world.transform_vector3(-Vec3::Z).normalize_or(-Vec3::Z);
            let up = world.transform_vector3(Vec3::Y).normalize_or(Vec3::Y);
            let near = perspective.znear();
            loaded.cameras.push(Camera {
                position,
                target: position + forward,
                up,
                fov_y: perspective.yfov(),
                near,
                far: perspective.zfar().unwrap_or(near * 1.0e4),
            });
        }
        let mut lineage = ancestors;
        lineage.push(node.index());
        for child in node.children() {
            stack.push((child, world, lineage.clone()));
        }
    }
    Ok(loaded)
}
