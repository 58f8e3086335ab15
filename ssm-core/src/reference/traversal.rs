//! Each ray's traversal: a shadow ray runs along the segment from its origin to its light sample
//! (`segment_ray`), through obvhs's own traversal (the definition, `GroundTruth::unoccluded`),
//! or through the decoded nodes below after the triangles that blocked the pixel's last rays
//! (`RecentBlockers`), or against the few triangles a shortcut gathered.
//!
//! The ground truth's CWBVH as the shortcuts read it: obvhs 0.4's nodes with each child's
//! quantised bounds converted to floats once, when the BVH is built, rather than at every visit
//! (by obvhs's own comment, that conversion is the costliest part of its node test). A node's
//! eight boxes are then plain float arithmetic on eight lanes, which the compiler vectorises
//! without unsafe code, for the two traversals the shortcuts make: a shadow ray's, which is
//! obvhs's `CwBvh::ray_traverse_miss` (its `traverse!` loop and its SSE node test,
//! `CwBvhNode::intersect_ray_simd`) step for step, and a pyramid's gather of the leaves it meets.
//!
//! The same float operations in the same order on the same values (a byte converted to a float
//! is exact either way): a ray enters the same children in the same order, so it is offered the
//! same triangles in the same order. A test compares the sequence with obvhs's.

use glam::{UVec2, Vec3, Vec3A};
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ray::Ray;

use super::GroundTruth;

/// The least distance at which obvhs's node test lets a ray enter a child box (its private
/// `cwbvh::node::EPSILON`, used where the ray's own `tmin` would be).
const ENTRY_EPSILON: f32 = 0.0001;

/// One CWBVH node as the traversal reads it: obvhs's node with its child bounds as floats and
/// its leaf children's triangle bits laid out. Four cache lines, aligned to them.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct DecodedNode {
    /// Child k's quantised bounds, as floats, at `[axis * 2 + side][k]` (side 0: the least, 1:
    /// the greatest), in steps of the node's extent from `origin`.
    bounds: [[f32; 8]; 6],
    /// What leaf child k adds to the hit mask when the ray enters it: its triangles' bits in the
    /// low 24 (obvhs's `child_bits << bit_index`, the same in every octant); zero for an inner or
    /// empty child.
    leaf_bits: [u32; 8],
    /// The corner of the node's quantisation grid (`CwBvhNode::p`).
    origin: Vec3,
    /// The exponent of the node's quantisation step on each axis (`CwBvhNode::e`).
    exponents: [u8; 3],
    /// Bit k set when child k is an inner node (`CwBvhNode::imask`).
    inner: u8,
    /// Index of the node's first inner child (`CwBvhNode::child_base_idx`).
    child_base: u32,
    /// BVH slot of the node's first triangle (`CwBvhNode::primitive_base_idx`).
    triangle_base: u32,
}

impl DecodedNode {
    fn new(node: &CwBvhNode) -> Self {
        // `hit_mask` places inner child k's bit as obvhs's builder numbers it (meta byte 24 + k);
        // the traversal test fails if a new obvhs numbers them otherwise.
        debug_assert!((0..8).all(|k| node.imask & (1 << k) == 0 || usize::from(node.child_meta[k] & 0b1_1111) == 24 + k));
        let floats = |bytes: &[u8; 8]| bytes.map(f32::from);
        // obvhs's `get_child_and_index_bits` for a leaf child, whose bits do not depend on the
        // octant: the unary triangle count (the meta byte's top three bits) shifted to the
        // child's first triangle (its low five).
        let leaf_bits = std::array::from_fn(|k| {
            let meta = u32::from(node.child_meta[k]);
            if node.imask & (1 << k) != 0 { 0 } else { ((meta >> 5) & 0b111) << (meta & 0b1_1111) }
        });
        Self {
            bounds: [
                floats(&node.child_min_x),
                floats(&node.child_max_x),
                floats(&node.child_min_y),
                floats(&node.child_max_y),
                floats(&node.child_min_z),
                floats(&node.child_max_z),
            ],
            leaf_bits,
            origin: node.p,
            exponents: node.e,
            inner: node.imask,
            child_base: node.child_base_idx,
            triangle_base: node.primitive_base_idx,
        }
    }

    /// The size of one quantisation step on each axis (obvhs's `CwBvhNode::compute_extent`):
    /// a power of two, from its exponent byte.
    #[inline(always)]
    fn extent(&self) -> Vec3A {
        Vec3A::new(
            f32::from_bits(u32::from(self.exponents[0]) << 23),
            f32::from_bits(u32::from(self.exponents[1]) << 23),
            f32::from_bits(u32::from(self.exponents[2]) << 23),
        )
    }

    /// The node's hit mask for `ray`, as `CwBvhNode::intersect_ray_simd` computes it: the inner
    /// children entered in the high byte (inner child k at bit 24 + (k ^ octant): obvhs's builder
    /// gives it meta byte 24 + k), the entered leaves' triangles in the low 24 bits. `near` holds,
    /// per axis, the bound a ray along `ray.direction` meets first; `octant` is the low byte of
    /// obvhs's `oct_inv4`.
    #[inline(always)]
    fn hit_mask(&self, ray: &Ray, near: [usize; 3], octant: u32) -> u32 {
        let scale = self.extent() * ray.inv_direction;
        let offset = (Vec3A::from(self.origin) - ray.origin) * ray.inv_direction;
        let (near_x, near_y, near_z) = (&self.bounds[near[0]], &self.bounds[near[1]], &self.bounds[near[2]]);
        let (far_x, far_y, far_z) = (&self.bounds[near[0] ^ 1], &self.bounds[near[1] ^ 1], &self.bounds[near[2] ^ 1]);
        let mut entered = 0u32;
        let mut leaves = 0u32;
        for k in 0..8 {
            let entry = max_ps(near_x[k] * scale.x + offset.x, max_ps(near_y[k] * scale.y + offset.y, near_z[k] * scale.z + offset.z));
            let exit = min_ps(far_x[k] * scale.x + offset.x, min_ps(far_y[k] * scale.y + offset.y, far_z[k] * scale.z + offset.z));
            let enters = max_ps(entry, ENTRY_EPSILON) <= min_ps(exit, ray.tmax);
            entered |= u32::from(enters) << k;
            // Without branches: which children a ray enters is not predictable.
            leaves |= self.leaf_bits[k] & u32::from(enters).wrapping_neg();
        }
        (permute_by_xor(entered & u32::from(self.inner), octant) << 24) | leaves
    }

    /// Bit k set when child k lies wholly beyond one of `planes` (outward normal, offset) by
    /// more than `margin`, the eight children at once: each plane moved into the node's
    /// quantisation frame, where a child's box is its six bounds.
    #[inline(always)]
    fn children_beyond(&self, planes: &[(Vec3, f32)], margin: f32) -> u8 {
        let extent = Vec3::from(self.extent());
        let mut beyond = [false; 8];
        for (normal, offset) in planes {
            let scaled = *normal * extent;
            let limit = offset + margin - normal.dot(self.origin);
            // The child's corner nearest the inside of the plane, one axis at a time.
            let xs = &self.bounds[if normal.x >= 0.0 { 0 } else { 1 }];
            let ys = &self.bounds[2 + if normal.y >= 0.0 { 0 } else { 1 }];
            let zs = &self.bounds[4 + if normal.z >= 0.0 { 0 } else { 1 }];
            for k in 0..8 {
                beyond[k] |= scaled.x * xs[k] + scaled.y * ys[k] + scaled.z * zs[k] > limit;
            }
        }
        beyond.iter().enumerate().fold(0, |bits, (k, out)| bits | (u8::from(*out) << k))
    }
}

/// `bits` (eight of them) with bit k moved to bit k ^ `octant`.
#[inline(always)]
fn permute_by_xor(bits: u32, octant: u32) -> u32 {
    let mut bits = bits;
    if octant & 1 != 0 {
        bits = ((bits & 0x55) << 1) | ((bits >> 1) & 0x55);
    }
    if octant & 2 != 0 {
        bits = ((bits & 0x33) << 2) | ((bits >> 2) & 0x33);
    }
    if octant & 4 != 0 {
        bits = ((bits & 0x0f) << 4) | ((bits >> 4) & 0x0f);
    }
    bits
}

/// SSE's `maxps` for one lane: `a` when it is greater, else `b` (also when either is NaN).
#[inline(always)]
fn max_ps(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// SSE's `minps` for one lane: `a` when it is less, else `b` (also when either is NaN).
#[inline(always)]
fn min_ps(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

// Four cache lines: the bounds (192 bytes), the leaf bits (32) and the rest (24), padded.
const _: () = assert!(std::mem::size_of::<DecodedNode>() == 256);

/// The ground truth's CWBVH with its nodes decoded for [`DecodedBvh::traverse`] and
/// [`DecodedBvh::gather`].
pub(super) struct DecodedBvh {
    nodes: Vec<DecodedNode>,
}

impl DecodedBvh {
    pub(super) fn new(bvh: &CwBvh) -> Self {
        Self { nodes: bvh.nodes.iter().map(DecodedNode::new).collect() }
    }

    /// Offers `leaf` each leaf whose box is not wholly beyond one of `planes` (outward normal,
    /// offset) by more than `margin`, as the BVH slot of its first triangle and their number,
    /// depth first, until it returns false; whether it never did.
    pub(super) fn gather(&self, planes: &[(Vec3, f32)], margin: f32, mut leaf: impl FnMut(u32, u32) -> bool) -> bool {
        if self.nodes.is_empty() {
            return true;
        }
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            let beyond = node.children_beyond(planes, margin);
            for k in 0..8 {
                if beyond & (1 << k) != 0 {
                    continue;
                }
                if node.inner & (1 << k) != 0 {
                    // obvhs's `child_node_index`: inner children are stored in child order.
                    stack.push(node.child_base + (u32::from(node.inner) & ((1 << k) - 1)).count_ones());
                } else if node.leaf_bits[k] != 0
                    && !leaf(node.triangle_base + node.leaf_bits[k].trailing_zeros(), node.leaf_bits[k].count_ones())
                {
                    return false;
                }
            }
        }
        true
    }

    /// Offers `test` the BVH slot of each triangle in the leaves `ray` enters, in obvhs's
    /// traversal order, until it returns true; whether one did. `stack` is scratch space, kept
    /// by the caller so that a traversal allocates nothing.
    pub(super) fn traverse(&self, ray: &Ray, stack: &mut Vec<UVec2>, mut test: impl FnMut(usize) -> bool) -> bool {
        stack.clear();
        if self.nodes.is_empty() {
            return false;
        }
        let negative = [ray.direction.x < 0.0, ray.direction.y < 0.0, ray.direction.z < 0.0];
        let near = [usize::from(negative[0]), 2 + usize::from(negative[1]), 4 + usize::from(negative[2])];
        // obvhs's `ray_get_octant_inv4`.
        let oct_inv4 = (if negative[0] { 0 } else { 0x0404_0404 })
            | (if negative[1] { 0 } else { 0x0202_0202 })
            | (if negative[2] { 0 } else { 0x0101_0101 });
        // obvhs's `traverse!`: a group is a base index and a bit mask (child nodes in the high
        // byte with the parent's inner-child mask in the low one; or triangles).
        let mut node_group = UVec2::new(0, 0x8000_0000);
        let mut triangle_group = UVec2::ZERO;
        loop {
            while triangle_group.y != 0 {
                let local = 31 - triangle_group.y.leading_zeros();
                triangle_group.y &= !(1 << local);
                if test((triangle_group.x + local) as usize) {
                    return true;
                }
            }
            if node_group.y & 0xff00_0000 != 0 {
                let hits = node_group.y;
                let child_bit = 31 - hits.leading_zeros();
                node_group.y &= !(1 << child_bit);
                if node_group.y & 0xff00_0000 != 0 {
                    stack.push(node_group);
                }
                let slot = (child_bit - 24) ^ (oct_inv4 & 0xff);
                let relative = (hits & !(u32::MAX << slot)).count_ones();
                let node = &self.nodes[(node_group.x + relative) as usize];
                let mask = node.hit_mask(ray, near, oct_inv4 & 0xff);
                node_group = UVec2::new(node.child_base, (mask & 0xff00_0000) | u32::from(node.inner));
                triangle_group = UVec2::new(node.triangle_base, mask & 0x00ff_ffff);
            } else {
                node_group = UVec2::ZERO;
            }
            if triangle_group.y == 0 && node_group.y & 0xff00_0000 == 0 {
                match stack.pop() {
                    Some(group) => node_group = group,
                    None => return false,
                }
            }
        }
    }
}

/// The last few triangles that blocked a pixel's rays (their BVH slots), newest first, and the
/// stack its rays traverse the BVH with (kept, so that a traversal allocates nothing).
#[derive(Default)]
pub(super) struct RecentBlockers {
    slots: [u32; 4],
    count: usize,
    traversal_stack: Vec<UVec2>,
}

impl RecentBlockers {
    fn triangles(&self) -> &[u32] {
        &self.slots[..self.count]
    }

    fn push(&mut self, triangle: u32) {
        let len = self.slots.len();
        self.slots.copy_within(0..len - 1, 1);
        self.slots[0] = triangle;
        self.count = (self.count + 1).min(len);
    }
}

/// The ray along the segment from `origin` to `target`, stopping just short of `target` so that
/// geometry lying in the light's plane does not count; `None` for a segment of no length.
pub(super) fn segment_ray(origin: Vec3, target: Vec3) -> Option<Ray> {
    let offset = target - origin;
    let distance = offset.length();
    (distance > 0.0).then(|| Ray::new(Vec3A::from(origin), Vec3A::from(offset / distance), 0.0, distance * (1.0 - 1e-6)))
}

impl GroundTruth {
    /// True when the segment from `origin` to `target` crosses no triangle.
    pub(super) fn unoccluded(&self, origin: Vec3, target: Vec3) -> bool {
        segment_ray(origin, target).is_none_or(|ray| {
            self.bvh.ray_traverse_miss(ray, |ray, id| self.triangles[self.bvh.primitive_indices[id] as usize].intersect(ray))
        })
    }

    /// The BVH slot of the triangle the BVH finds first on `ray` (a [`segment_ray`], with the
    /// test of [`GroundTruth::unoccluded`] and its traversal, node for node), if any.
    fn first_blocker(&self, ray: &Ray, stack: &mut Vec<UVec2>) -> Option<u32> {
        let mut found = None;
        self.decoded.traverse(ray, stack, |slot| {
            let blocks = self.crosses(ray, slot as u32);
            if blocks {
                found = Some(slot as u32);
            }
            blocks
        });
        found
    }

    /// True when `ray` crosses the triangle in BVH slot `slot` before its `tmax`.
    #[inline(always)]
    fn crosses(&self, ray: &Ray, slot: u32) -> bool {
        self.prepared[slot as usize].intersect(ray) < ray.tmax
    }

    /// True when the ray from `origin` to `target` crosses one of `candidates` (BVH slots; the same
    /// segment and intersection test as [`GroundTruth::unoccluded`]).
    pub(super) fn blocked_by(&self, origin: Vec3, target: Vec3, candidates: &[u32]) -> bool {
        segment_ray(origin, target).is_some_and(|ray| candidates.iter().any(|slot| self.crosses(&ray, *slot)))
    }

    /// True when the ray from `origin` to `target` is blocked: by one of the triangles in
    /// `recent` (tried first: a pixel's neighbouring rays mostly hit the same ones), else by the
    /// triangle the BVH finds, which `recent` then remembers. The same answer as
    /// `!unoccluded`: a ray a remembered triangle blocks is blocked.
    pub(super) fn blocked_remembering(&self, origin: Vec3, target: Vec3, recent: &mut RecentBlockers) -> bool {
        let Some(ray) = segment_ray(origin, target) else { return false };
        recent.triangles().iter().any(|slot| self.crosses(&ray, *slot))
            || self.first_blocker(&ray, &mut recent.traversal_stack).map(|blocker| recent.push(blocker)).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::SplitMix64;
    use crate::reference::pyramid::Pyramid;
    use glam::Vec2;
    use obvhs::cwbvh::builder::build_cwbvh_from_tris;
    use obvhs::triangle::Triangle;
    use ssm_scene::RectLight;
    use std::time::Duration;

    /// The decoded traversal offers the same triangles in the same order as obvhs's, on random
    /// triangle soups and rays (some along an axis, some with a short `tmax`), and stops where
    /// its caller says.
    #[test]
    fn decoded_traversal_offers_what_obvhs_offers_in_its_order() {
        let mut rng = SplitMix64::for_pixel(11, 0);
        let mut point = |scale: f32| Vec3A::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * scale;
        for soup in 0..6 {
            let count = [1, 7, 60, 400, 2_000, 9_000][soup];
            let triangles: Vec<Triangle> = (0..count)
                .map(|_| {
                    let centre = point(10.0);
                    Triangle { v0: centre + point(3.0), v1: centre + point(3.0), v2: centre + point(3.0) }
                })
                .collect();
            let bvh = build_cwbvh_from_tris(&triangles, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
            let decoded = DecodedBvh::new(&bvh);
            let mut stack = Vec::new();
            let mut offered_in_total = 0;
            for r in 0..400 {
                let origin = point(12.0);
                let mut direction = Vec3::from(point(1.0)).try_normalize().unwrap_or(Vec3::X);
                if r % 5 == 0 {
                    direction = [Vec3::X, Vec3::NEG_Y, Vec3::Z][r % 3];
                }
                let tmax = if r % 3 == 0 { 2.0 } else { 30.0 };
                let ray = Ray::new(origin, Vec3A::from(direction), 0.0, tmax);
                let mut expected = Vec::new();
                bvh.ray_traverse_anyhit(ray, |_, slot| expected.push(slot));
                let mut offered = Vec::new();
                assert!(!decoded.traverse(&ray, &mut stack, |slot| {
                    offered.push(slot);
                    false
                }));
                assert_eq!(offered, expected, "soup {soup}, ray {r}");
                offered_in_total += offered.len();
                if let Some(stop) = expected.get(expected.len() / 2) {
                    let mut until_stop = Vec::new();
                    assert!(decoded.traverse(&ray, &mut stack, |slot| {
                        until_stop.push(slot);
                        slot == *stop
                    }));
                    assert_eq!(until_stop[..], expected[..=expected.iter().position(|s| s == stop).unwrap()]);
                }
            }
            assert!(count < 400 || offered_in_total > 1_000, "soup {soup}: the rays met too few triangles to test anything");
        }
    }

    /// All eight children of a decoded node tested against a pyramid at once say what each
    /// child's own box (obvhs's) says: never outside where its box meets the pyramid, and outside wherever the box
    /// lies beyond a plane by more than rounding.
    #[test]
    fn children_beyond_a_pyramid_agree_with_each_childs_box() {
        let mut rng = SplitMix64::for_pixel(12, 0);
        let triangles: Vec<Triangle> = (0..3_000)
            .map(|_| {
                let centre = random_point(&mut rng) * 4.0;
                let [a, b, c] = [(); 3].map(|()| Vec3A::from(centre + random_point(&mut rng) * 0.2));
                Triangle { v0: a, v1: b, v2: c }
            })
            .collect();
        let bvh = build_cwbvh_from_tris(&triangles, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
        let decoded = DecodedBvh::new(&bvh);
        let light = RectLight::try_facing(Vec3::new(0.0, 6.0, 0.0), Vec3::NEG_Y, Vec3::X, Vec2::splat(1.5), 1.0).unwrap();
        let (mut outside, mut inside) = (0, 0);
        for _ in 0..50 {
            let apex = random_point(&mut rng) * Vec3::new(4.0, 1.0, 4.0) - Vec3::Y * 4.0;
            let (s, t) = (rng.next_f32() * 2.0 - 1.0, rng.next_f32() * 2.0 - 1.0);
            let corners = [light.point(-1.0, -1.0), light.point(s, -1.0), light.point(s, t), light.point(-1.0, t)];
            let Some(pyramid) = Pyramid::new(apex, corners, &light) else { continue };
            for (node, decoded_node) in bvh.nodes.iter().zip(&decoded.nodes) {
                let bits = decoded_node.children_beyond(&pyramid.planes, 0.0);
                for child in (0..8).filter(|child| !node.is_child_empty(*child)) {
                    let aabb = node.child_aabb(child);
                    let (min, max) = (Vec3::from(aabb.min), Vec3::from(aabb.max));
                    // How far the box lies beyond its farthest plane (negative: it meets every half-space).
                    let beyond = pyramid
                        .planes
                        .iter()
                        .map(|(normal, offset)| normal.dot(Vec3::select(normal.cmpge(Vec3::ZERO), min, max)) - offset)
                        .fold(f32::NEG_INFINITY, f32::max);
                    let said_outside = bits & (1 << child) != 0;
                    if beyond.abs() > 1e-4 {
                        assert_eq!(said_outside, beyond > 0.0, "child {child}: beyond by {beyond}");
                    }
                    if said_outside { outside += 1 } else { inside += 1 }
                }
            }
        }
        assert!(outside > 1_000 && inside > 1_000, "{outside} outside, {inside} inside: both must be seen");
    }

    /// A point in [-1, 1)^3 from `rng`.
    fn random_point(rng: &mut SplitMix64) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE
    }
}
