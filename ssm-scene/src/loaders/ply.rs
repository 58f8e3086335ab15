//! Stanford PLY (ASCII and binary) through `ply-rs-bw`.

use std::path::Path;

use glam::{Mat4, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use super::{LoadedModel, Placement, malformed};
use crate::error::Result;
use crate::mesh::{Mesh, check_indices, fan_to_list, generate_normals};

fn scalar(element: &DefaultElement, key: &str) -> Option<f32> {
    match element.get(key)? {
        Property::Char(v) => Some(f32::from(*v)),
        Property::UChar(v) => Some(f32::from(*v)),
        Property::Short(v) => Some(f32::from(*v)),
        Property::UShort(v) => Some(f32::from(*v)),
        Property::Int(v) => Some(*v as f32),
        Property::UInt(v) => Some(*v as f32),
        Property::Float(v) => Some(*v),
        Property::Double(v) => Some(*v as f32),
        _ => None,
    }
}

fn index_list(element: &DefaultElement) -> Option<Vec<i64>> {
    let list = element.get("vertex_indices").or_else(|| element.get("vertex_index"))?;
    Some(match list {
        Property::ListChar(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUChar(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListShort(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUShort(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListInt(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUInt(v) => v.iter().map(|&i| i64::from(i)).collect(),
        _ => return None,
    })
}

pub(super) fn load(path: &Path, bytes: &[u8]) -> Result<LoadedModel> {
    let parser = Parser::<DefaultElement>::new();
    let ply = parser.read_ply(&mut &bytes[..]).map_err(|e| malformed(path, "PLY", e))?;
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("ply").to_owned();
    let vertices = ply.payload.get("vertex").ok_or_else(|| malformed(path, "PLY", "no `vertex` element"))?;
    let faces = ply.payload.get("face").ok_or_else(|| malformed(path, "PLY", "no `face` element (point clouds cast no shadows)"))?;

    let mut positions = Vec::with_capacity(vertices.len());
    let mut file_normals = Vec::with_capacity(vertices.len());
    for (index, vertex) in vertices.iter().enumerate() {
        let coordinate = |key| scalar(vertex, key).ok_or_else(|| malformed(path, "PLY", format!("vertex {index} has no scalar `{key}`")));
        positions.push(Vec3::new(coordinate("x")?, coordinate("y")?, coordinate("z")?));
        if let (Some(x), Some(y), Some(z)) = (scalar(vertex, "nx"), scalar(vertex, "ny"), scalar(vertex, "nz")) {
            file_normals.push(Vec3::new(x, y, z).normalize_or(Vec3::Y));
        }
    }

    let mut indices = Vec::with_capacity(faces.len() * 3);
    for (index, face) in faces.iter().enumerate() {
        let polygon =
            index_list(face).ok_or_else(|| malformed(path, "PLY", format!("face {index} has no integer `vertex_indices` list")))?;
        if let Some(&bad) = polygon.iter().find(|&&i| i < 0 || i >= positions.len() as i64) {
            return Err(crate::error::SceneError::InvalidIndex {
                file: path.into(),
                mesh: name.clone(),
                index: bad as u64,
                position: index,
                count: positions.len(),
            });
        }
        let polygon: Vec<u32> = polygon.into_iter().map(|i| i as u32).collect();
        indices.extend(fan_to_list(&polygon));
    }
    check_indices(path, &name, indices.iter().map(|&i| u64::from(i)), positions.len())?;
    let normals = if file_normals.len() == positions.len() { file_normals } else { generate_normals(&positions, &indices) };
    Ok(LoadedModel {
        meshes: vec![Mesh { name: name.clone(), positions, normals, indices }],
        placements: vec![Placement { mesh: 0, transform: Mat4::IDENTITY, node_name: name }],
        cameras: Vec::new(),
    })
}
