//! Wavefront OBJ through `tobj`.

use std::io::BufReader;
use std::path::Path;

use glam::{Mat4, Vec3};

use super::{LoadedModel, Placement, malformed};
use crate::error::Result;
use crate::mesh::{Mesh, check_indices, generate_normals};

pub(super) fn load(path: &Path, bytes: &[u8]) -> Result<LoadedModel> {
    // Other fields exist when tobj's `merging`/`reordering` features are on (another crate may enable them).
    #[allow(clippy::needless_update)]
    let options =
        tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true, ..Default::default() };
    // Materials are not needed; answering every `mtllib` with "none" keeps a missing .mtl from failing the load.
    let (models, _) = tobj::load_obj_buf(&mut BufReader::new(bytes), &options, |_| Err(tobj::LoadError::OpenFileFailed))
        .map_err(|e| malformed(path, "OBJ", e))?;
    let mut loaded = LoadedModel::default();
    for (index, model) in models.into_iter().enumerate() {
        let name = if model.name.is_empty() { format!("object-{index}") } else { model.name };
        let mesh = model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        if mesh.positions.len() % 3 != 0 {
            return Err(malformed(path, "OBJ", format!("object `{name}`: position array is not made of triples")));
        }
        let positions: Vec<Vec3> = mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        check_indices(path, &name, mesh.indices.iter().map(|&i| u64::from(i)), positions.len())?;
        let normals = if mesh.normals.len() == mesh.positions.len() {
            mesh.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or(Vec3::Y)).collect()
        } else {
            generate_normals(&positions, &mesh.indices)
        };
        loaded.meshes.push(Mesh { name: name.clone(), positions, normals, indices: mesh.indices });
        loaded.placements.push(Placement { mesh: loaded.meshes.len() - 1, transform: Mat4::IDENTITY, node_name: name });
    }
    Ok(loaded)
}
