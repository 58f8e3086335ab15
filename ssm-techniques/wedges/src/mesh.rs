//! The casting mesh as the silhouette passes read it, prepared once at setup
//! from the framework's adjacency (`Requirements::adjacency`): welded
//! positions, faces, and one record per edge incidence. Nothing here depends
//! on the light: silhouettes are found on the GPU every frame.
//!
//! **The rule for meshes that are not closed.** A connected component of the
//! casting mesh whose every edge is shared by exactly two faces winding it in
//! opposite directions is *closed*: its shadow volume is the classic one of
//! its faces turned towards the light. Any other component (an open edge, an
//! edge of three or more faces, two faces winding an edge the same way) is
//! *two-sided*: every face takes part, turned to face the light, and the
//! volume is the union of the faces' prisms. Both give a stencil count that
//! is exactly the number of prisms (or closed volumes) a point is in, so no
//! input leaks light; a two-sided closed surface would be counted twice in
//! the penumbra, which is why closed components stay one-sided.

use std::collections::HashMap;

use ssm_scene::Adjacency;

/// No second face: [`EdgeRecord::face_b`] of an incidence recorded alone.
pub const NO_FACE: u32 = u32::MAX;

/// Face flag (`faces[f].flags`): the face's component is two-sided.
pub const FACE_TWO_SIDED: u32 = 1;

/// One edge incidence as `shaders/wedges/wedges_common.wgsl` reads it (`EdgeRecord`):
/// `v0 -> v1` as `face_a` winds it; `face_b`, when not [`NO_FACE`], winds it `v1 -> v0`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct EdgeRecord {
    /// First welded vertex.
    pub v0: u32,
    /// Second welded vertex.
    pub v1: u32,
    /// The face that winds `v0 -> v1`.
    pub face_a: u32,
    /// The face that winds `v1 -> v0`, or [`NO_FACE`].
    pub face_b: u32,
}

/// What the preparation found, for messages and diagnostics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshReport {
    /// Faces (triangles) of the casting geometry.
    pub faces: usize,
    /// Faces with two equal welded corners (collapsed): kept, they bound nothing.
    pub collapsed_faces: usize,
    /// Edges used by one face.
    pub open_edges: usize,
    /// Edges used by three or more faces.
    pub non_manifold_edges: usize,
    /// Edges of two faces that wind them the same way.
    pub inconsistent_edges: usize,
    /// Connected components.
    pub components: usize,
    /// Components treated as two-sided (the rule above).
    pub two_sided_components: usize,
}

/// The casting mesh, ready to upload.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CastingMesh {
    /// Welded world-space positions (w = 1).
    pub positions: Vec<[f32; 4]>,
    /// Per face: three welded vertex ids and flags ([`FACE_TWO_SIDED`]).
    pub faces: Vec<[u32; 4]>,
    /// Edge incidences: paired where the edge is manifold and consistently wound, else one per face.
    pub records: Vec<EdgeRecord>,
    /// The most silhouette half-edges one frame can emit: two per paired record, one per single.
    pub half_edge_capacity: u32,
    /// What was found.
    pub report: MeshReport,
}

/// An undirected edge: its welded vertices, smaller first.
type EdgeKey = (u32, u32);

/// One face's traversal of an edge: from, to, face.
type Incidence = (u32, u32, u32);

/// Union–find over faces, for the connected components.
struct Components {
    parent: Vec<u32>,
}

impl Components {
    fn new(count: usize) -> Self {
        Self { parent: (0..count as u32).collect() }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

impl CastingMesh {
    /// Prepares the adjacency's welded mesh: records per edge, components, and the two-sided rule.
    #[must_use]
    pub fn prepare(adjacency: &Adjacency) -> Self {
        let positions = adjacency.welded_positions.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
        let face_count = adjacency.triangles.len();
        let mut report = MeshReport { faces: face_count, ..MeshReport::default() };
        // Every directed edge (from, to, face), grouped by undirected key in first-seen order.
        let mut order: Vec<EdgeKey> = Vec::new();
        let mut incidences: HashMap<EdgeKey, Vec<Incidence>> = HashMap::new();
        for (face, triangle) in adjacency.triangles.iter().enumerate() {
            if triangle[0] == triangle[1] || triangle[1] == triangle[2] || triangle[2] == triangle[0] {
                report.collapsed_faces += 1;
            }
            for k in 0..3 {
                let (from, to) = (triangle[k], triangle[(k + 1) % 3]);
                if from == to {
                    continue; // a collapsed edge bounds nothing
                }
                let key = (from.min(to), from.max(to));
                incidences
                    .entry(key)
                    .or_insert_with(|| {
                        order.push(key);
                        Vec::new()
                    })
                    .push((from, to, face as u32));
            }
        }
        let mut components = Components::new(face_count);
        let mut records = Vec::with_capacity(order.len());
        let mut irregular_faces = Vec::new();
        let mut half_edge_capacity: u64 = 0;
        for key in &order {
            let Some(list) = incidences.get(key) else { continue };
            for pair in list.windows(2) {
                components.union(pair[0].2, pair[1].2);
            }
            match list.as_slice() {
                [(from, to, face_a), (from_b, to_b, face_b)] if from == to_b && to == from_b => {
                    records.push(EdgeRecord { v0: *from, v1: *to, face_a: *face_a, face_b: *face_b });
                    half_edge_capacity += 2;
                }
                _ => {
                    match list.len() {
                        1 => report.open_edges += 1,
                        2 => report.inconsistent_edges += 1,
                        _ => report.non_manifold_edges += 1,
                    }
                    for &(from, to, face) in list {
                        records.push(EdgeRecord { v0: from, v1: to, face_a: face, face_b: NO_FACE });
                        irregular_faces.push(face);
                    }
                    half_edge_capacity += list.len() as u64;
                }
            }
        }
        let mut two_sided_roots: Vec<u32> = irregular_faces.iter().map(|f| components.find(*f)).collect();
        two_sided_roots.sort_unstable();
        two_sided_roots.dedup();
        let mut roots: Vec<u32> = (0..face_count as u32).map(|f| components.find(f)).collect();
        let faces = adjacency
            .triangles
            .iter()
            .zip(&roots)
            .map(|(t, root)| {
                let flags = if two_sided_roots.binary_search(root).is_ok() { FACE_TWO_SIDED } else { 0 };
                [t[0], t[1], t[2], flags]
            })
            .collect();
        roots.sort_unstable();
        roots.dedup();
        report.components = roots.len();
        report.two_sided_components = two_sided_roots.len();
        Self { positions, faces, records, half_edge_capacity: u32::try_from(half_edge_capacity).unwrap_or(u32::MAX), report }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use glam::{Vec2, Vec3};
    use ssm_scene::Mesh;
    use ssm_scene::primitives::{cuboid, plane, sphere};

    use super::*;

    fn prepared(mesh: &Mesh) -> CastingMesh {
        CastingMesh::prepare(&Adjacency::of(mesh))
    }

    #[test]
    fn a_closed_mesh_is_one_sided_with_paired_records() {
        let ball = prepared(&sphere("s", 1.0, 12, 6));
        assert_eq!(ball.report.two_sided_components, 0);
        assert_eq!(ball.report.components, 1);
        assert!(ball.records.iter().all(|r| r.face_b != NO_FACE));
        assert!(ball.faces.iter().all(|f| f[3] == 0));
        assert_eq!(ball.records.len() * 3, ball.faces.len() * 3 * 3 / 2, "E = 3F/2");
        let cube = prepared(&cuboid("c", Vec3::ONE));
        assert_eq!((cube.report.components, cube.report.two_sided_components), (1, 0));
    }

    #[test]
    fn an_open_mesh_is_two_sided() {
        let quad = prepared(&plane("p", Vec2::ONE));
        assert_eq!((quad.report.open_edges, quad.report.two_sided_components), (4, 1));
        assert!(quad.faces.iter().all(|f| f[3] == FACE_TWO_SIDED));
        // The diagonal is paired, the four borders are single.
        assert_eq!(quad.records.iter().filter(|r| r.face_b == NO_FACE).count(), 4);
        assert_eq!(quad.half_edge_capacity, 2 + 4);
    }

    #[test]
    fn a_non_manifold_edge_makes_its_component_two_sided_and_records_every_face() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Y];
        let fin = Mesh::with_generated_normals("fin", positions, vec![0, 1, 2, 1, 0, 3, 0, 1, 4]);
        let mesh = prepared(&fin);
        assert_eq!(mesh.report.non_manifold_edges, 1);
        assert_eq!(mesh.report.two_sided_components, 1);
        let shared: Vec<&EdgeRecord> = mesh.records.iter().filter(|r| (r.v0.min(r.v1), r.v0.max(r.v1)) == (0, 1)).collect();
        assert_eq!(shared.len(), 3, "one single record per face on the shared edge");
    }

    #[test]
    fn separate_objects_are_separate_components_and_keep_their_own_rule() {
        // A closed cube and an open quad, far apart, in one mesh.
        let cube = cuboid("c", Vec3::ONE);
        let quad = plane("p", Vec2::ONE);
        let offset = cube.positions.len() as u32;
        let mut positions = cube.positions.clone();
        positions.extend(quad.positions.iter().map(|p| *p + Vec3::new(5.0, 0.0, 0.0)));
        let mut indices = cube.indices.clone();
        indices.extend(quad.indices.iter().map(|i| i + offset));
        let both = prepared(&Mesh::with_generated_normals("both", positions, indices));
        assert_eq!((both.report.components, both.report.two_sided_components), (2, 1));
        assert_eq!(both.faces.iter().filter(|f| f[3] == FACE_TWO_SIDED).count(), 2);
    }

    #[test]
    fn collapsed_faces_are_kept_and_their_collapsed_edges_dropped() {
        let positions = vec![Vec3::ZERO, Vec3::ZERO, Vec3::X];
        let mesh = prepared(&Mesh::with_generated_normals("needle", positions, vec![0, 1, 2]));
        assert_eq!(mesh.report.collapsed_faces, 1);
        assert_eq!(mesh.faces.len(), 1);
        // The welded triangle is (0, 0, 1): one real edge, traversed twice the same way... or once each way.
        assert!(mesh.records.len() <= 2);
    }
}
