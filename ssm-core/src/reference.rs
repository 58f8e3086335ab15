//! The ground truth: for each pixel, the fraction of the rectangular light
//! visible from the surface point seen there, by casting stratified, jittered
//! rays to the light against every triangle of the scene (roles do not
//! matter: everything blocks light), on the CPU, with a CWBVH (`obvhs`) and
//! all cores (`rayon`).
//!
//! Each pixel is estimated twice, by two independent sets of N×N strata,
//! each refined where the visibility varies across the light (M×M rays in a
//! stratum whose result in the other set differs from a neighbour's); the
//! estimate is their mean and its noise half their difference, so every
//! error measured against the truth can carry the truth's own error over the
//! same pixels ([`GroundTruth::estimate`], [`ReferenceImage::noise`]).
//!
//! Deterministic: each pixel's jitter comes from a fixed seed and the pixel's
//! index, so the result does not depend on thread scheduling, and it is cached
//! on disk under a hash of everything that changes it.
//!
//! A pixel's rays share their origin (one on each side of its tangent plane),
//! so they are not traced one by one where that can be avoided, with the same
//! answer ray for ray: the triangles in the pyramid from the point to the light
//! (or to the part of it on one side of the plane) are gathered from the BVH once (none:
//! lit; one that covers the pyramid: dark; a few: each ray tested against
//! them; too many: the light cut into quarters, each with its own pyramid),
//! and rays that still traverse the BVH first try the triangles that blocked
//! the pixel's last rays. Those tests use each triangle's edges and normal
//! computed once (obvhs's arithmetic, so the same answers bit for bit), and
//! the BVH's nodes are read with their quantised bounds already converted to
//! floats (`traversal`: obvhs's traversal, node for node): a gather tests a
//! node's eight children against the pyramid at once, a ray its eight boxes.
//! `GroundTruth::visibility_per_ray` is the plain definition, which a test
//! compares it with.
//!
//! The estimate goes further where the occluders are convex pieces (a
//! connected part of a mesh that is a convex solid or a flat convex polygon:
//! a box, a sphere, a leaf card; `pieces`): from a ray origin, each hides one
//! convex polygon of the light, so the share of a part of the light that a
//! few of them hide is computed exactly, in the light's plane, for the whole
//! light or its quarters, with no ray and no noise (`coverage`).
//!
//! The parts, each in a file of its own under `reference/`: `prepare` (the triangles the ground
//! truth traces, their BVH and the convex pieces, made once per scene), `pyramid` (the pyramid
//! shortcuts), `traversal` (the BVH's nodes as the shortcuts read them, and each ray's
//! traversal), `sampling` (the surface points, the strata and their jitter, and each pixel's
//! estimate), `cache` (the on-disk cache and its keys) and `technique` (the `reference`
//! technique and its registration), with `coverage` and `pieces` for the exact shares. This
//! file holds the tracer, what it traces an image into, and the analytic formula the tests
//! check it against.

use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use obvhs::cwbvh::CwBvh;
use obvhs::triangle::Triangle;
use rayon::prelude::*;
use ssm_scene::RectLight;

mod cache;
mod coverage;
mod pieces;
mod prepare;
mod pyramid;
mod sampling;
mod technique;
mod traversal;

pub use cache::{ReferenceCache, default_cache_dir};
pub use sampling::{PixelEstimate, PixelFootprint, Sampling, SplitMix64, SurfacePoint, surface_points};
pub use technique::{INFO, NAME, NOISE_OUTPUT, PARAMS, link};

use prepare::{OccluderLayer, PreparedTriangle};

/// Version of the reference algorithm, part of every cache key: bump it when
/// the results of the same inputs change.
pub const REFERENCE_VERSION: u32 = 7;

/// The scene's triangles in a BVH, ready for shadow rays.
pub struct GroundTruth {
    triangles: Vec<Triangle>,
    /// The same triangles prepared for the shortcuts' tests, in the BVH's primitive order (slot
    /// k holds triangle `bvh.primitive_indices[k]`), so that a traversal reads a leaf's triangles
    /// side by side without looking their indices up. The shortcuts name triangles by slot.
    prepared: Vec<PreparedTriangle>,
    /// Each triangle's unit normal (zero where it has none), for [`GroundTruth::may_cross`].
    normals: Vec<Vec3>,
    bvh: CwBvh,
    /// The same BVH with its nodes decoded for the shortcuts' traversals (obvhs's, faster).
    decoded: traversal::DecodedBvh,
    /// Offset of ray origins off the surface, world units (scaled to the scene).
    surface_offset: f32,
    /// What the cache is keyed by beyond each image's own inputs: the triangles.
    cache: ReferenceCache,
    /// How [`GroundTruth::trace`] traces each pixel.
    traversal: Traversal,
    /// The scene's convex pieces and its other triangles, each in a BVH of its own, for the exact
    /// share of the light a few occluders hide; `None` when no placed mesh is a convex piece.
    occluders: Option<OccluderLayer>,
}

/// How [`GroundTruth::trace`] traces a pixel's rays. Both give the same visibility, ray for ray
/// (a test compares every pixel), so the cache does not tell them apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq, crate::Choice)]
pub enum Traversal {
    /// [`GroundTruth::visibility`]: the pyramid from the point to the light (or its quarters)
    /// gathered from the BVH once, its few triangles tested by each ray.
    Shortcuts,
    /// [`GroundTruth::visibility_per_ray`]: every ray through the BVH, the definition.
    PerRay,
}

/// The result of tracing one image.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceImage {
    /// Visibility per pixel, row-major; 1 for pixels without a surface point.
    pub visibility: Vec<f32>,
    /// The estimate's own error per pixel ([`PixelEstimate::noise`]): the mean over a set of
    /// pixels estimates the ground truth's mean absolute error there, the mean of its squares
    /// its mean squared error.
    pub noise: Vec<f32>,
    /// Light samples evaluated, refinements included (0 when read from the cache). The BVH
    /// shortcuts decide many of them without casting a ray of their own.
    pub rays: u64,
    /// Wall time spent tracing.
    pub elapsed: Duration,
    /// True when the image came from the cache.
    pub cached: bool,
}

impl ReferenceImage {
    /// Shadow rays per second of wall time, when rays were traced.
    #[must_use]
    pub fn rays_per_second(&self) -> Option<f64> {
        (self.rays > 0 && !self.elapsed.is_zero()).then(|| self.rays as f64 / self.elapsed.as_secs_f64())
    }
}

impl GroundTruth {
    /// This tracer with `traversal` for [`GroundTruth::trace`] (the same visibility either way).
    #[must_use]
    pub fn with_traversal(self, traversal: Traversal) -> Self {
        Self { traversal, ..self }
    }

    /// This tracer with (`true`, the default) or without the convex pieces: placed meshes whose
    /// triangles are a convex solid or a flat convex polygon, each one polygon when the estimate
    /// computes the share of a part of the light that a few occluders hide exactly. Without, those
    /// parts are sampled by rays, as any other triangles: the same expected visibility, with the
    /// rays' noise (tests of the rays use it).
    #[must_use]
    pub fn with_convex_pieces(self, pieces: bool) -> Self {
        if pieces { self } else { Self { occluders: None, ..self } }
    }

    /// How many placed meshes the estimate treats as convex pieces
    /// ([`GroundTruth::with_convex_pieces`]).
    #[must_use]
    pub fn convex_piece_count(&self) -> usize {
        self.occluders.as_ref().map_or(0, |layer| layer.pieces.len())
    }

    /// Traces every pixel (`None`: no surface, visibility 1, noise 0) on all cores, each as
    /// [`GroundTruth::estimate`] with its own generator seeded from `seed` and its index.
    #[must_use]
    pub fn trace(&self, light: &RectLight, points: &[Option<SurfacePoint>], sampling: Sampling, seed: u64) -> ReferenceImage {
        let start = Instant::now();
        let estimates: Vec<PixelEstimate> = points
            .par_iter()
            .enumerate()
            .map(|(index, point)| match point {
                Some(point) => self.estimate(light, point, sampling, &mut SplitMix64::for_pixel(seed, index as u64)),
                None => PixelEstimate { visibility: 1.0, noise: 0.0, rays: 0 },
            })
            .collect();
        ReferenceImage {
            visibility: estimates.iter().map(|e| e.visibility).collect(),
            noise: estimates.iter().map(|e| e.noise).collect(),
            rays: estimates.iter().map(|e| e.rays).sum(),
            elapsed: start.elapsed(),
            cached: false,
        }
    }

    /// Number of triangles in the BVH.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
}

/// Exact visibility of a rectangular light from `point` past one rectangular
/// occluder parallel to the light and aligned with its axes: the occluder
/// seen from the point projects onto the light's plane as a rectangle, and
/// the hidden fraction is the product of the two clamped 1-D overlaps with
/// the light (Atty et al., Sec. 4.2). `occluder_centre` is a point of the
/// occluder; `occluder_half_size` its half extents along the light's u and v.
/// Used to test the ray caster on `parallel-square`.
#[must_use]
pub fn parallel_rectangle_visibility(light: &RectLight, occluder_centre: Vec3, occluder_half_size: Vec2, point: Vec3) -> f32 {
    let normal = light.normal();
    let local = |p: Vec3| {
        let offset = p - light.centre;
        (Vec2::new(offset.dot(light.u_axis), offset.dot(light.v_axis)), offset.dot(normal))
    };
    let (point_uv, point_depth) = local(point);
    let (occluder_uv, occluder_depth) = local(occluder_centre);
    if point_depth <= 0.0 {
        return 0.0;
    }
    if !(occluder_depth > 0.0 && occluder_depth < point_depth) {
        return 1.0;
    }
    // From the point, the occluder's plane maps onto the light's plane by this factor.
    let scale = point_depth / (point_depth - occluder_depth);
    if light.is_point() {
        // One ray, to the centre: where does it cross the occluder's plane?
        let crossing = point_uv - point_uv / scale;
        return if (crossing - occluder_uv).abs().cmple(occluder_half_size).all() { 0.0 } else { 1.0 };
    }
    let low = point_uv + (occluder_uv - occluder_half_size - point_uv) * scale;
    let high = point_uv + (occluder_uv + occluder_half_size - point_uv) * scale;
    let overlap = (high.min(light.half_size) - low.max(-light.half_size)).max(Vec2::ZERO);
    1.0 - overlap.x * overlap.y / light.area()
}

#[cfg(test)]
mod tests {
    use ssm_scene::builtin;

    use super::*;

    #[test]
    fn analytic_formula_matches_the_hand_computed_parallel_square() {
        let scene = builtin("parallel-square").unwrap().build();
        let light = &scene.lights[0];
        let exact = |x: f32, z: f32| parallel_rectangle_visibility(light, Vec3::new(0.0, 2.0, 0.0), Vec2::splat(0.5), Vec3::new(x, 0.0, z));
        assert_eq!(exact(0.0, 0.0), 0.0);
        assert_eq!(exact(2.0, 0.0), 1.0);
        // Half-way through the penumbra along x, half the light is hidden.
        assert!((exact(1.0, 0.0) - 0.5).abs() < 1e-6);
        // At (1, 1) a quarter of the light is hidden.
        assert!((exact(1.0, 1.0) - 0.75).abs() < 1e-6);
    }
}
