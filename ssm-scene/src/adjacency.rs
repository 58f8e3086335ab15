//! Edge–face adjacency, for silhouette extraction (penumbra wedges, shadow volumes).

use std::collections::HashMap;

use glam::Vec3;

use crate::mesh::Mesh;

/// Marker for "no second face" in [`Edge::faces`].
pub const NO_FACE: u32 = u32::MAX;

/// One undirected edge and the triangles that share it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    /// Welded vertex ids, in the order the edge runs in `faces[0]`'s winding.
    pub vertices: [u32; 2],
    /// The first two faces using the edge; `faces[1] == NO_FACE` on an open edge.
    pub faces: [u32; 2],
    /// Number of faces using the edge: 1 open, 2 manifold, more non-manifold.
    pub face_count: u32,
}

/// Adjacency of one mesh, computed on welded positions so that seams split for
/// normals or texture coordinates do not open the surface.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Adjacency {
    /// Positions after welding bit-identical ones.
    pub welded_positions: Vec<Vec3>,
    /// Triangles as welded vertex ids; same order as the mesh's triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Every edge once.
    pub edges: Vec<Edge>,
}

impl Adjacency {
    /// Computes the adjacency of `mesh` (indices must be valid).
    #[must_use]
    pub fn of(mesh: &Mesh) -> Self {
        let mut weld: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.positions.len());
        let mut welded_positions = Vec::new();
        let remap: Vec<u32> = mesh
            .positions
            .iter()
            .map(|p| {
                // -0.0 and 0.0 are the same point.
                let key = (*p + Vec3::ZERO).to_array().map(f32::to_bits);
                *weld.entry(key).or_insert_with(|| {
                    welded_positions.push(*p);
                    welded_positions.len() as u32 - 1
                })
            })
            .collect();
        let triangles: Vec<[u32; 3]> = mesh.triangles().map(|t| t.map(|i| remap[i as usize])).collect();

        let mut edges: Vec<Edge> = Vec::new();
        let mut by_key: HashMap<(u32, u32), usize> = HashMap::new();
        for (face, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if a == b {
                    continue; // a collapsed edge of a degenerate triangle bounds nothing
                }
                let key = (a.min(b), a.max(b));
                match by_key.get(&key) {
                    Some(&e) => {
                        let edge = &mut edges[e];
                        if edge.face_count == 1 {
                            edge.faces[1] = face as u32;
                        }
                        edge.face_count += 1;
                    }
                    None => {
                        by_key.insert(key, edges.len());
                        edges.push(Edge { vertices: [a, b], faces: [face as u32, NO_FACE], face_count: 1 });
                    }
                }
            }
        }
        Self { welded_positions, triangles, edges }
    }

    /// Edges used by one face only: holes and borders.
    #[must_use]
    pub fn open_edge_count(&self) -> usize {
        self.edges.iter().filter(|e| e.face_count == 1).count()
    }

    /// Edges used by more than two faces.
    #[must_use]
    pub fn non_manifold_edge_count(&self) -> usize {
        self.edges.iter().filter(|e| e.face_count > 2).count()
    }

    /// True when every edge has exactly two faces.
    #[must_use]
    pub fn is_closed_manifold(&self) -> bool {
        self.edges.iter().all(|e| e.face_count == 2)
    }

    /// True when every edge has an even number of faces (two, or four where two closed parts
    /// touch): the triangles bound a volume, so a segment between two points off the surface
    /// crosses it an odd number of times exactly when one point is inside and the other outside.
    /// A manifold mesh with a hole, or a single quad, is not closed.
    #[must_use]
    pub fn is_closed(&self) -> bool {
        !self.edges.is_empty() && self.edges.iter().all(|e| e.face_count % 2 == 0)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;
    use crate::primitives::{cuboid, plane, sphere};

    #[test]
    fn closed_meshes_have_no_open_edges() {
        // The cuboid's 24 split vertices weld back to 8 corners.
        let cube = Adjacency::of(&cuboid("c", Vec3::ONE));
        assert_eq!(cube.welded_positions.len(), 8);
        assert_eq!(cube.edges.len(), 18);
        assert!(cube.is_closed_manifold());
        let ball = Adjacency::of(&sphere("s", 1.0, 12, 6));
        assert!(ball.is_closed_manifold());
        assert!(cube.is_closed() && ball.is_closed());
        // Euler: V - E + F = 2 for a sphere.
        assert_eq!(ball.welded_positions.len() as i64 - ball.edges.len() as i64 + ball.triangles.len() as i64, 2);
    }

    #[test]
    fn a_quad_has_four_open_edges_and_one_shared() {
        let quad = Adjacency::of(&plane("p", Vec2::ONE));
        assert_eq!(quad.open_edge_count(), 4);
        assert_eq!(quad.edges.iter().filter(|e| e.face_count == 2).count(), 1);
        assert!(!quad.is_closed());
    }

    #[test]
    fn two_closed_parts_touching_at_an_edge_are_closed_a_punctured_one_is_not() {
        // Two tetrahedra sharing the edge (0, 1): four faces on it, every other edge two.
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(0.5, 0.3, 1.0),
            Vec3::new(0.5, -1.0, 0.0),
            Vec3::new(0.5, -0.3, -1.0),
        ];
        let mut indices = vec![0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3];
        indices.extend_from_slice(&[0, 1, 4, 1, 0, 5, 4, 1, 5, 0, 4, 5]);
        let pair = Adjacency::of(&Mesh::with_generated_normals("pair", positions.clone(), indices.clone()));
        assert_eq!(pair.non_manifold_edge_count(), 1);
        assert!(pair.is_closed());
        indices.truncate(indices.len() - 3);
        assert!(!Adjacency::of(&Mesh::with_generated_normals("punctured", positions, indices)).is_closed());
    }

    #[test]
    fn three_faces_on_one_edge_are_non_manifold() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Y];
        let mesh = Mesh::with_generated_normals("fin", positions, vec![0, 1, 2, 1, 0, 3, 0, 1, 4]);
        assert_eq!(Adjacency::of(&mesh).non_manifold_edge_count(), 1);
    }
}
