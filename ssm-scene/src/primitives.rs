//! Procedural meshes used by the built-in scenes and by manifests (`primitive = "..."`).

use glam::{Vec2, Vec3};

use crate::mesh::Mesh;

/// A `size.x` × `size.y` rectangle in the XZ plane centred on the origin, facing +Y.
#[must_use]
pub fn plane(name: &str, size: Vec2) -> Mesh {
    let (hx, hz) = (size.x * 0.5, size.y * 0.5);
    let positions = vec![Vec3::new(-hx, 0.0, -hz), Vec3::new(hx, 0.0, -hz), Vec3::new(hx, 0.0, hz), Vec3::new(-hx, 0.0, hz)];
    // Counter-clockwise seen from +Y.
    let indices = vec![0, 2, 1, 0, 3, 2];
    Mesh { name: name.into(), normals: vec![Vec3::Y; 4], positions, indices }
}

/// An axis-aligned box of edge lengths `size` centred on the origin, flat-shaded (24 vertices).
#[must_use]
pub fn cuboid(name: &str, size: Vec3) -> Mesh {
    let h = size * 0.5;
    let mut positions = Vec::with_capacity(24);
    let mut normals = Vec::with_capacity(24);
    let mut indices = Vec::with_capacity(36);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut normal = Vec3::ZERO;
            normal[axis] = sign;
            // Two tangents with tangent_a × tangent_b = normal, so the quad winds counter-clockwise outside.
            let tangent_a = Vec3::from_array(std::array::from_fn(|k| if k == (axis + 1) % 3 { 1.0 } else { 0.0 }));
            let tangent_b = normal.cross(tangent_a);
            let base = positions.len() as u32;
            for (s, t) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                positions.push((normal + tangent_a * s + tangent_b * t) * h);
                normals.push(normal);
            }
            indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    Mesh { name: name.into(), positions, normals, indices }
}

/// A closed UV sphere of `radius` centred on the origin, smooth normals.
///
/// `segments` around the equator (at least 3) and `rings` from pole to pole (at least 2).
/// The poles are single vertices, so the mesh is closed and manifold.
#[must_use]
pub fn sphere(name: &str, radius: f32, segments: u32, rings: u32) -> Mesh {
    let (segments, rings) = (segments.max(3), rings.max(2));
    let mut positions = vec![Vec3::Y];
    for ring in 1..rings {
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        for segment in 0..segments {
            let phi = std::f32::consts::TAU * segment as f32 / segments as f32;
            positions.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()));
        }
    }
    positions.push(-Vec3::Y);
    let south = positions.len() as u32 - 1;
    let ring_start = |ring: u32| 1 + (ring - 1) * segments;
    let mut indices = Vec::new();
    for segment in 0..segments {
        let next = (segment + 1) % segments;
        indices.extend_from_slice(&[0, ring_start(1) + segment, ring_start(1) + next]);
        let last = ring_start(rings - 1);
        indices.extend_from_slice(&[south, last + next, last + segment]);
    }
    for ring in 1..rings - 1 {
        let (upper, lower) = (ring_start(ring), ring_start(ring + 1));
        for segment in 0..segments {
            let next = (segment + 1) % segments;
            indices.extend_from_slice(&[upper + segment, lower + segment, lower + next]);
            indices.extend_from_slice(&[upper + segment, lower + next, upper + next]);
        }
    }
    let normals = positions.clone();
    Mesh { name: name.into(), positions: positions.into_iter().map(|p| p * radius).collect(), normals, indices }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sum of (centroid · face normal) over faces: positive when every face winds outwards.
    fn outward(mesh: &Mesh) -> bool {
        mesh.triangles().all(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            (b - a).cross(c - a).dot((a + b + c) / 3.0) > 0.0
        })
    }

    #[test]
    fn closed_primitives_wind_outwards() {
        assert!(outward(&cuboid("c", Vec3::ONE)));
        assert!(outward(&sphere("s", 1.0, 8, 6)));
        let p = plane("p", Vec2::ONE);
        let [a, b, c] = [0, 1, 2].map(|k| p.positions[p.indices[k] as usize]);
        assert!((b - a).cross(c - a).y > 0.0);
    }
}
