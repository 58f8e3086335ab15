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
//!
//! **A closed component around the light.** Which faces of a closed component
//! bound its volume depends on which side of it the light is, so that is
//! decided on the GPU every frame from the component's winding number around
//! the light's centre (`wedges_winding`); each face therefore carries its
//! closed component's index.
//!
//! **Edges that meet without sharing vertices.** Two surfaces whose edges
//! overlap along a line but end at different points (a wall standing on
//! another's edge, a wall raised above the ground beside its neighbour; a
//! T-junction of a modelled mesh) share no welded edge, so each would be
//! its own silhouette there and their penumbrae would be blended (Sec. 3.2)
//! where they abut. A welded vertex lying on an open edge of another face
//! splits that face (`split_t_junctions`): the overlapping parts become
//! shared edges, which join the surfaces into one silhouette where their
//! sides cancel.
//!
//! **Convex closed components.** A closed component whose every edge is
//! convex bounds a convex solid (when it does not cross itself), which a ray
//! from the light enters or leaves once: it adds at most one to a point's
//! stencil count, whatever its face count. That bounds the count
//! (`stencil_levels_bound`) far more tightly than the faces do.

use std::collections::HashMap;

use glam::{IVec3, Vec3};
use ssm_scene::Adjacency;

/// No second face: [`EdgeRecord::face_b`] of an incidence recorded alone.
pub const NO_FACE: u32 = u32::MAX;

/// The component of a face whose connected component is two-sided (`faces[f][3]`; a closed
/// component's faces hold its index there instead).
pub const TWO_SIDED_COMPONENT: u32 = u32::MAX;

/// One edge incidence as `shaders/wedges/wedges_common.wgsl` reads it (`EdgeRecord`):
/// `v0 -> v1` as `face_a` winds it; `face_b`, when not [`NO_FACE`], winds it `v1 -> v0`, or
/// `v0 -> v1` as well when [`EdgeRecord::face_b_winds_forward`] is 1.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct EdgeRecord {
    /// First welded vertex.
    pub v0: u32,
    /// Second welded vertex.
    pub v1: u32,
    /// The face that winds `v0 -> v1`.
    pub face_a: u32,
    /// The face that winds `v1 -> v0` (or `v0 -> v1`, see `face_b_winds_forward`), or [`NO_FACE`].
    pub face_b: u32,
    /// 1 when `face_b` winds the edge `v0 -> v1` like `face_a`: two faces of a two-sided surface
    /// whose windings disagree (two open quads meeting at a corner, one wound inwards and one
    /// outwards). Each frame turns such faces to the light, after which their sides on the edge
    /// may cancel like any manifold edge's; else 0.
    pub face_b_winds_forward: u32,
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
    /// Closed components whose every edge is convex.
    pub convex_components: usize,
    /// Faces split because a welded vertex lay on one of their open edges (T-junctions).
    pub split_faces: usize,
}

impl MeshReport {
    /// Closed components: the winding numbers computed per light and frame.
    #[must_use]
    pub fn closed_components(&self) -> usize {
        self.components - self.two_sided_components
    }
}

/// The casting mesh, ready to upload.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CastingMesh {
    /// Welded world-space positions (w = 1).
    pub positions: Vec<[f32; 4]>,
    /// Per face: three welded vertex ids, and the index of its closed component (0 to
    /// [`MeshReport::closed_components`] − 1, in order of first face), or [`TWO_SIDED_COMPONENT`].
    pub faces: Vec<[u32; 4]>,
    /// Edge incidences: paired where the edge is manifold and consistently wound, else one per face.
    pub records: Vec<EdgeRecord>,
    /// Per closed component (by its index in `faces`): 1 when every edge of it is convex, else 0.
    pub closed_convex: Vec<u32>,
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
        let (welded, triangles, split_faces) = split_t_junctions(adjacency);
        let positions = welded.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
        let face_count = triangles.len();
        let mut report = MeshReport { faces: face_count, split_faces, ..MeshReport::default() };
        // Every directed edge (from, to, face), grouped by undirected key in first-seen order.
        let mut order: Vec<EdgeKey> = Vec::new();
        let mut incidences: HashMap<EdgeKey, Vec<Incidence>> = HashMap::new();
        for (face, triangle) in triangles.iter().enumerate() {
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
                    records.push(EdgeRecord { v0: *from, v1: *to, face_a: *face_a, face_b: *face_b, face_b_winds_forward: 0 });
                    half_edge_capacity += 2;
                }
                // Two faces winding the edge the same way: their component is two-sided (its
                // faces are turned to the light each frame), but the edge stays one edge between
                // two faces, so that where the turned faces' sides cancel it joins them into one
                // silhouette region like a manifold edge. Recorded alone, each face would emit its
                // side and the two separate surfaces would be two silhouettes whose penumbrae are
                // blended (Sec. 3.2) where they abut, leaking light along the seam.
                [(from, to, face_a), (from_b, to_b, face_b)] if from == from_b && to == to_b => {
                    report.inconsistent_edges += 1;
                    records.push(EdgeRecord { v0: *from, v1: *to, face_a: *face_a, face_b: *face_b, face_b_winds_forward: 1 });
                    irregular_faces.extend([*face_a, *face_b]);
                    half_edge_capacity += 2;
                }
                _ => {
                    if list.len() == 1 {
                        report.open_edges += 1;
                    } else {
                        report.non_manifold_edges += 1;
                    }
                    for &(from, to, face) in list {
                        records.push(EdgeRecord { v0: from, v1: to, face_a: face, face_b: NO_FACE, face_b_winds_forward: 0 });
                        irregular_faces.push(face);
                    }
                    half_edge_capacity += list.len() as u64;
                }
            }
        }
        let mut two_sided_roots: Vec<u32> = irregular_faces.iter().map(|f| components.find(*f)).collect();
        two_sided_roots.sort_unstable();
        two_sided_roots.dedup();
        // Closed components numbered densely in order of their first face.
        let mut closed_index: HashMap<u32, u32> = HashMap::new();
        let faces: Vec<[u32; 4]> = triangles
            .iter()
            .enumerate()
            .map(|(face, t)| {
                let root = components.find(face as u32);
                let component = if two_sided_roots.binary_search(&root).is_ok() {
                    TWO_SIDED_COMPONENT
                } else {
                    let next = closed_index.len() as u32;
                    *closed_index.entry(root).or_insert(next)
                };
                [t[0], t[1], t[2], component]
            })
            .collect();
        report.two_sided_components = two_sided_roots.len();
        report.components = closed_index.len() + two_sided_roots.len();
        let closed_convex = convex_components(&welded, &faces, &records, closed_index.len());
        report.convex_components = closed_convex.iter().filter(|c| **c == 1).count();
        Self { positions, faces, records, closed_convex, half_edge_capacity: u32::try_from(half_edge_capacity).unwrap_or(u32::MAX), report }
    }
}

/// A welded vertex lies on an edge when its distance to the edge's line is at most this share of
/// the edge's length (float rounding of transformed coordinates, far below any modelled gap).
const ON_EDGE_TOLERANCE: f32 = 1e-5;

/// Grid cells one edge may visit in the search for vertices on it; a longer edge (against the
/// open edges' mean length) is not split.
const MAX_CELLS_PER_EDGE: i64 = 1 << 16;

/// The triangles with every face that has a welded vertex on one of its open edges (an edge of
/// no other face) split so that the vertex becomes a corner: the face's boundary, with the
/// vertices found on each edge in order, fanned from its centroid (a new vertex), winding kept.
/// Returns the positions (the welded ones, then the centroids), the triangles and the count of
/// faces split. A mesh without open edges comes back unchanged.
fn split_t_junctions(adjacency: &Adjacency) -> (Vec<Vec3>, Vec<[u32; 3]>, usize) {
    let (welded, triangles) = (&adjacency.welded_positions, &adjacency.triangles);
    let open: Vec<EdgeKey> = adjacency
        .edges
        .iter()
        .filter(|edge| edge.face_count == 1)
        .map(|edge| (edge.vertices[0].min(edge.vertices[1]), edge.vertices[0].max(edge.vertices[1])))
        .collect();
    if open.is_empty() {
        return (welded.to_vec(), triangles.to_vec(), 0);
    }
    // The endpoints of open edges, in a grid of cells the open edges' mean length wide: only they
    // can lie on another open edge without sharing it (a vertex inside a closed surface has no
    // open edge).
    let mean_length = open.iter().map(|(a, b)| welded[*a as usize].distance(welded[*b as usize])).sum::<f32>() / open.len() as f32;
    let cell = mean_length.max(f32::MIN_POSITIVE);
    let cell_of = |p: Vec3| (p / cell).floor().as_ivec3();
    let mut grid: HashMap<IVec3, Vec<u32>> = HashMap::new();
    let mut endpoints: Vec<u32> = open.iter().flat_map(|(a, b)| [*a, *b]).collect();
    endpoints.sort_unstable();
    endpoints.dedup();
    for v in &endpoints {
        grid.entry(cell_of(welded[*v as usize])).or_default().push(*v);
    }
    // Per open edge, the vertices strictly inside it, by their place along it.
    let mut on_edge: HashMap<EdgeKey, Vec<(f32, u32)>> = HashMap::new();
    for &(a, b) in &open {
        let (pa, pb) = (welded[a as usize], welded[b as usize]);
        let along = pb - pa;
        let length_squared = along.length_squared();
        let (low, high) = (cell_of(pa.min(pb)), cell_of(pa.max(pb)));
        let span = (high - low + IVec3::ONE).as_i64vec3();
        if length_squared <= 0.0 || span.x * span.y * span.z > MAX_CELLS_PER_EDGE {
            continue;
        }
        let tolerance = ON_EDGE_TOLERANCE * length_squared.sqrt();
        let mut found = Vec::new();
        for x in low.x..=high.x {
            for y in low.y..=high.y {
                for z in low.z..=high.z {
                    for &v in grid.get(&IVec3::new(x, y, z)).into_iter().flatten() {
                        if v == a || v == b {
                            continue;
                        }
                        let offset = welded[v as usize] - pa;
                        let t = offset.dot(along) / length_squared;
                        if t > 1e-6 && t < 1.0 - 1e-6 && (offset - along * t).length() <= tolerance {
                            found.push((t, v));
                        }
                    }
                }
            }
        }
        if !found.is_empty() {
            found.sort_by(|x, y| x.0.total_cmp(&y.0));
            on_edge.insert((a, b), found);
        }
    }
    if on_edge.is_empty() {
        return (welded.to_vec(), triangles.to_vec(), 0);
    }
    let mut positions = welded.to_vec();
    let mut split = Vec::with_capacity(triangles.len() + 4 * on_edge.len());
    let mut split_faces = 0;
    for triangle in triangles {
        let mut boundary = Vec::with_capacity(6);
        for k in 0..3 {
            let (from, to) = (triangle[k], triangle[(k + 1) % 3]);
            boundary.push(from);
            if let Some(points) = on_edge.get(&(from.min(to), from.max(to))) {
                // Stored from the smaller vertex to the larger: walk them the way this face runs.
                if from < to {
                    boundary.extend(points.iter().map(|(_, v)| *v));
                } else {
                    boundary.extend(points.iter().rev().map(|(_, v)| *v));
                }
            }
        }
        if boundary.len() == 3 {
            split.push(*triangle);
            continue;
        }
        split_faces += 1;
        let centroid = positions.len() as u32;
        positions.push(triangle.iter().map(|v| welded[*v as usize]).sum::<Vec3>() / 3.0);
        for k in 0..boundary.len() {
            split.push([centroid, boundary[k], boundary[(k + 1) % boundary.len()]]);
        }
    }
    (positions, split, split_faces)
}

/// Per closed component: 1 when every one of its (paired) edges is convex, that is when each face's
/// third corner lies on or behind the other face's plane, within a rounding of its size.
fn convex_components(welded: &[Vec3], faces: &[[u32; 4]], records: &[EdgeRecord], closed: usize) -> Vec<u32> {
    let mut convex = vec![1u32; closed];
    let position = |v: u32| welded[v as usize];
    let third = |face: &[u32; 4], a: u32, b: u32| face[..3].iter().copied().find(|v| *v != a && *v != b);
    for record in records {
        let (Some(face_a), Some(face_b)) = (faces.get(record.face_a as usize), faces.get(record.face_b as usize)) else { continue };
        let component = face_a[3];
        if component == TWO_SIDED_COMPONENT {
            continue;
        }
        let (Some(opposite_a), Some(opposite_b)) = (third(face_a, record.v0, record.v1), third(face_b, record.v0, record.v1)) else {
            continue;
        };
        let (p0, p1, pa) = (position(record.v0), position(record.v1), position(opposite_a));
        // face_a winds v0 -> v1 -> opposite_a: its outward normal.
        let normal = (p1 - p0).cross(pa - p0);
        let q = position(opposite_b) - p0;
        let size = (p1 - p0).length().max((pa - p0).length()).max(q.length());
        if normal.dot(q) > 1e-5 * normal.length() * size {
            convex[component as usize] = 0;
        }
    }
    convex
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
        assert!(ball.faces.iter().all(|f| f[3] == 0), "one closed component, index 0");
        assert_eq!(ball.records.len() * 3, ball.faces.len() * 3 * 3 / 2, "E = 3F/2");
        let cube = prepared(&cuboid("c", Vec3::ONE));
        assert_eq!((cube.report.components, cube.report.two_sided_components), (1, 0));
    }

    #[test]
    fn an_open_mesh_is_two_sided() {
        let quad = prepared(&plane("p", Vec2::ONE));
        assert_eq!((quad.report.open_edges, quad.report.two_sided_components), (4, 1));
        assert!(quad.faces.iter().all(|f| f[3] == TWO_SIDED_COMPONENT));
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
    fn two_open_quads_wound_the_same_way_on_a_shared_edge_are_paired_there() {
        // Two walls meeting at a corner, one wound inwards and one outwards: the shared edge is
        // wound the same way by both, and stays one paired record (flagged) so that the frame's
        // turned faces can cancel there; both are two-sided.
        let positions = vec![
            Vec3::ZERO,
            Vec3::Y,
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(0.0, 1.0, -1.0),
        ];
        // Wall A: 0-1 shared, winds 0 -> 1 in its first triangle; wall B winds 0 -> 1 too.
        let indices = vec![0, 1, 2, 1, 3, 2, 0, 1, 4, 1, 5, 4];
        let mesh = prepared(&Mesh::with_generated_normals("corner", positions, indices));
        assert_eq!(mesh.report.inconsistent_edges, 1);
        assert_eq!(mesh.report.two_sided_components, 1);
        let shared: Vec<&EdgeRecord> = mesh.records.iter().filter(|r| (r.v0.min(r.v1), r.v0.max(r.v1)) == (0, 1)).collect();
        assert_eq!(shared.len(), 1, "{shared:?}");
        assert_eq!((shared[0].face_b_winds_forward, shared[0].face_a, shared[0].face_b), (1, 0, 2));
        assert_eq!(mesh.records.iter().filter(|r| r.face_b_winds_forward == 1).count(), 1);
    }

    #[test]
    fn a_vertex_on_another_faces_open_edge_splits_that_face_and_the_overlap_is_shared() {
        // Wall A: the quad x = 0, y in [0, 1], z in [0, 1]; wall B stands on its edge z = 0 from
        // y = 0.25 up (x in [0, -1]): B's corner (0, 0.25, 0) lies on A's open edge
        // (0, 0, 0)-(0, 1, 0), which it shares from 0.25 to 1 without a vertex there.
        let positions = vec![
            Vec3::ZERO,
            Vec3::Y,
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::Z,
            Vec3::new(0.0, 0.25, 0.0),
            Vec3::new(-1.0, 0.25, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let indices = vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 1];
        let mesh = prepared(&Mesh::with_generated_normals("t-junction", positions, indices));
        assert_eq!(mesh.report.split_faces, 1, "{:?}", mesh.report);
        // The split face is fanned from a new centroid: 4 boundary vertices, 4 triangles.
        assert_eq!(mesh.faces.len(), 4 - 1 + 4);
        assert_eq!(mesh.positions.len(), 7 + 1);
        // (0, 0.25, 0)-(0, 1, 0) is now one edge of two faces (4 and 1 are its welded ids).
        let shared: Vec<&EdgeRecord> = mesh.records.iter().filter(|r| (r.v0.min(r.v1), r.v0.max(r.v1)) == (1, 4)).collect();
        assert_eq!(shared.len(), 1, "{shared:?}");
        assert_ne!(shared[0].face_b, NO_FACE);
        // Both walls are one component now.
        assert_eq!(mesh.report.components, 1);
        // The part of A's edge below B stays open: 0 to 4.
        assert!(mesh.records.iter().any(|r| (r.v0.min(r.v1), r.v0.max(r.v1)) == (0, 4) && r.face_b == NO_FACE));
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
        assert_eq!(both.faces.iter().filter(|f| f[3] == TWO_SIDED_COMPONENT).count(), 2);
        assert!(both.faces.iter().filter(|f| f[3] != TWO_SIDED_COMPONENT).all(|f| f[3] == 0));
        assert_eq!(both.report.closed_components(), 1);
    }

    #[test]
    fn closed_components_are_numbered_densely_in_order_of_their_first_face() {
        // A quad (two-sided), then two cubes: the cubes are closed components 0 and 1.
        let parts = [plane("p", Vec2::ONE), cuboid("a", Vec3::ONE), cuboid("b", Vec3::ONE)];
        let (mut positions, mut indices) = (Vec::new(), Vec::new());
        for (k, part) in parts.iter().enumerate() {
            let offset = positions.len() as u32;
            positions.extend(part.positions.iter().map(|p| *p + Vec3::new(3.0 * k as f32, 0.0, 0.0)));
            indices.extend(part.indices.iter().map(|i| i + offset));
        }
        let mesh = prepared(&Mesh::with_generated_normals("three", positions, indices));
        let components: Vec<u32> = mesh.faces.iter().map(|f| f[3]).collect();
        assert_eq!(components[..2], [TWO_SIDED_COMPONENT; 2]);
        assert!(components[2..14].iter().all(|c| *c == 0) && components[14..].iter().all(|c| *c == 1), "{components:?}");
        assert_eq!(mesh.report.closed_components(), 2);
    }

    #[test]
    fn spheres_and_boxes_are_convex_an_l_shaped_prism_is_not() {
        assert_eq!(prepared(&sphere("s", 1.0, 12, 6)).closed_convex, vec![1]);
        assert_eq!(prepared(&cuboid("c", Vec3::ONE)).closed_convex, vec![1]);
        // An L-shaped prism: one re-entrant edge.
        let outline = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)];
        let mut positions: Vec<Vec3> = outline.iter().map(|&(x, z)| Vec3::new(x, 0.0, z)).collect();
        positions.extend(outline.iter().map(|&(x, z)| Vec3::new(x, 1.0, z)));
        // Bottom and top fans from corner 0, then the walls.
        let mut indices = vec![0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5];
        indices.extend([6, 8, 7, 6, 9, 8, 6, 10, 9, 6, 11, 10]);
        for k in 0..6u32 {
            let n = (k + 1) % 6;
            indices.extend([k, n + 6, n, k, k + 6, n + 6]);
        }
        let l = prepared(&Mesh::with_generated_normals("l", positions, indices));
        assert_eq!((l.report.components, l.report.two_sided_components), (1, 0), "{:?}", l.report);
        assert_eq!(l.closed_convex, vec![0]);
        assert_eq!(l.report.convex_components, 0);
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
