//! What the ground truth prepares once per scene, before any ray: the triangles it traces (every
//! world triangle with a non-zero area), their CWBVH (`obvhs`), each triangle prepared for the
//! shortcuts' tests (its edges and normal computed once: obvhs 0.4's `Triangle::intersect`,
//! Möller and Trumbore, step for step) and the layer of occluders that the convex pieces
//! (`pieces`) and the other triangles make.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::{build_cwbvh, build_cwbvh_from_tris};
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use ssm_scene::Scene;

use super::{GroundTruth, ReferenceCache, Traversal, pieces, traversal};

/// A triangle as the shortcuts test it: its first corner, two edges and (unnormalised) normal
/// computed once, so that each test does what `Triangle::intersect` does without computing them
/// again. The same operations on the same values, in the same order: the same answer, bit for bit
/// (the tests compare the shortcuts, which use it, with the per-ray traversal, which does not).
#[derive(Clone, Copy)]
pub(super) struct PreparedTriangle {
    v0: Vec3A,
    /// `v0 - v1`.
    e1: Vec3A,
    /// `v2 - v0`.
    e2: Vec3A,
    /// `e1 × e2`.
    normal: Vec3A,
}

impl PreparedTriangle {
    fn new(triangle: &Triangle) -> Self {
        let e1 = triangle.v0 - triangle.v1;
        let e2 = triangle.v2 - triangle.v0;
        Self { v0: triangle.v0, e1, e2, normal: e1.cross(e2) }
    }

    /// The distance along `ray` to the triangle, `f32::INFINITY` for none in [tmin, tmax]:
    /// obvhs 0.4's `Triangle::intersect` (Möller and Trumbore), step for step.
    #[inline(always)]
    pub(super) fn intersect(&self, ray: &Ray) -> f32 {
        let c = self.v0 - ray.origin;
        let r = ray.direction.cross(c);
        let inv_det = 1.0 / self.normal.dot(ray.direction);
        let u = r.dot(self.e2) * inv_det;
        let v = r.dot(self.e1) * inv_det;
        let w = 1.0 - u - v;
        // Every barycentric's sign bit clear (as obvhs: -0.0 counts as outside).
        let hit = u.to_bits() | v.to_bits() | w.to_bits();
        if inv_det != 0.0 && hit & 0x8000_0000 == 0 {
            let t = self.normal.dot(c) * inv_det;
            if t >= ray.tmin && t <= ray.tmax {
                return t;
            }
        }
        f32::INFINITY
    }
}

/// The scene's occluders as the estimate's exact parts read them: every connected part of a placed
/// mesh that is a convex piece (`pieces`), one polygon from a point, and every other triangle.
pub(super) struct OccluderLayer {
    pub(super) pieces: Vec<pieces::ConvexPiece>,
    /// The pieces' bounds (slot k holds piece `piece_bvh.primitive_indices[k]`).
    pub(super) piece_bvh: CwBvh,
    pub(super) piece_nodes: traversal::DecodedBvh,
    /// The triangles not in a piece (indices into `GroundTruth::triangles`), and their BVH
    /// (slot k holds `loose[loose_bvh.primitive_indices[k]]`); `None` when there are none.
    pub(super) loose: Vec<u32>,
    pub(super) loose_bvh: Option<(CwBvh, traversal::DecodedBvh)>,
}

impl OccluderLayer {
    /// The layer of `scene`'s triangles (`keys`: each traced triangle's instance and its index in
    /// the instance's mesh), or `None` when no part of a placed mesh is a convex piece.
    fn of(scene: &Scene, triangles: &[Triangle], keys: &[(u32, u32)]) -> Option<Self> {
        let mut parts: Vec<Option<pieces::MeshParts>> = (0..scene.meshes.len()).map(|_| None).collect();
        // Each convex part of each instance with a triangle traced becomes a piece (a transform
        // that flattens every triangle of a part leaves none, and nothing to hide the light).
        let mut pieces = Vec::new();
        let mut piece_of_part: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        let mut loose = Vec::new();
        for (slot, (instance, triangle)) in keys.iter().enumerate() {
            let placed = &scene.instances[*instance as usize];
            let mesh_parts = parts[placed.mesh].get_or_insert_with(|| pieces::MeshParts::of(&scene.meshes[placed.mesh]));
            let part = mesh_parts.part_of_triangle[*triangle as usize];
            match &mesh_parts.shapes[part as usize] {
                Some(shape) => {
                    piece_of_part.entry((*instance, part)).or_insert_with(|| {
                        pieces.push(pieces::ConvexPiece::placed(shape, placed.transform));
                        pieces.len() as u32 - 1
                    });
                }
                None => loose.push(slot as u32),
            }
        }
        if pieces.is_empty() {
            return None;
        }
        let loose_bvh = (!loose.is_empty()).then(|| {
            let loose_triangles: Vec<Triangle> = loose.iter().map(|t| triangles[*t as usize]).collect();
            let bvh = build_cwbvh_from_tris(&loose_triangles, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
            let nodes = traversal::DecodedBvh::new(&bvh);
            (bvh, nodes)
        });
        let boxes: Vec<obvhs::aabb::Aabb> =
            pieces.iter().map(|piece| obvhs::aabb::Aabb::new(Vec3A::from(piece.bounds[0]), Vec3A::from(piece.bounds[1]))).collect();
        let piece_bvh = build_cwbvh(&boxes, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
        let piece_nodes = traversal::DecodedBvh::new(&piece_bvh);
        Some(Self { pieces, piece_bvh, piece_nodes, loose, loose_bvh })
    }
}

/// The triangles the ground truth traces: every world triangle with a non-zero area.
pub(super) fn traced_triangles(scene: &Scene) -> impl Iterator<Item = [Vec3; 3]> + '_ {
    traced_triangles_by_instance(scene).map(|(_, corners)| corners)
}

/// [`traced_triangles`], each with the index of the instance it belongs to and its own index in
/// that instance's mesh (the same corners as [`Scene::world_triangles`], in its order).
fn traced_triangles_by_instance(scene: &Scene) -> impl Iterator<Item = ((u32, u32), [Vec3; 3])> + '_ {
    scene
        .instances
        .iter()
        .enumerate()
        .filter_map(|(index, instance)| scene.meshes.get(instance.mesh).map(|mesh| (index as u32, instance, mesh)))
        .flat_map(|(index, instance, mesh)| {
            mesh.triangles()
                .enumerate()
                .map(move |(k, t)| ((index, k as u32), t.map(|i| instance.transform.transform_point3(mesh.positions[i as usize]))))
        })
        .filter(|(_, t)| (t[1] - t[0]).cross(t[2] - t[0]).length_squared() > 0.0)
}

impl GroundTruth {
    /// Builds the BVH over every triangle of `scene` (degenerate ones skipped).
    #[must_use]
    pub fn new(scene: &Scene) -> Self {
        let (keys, triangles): (Vec<(u32, u32)>, Vec<Triangle>) = traced_triangles_by_instance(scene)
            .map(|(key, [v0, v1, v2])| (key, Triangle { v0: Vec3A::from(v0), v1: Vec3A::from(v1), v2: Vec3A::from(v2) }))
            .unzip();
        let occluders = OccluderLayer::of(scene, &triangles, &keys);
        let normals = triangles
            .iter()
            .map(|t| {
                let corners = [Vec3::from(t.v0), Vec3::from(t.v1), Vec3::from(t.v2)];
                (corners[1] - corners[0]).cross(corners[2] - corners[0]).try_normalize().unwrap_or(Vec3::ZERO)
            })
            .collect();
        let bvh = build_cwbvh_from_tris(&triangles, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
        let prepared = bvh.primitive_indices.iter().map(|index| PreparedTriangle::new(&triangles[*index as usize])).collect();
        let extent = scene.bounds().size().length().max(1e-6);
        Self {
            triangles,
            prepared,
            normals,
            decoded: traversal::DecodedBvh::new(&bvh),
            bvh,
            surface_offset: extent * 1e-5,
            cache: ReferenceCache::of(scene),
            traversal: Traversal::Shortcuts,
            occluders,
        }
    }

    /// The corners of the triangle in BVH slot `slot`.
    pub(super) fn triangle_of_slot(&self, slot: u32) -> [Vec3; 3] {
        self.triangle_corners(self.bvh.primitive_indices[slot as usize] as usize)
    }

    /// The corners of the triangle at `index` in `triangles`.
    pub(super) fn triangle_corners(&self, index: usize) -> [Vec3; 3] {
        let triangle = &self.triangles[index];
        [triangle.v0, triangle.v1, triangle.v2].map(Vec3::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::SplitMix64;
    use crate::reference::traversal::segment_ray;

    /// A point in [-1, 1)^3 from `rng`.
    fn random_point(rng: &mut SplitMix64) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE
    }

    /// The prepared triangle answers as obvhs's `Triangle::intersect`, bit for bit: on random
    /// rays, on rays through a corner or an edge (where rounding decides), inside it, in its
    /// plane, and on segments that end before it.
    #[test]
    fn prepared_triangles_intersect_as_obvhs_bit_for_bit() {
        let mut rng = SplitMix64::for_pixel(11, 0);
        let (mut compared, mut hits) = (0, 0);
        for _ in 0..2_000 {
            let triangle = Triangle {
                v0: Vec3A::from(random_point(&mut rng)),
                v1: Vec3A::from(random_point(&mut rng)),
                v2: Vec3A::from(random_point(&mut rng)),
            };
            let prepared = PreparedTriangle::new(&triangle);
            let [v0, v1, v2] = [triangle.v0, triangle.v1, triangle.v2].map(Vec3::from);
            let origin = random_point(&mut rng) * 3.0;
            let (a, b) = (rng.next_f32(), rng.next_f32());
            let targets = [
                random_point(&mut rng) * 3.0,
                v0,
                v1,
                (v1 + v2) * 0.5,
                v0 + (v1 - v0) * a,
                v0 + (v1 - v0) * a + (v2 - v0) * b,
                // In the triangle's plane: beside it or through it.
                origin + (v1 - v0) * a + (v2 - v0) * b,
            ];
            for aim in targets {
                // Past the point aimed at, so that the segment crosses the triangle's plane.
                let target = origin + (aim - origin) * 2.0;
                let Some(ray) = segment_ray(origin, target) else { continue };
                for ray in [ray, Ray { tmax: ray.tmax * 0.5, ..ray }] {
                    let (expected, actual) = (triangle.intersect(&ray), prepared.intersect(&ray));
                    assert_eq!(expected.to_bits(), actual.to_bits(), "origin {origin}, through {aim}: {expected} against {actual}");
                    compared += 1;
                    hits += usize::from(expected.is_finite());
                }
            }
        }
        assert!(hits > compared / 10 && hits < compared, "{hits} hits of {compared}: both cases must be seen");
    }
}
