//! How the ground truth samples a pixel: the surface points it samples (one per pixel, from the
//! G-buffer, with the pixel's footprint where asked), the strata (`Sampling`: two independent
//! sets of N×N jittered strata, refined where the visibility varies), the generator of their
//! jitter (SplitMix64, Steele et al. 2014), and each pixel's estimate and its own error
//! ([`GroundTruth::estimate`]), with the per-ray definition the shortcuts must match.

use glam::{Vec2, Vec3};
use ssm_scene::RectLight;

use super::pyramid::{EXACT_CANDIDATES, NO_LIST, Window};
use super::traversal::RecentBlockers;
use super::{GroundTruth, Traversal};

/// One pixel's surface point as the G-buffer records it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// World position.
    pub position: Vec3,
    /// Unit normal (either side; rays leave on the side facing each light sample, except on a
    /// closed surface: see `closed`).
    pub normal: Vec3,
    /// The point lies on a closed mesh ([`ssm_scene::Scene::closed_meshes`]) and `normal` points
    /// to the side the camera sees (as the G-buffer's does). Such a surface is the boundary of an
    /// opaque solid (or of a closed room), so light reaches the seen side only from in front of
    /// its tangent plane: a ray leaving behind it is blocked. Without this, a wall whose far side
    /// faces a light sealed behind it would see that light through itself.
    pub closed: bool,
    /// The camera rays bounding the pixel, when its visibility is averaged over the pixel's
    /// footprint on the surface's tangent plane instead of taken at the point.
    pub footprint: Option<PixelFootprint>,
}

/// The camera rays through one pixel: every ray through it leaves `eye` along
/// `corner + s·across + t·down` for (s, t) in [0, 1]² (directions are affine in
/// pixel coordinates for a pinhole camera).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelFootprint {
    /// The camera's centre.
    pub eye: Vec3,
    /// The direction through the pixel's top-left corner.
    pub corner: Vec3,
    /// The change of direction from the left edge to the right one.
    pub across: Vec3,
    /// The change of direction from the top edge to the bottom one.
    pub down: Vec3,
}

impl PixelFootprint {
    /// Where the ray through (s, t) of the pixel meets the plane through `point` with `normal`;
    /// `None` when it runs along the plane or meets it behind the eye.
    #[must_use]
    pub fn on_plane(&self, s: f32, t: f32, point: Vec3, normal: Vec3) -> Option<Vec3> {
        let direction = self.corner + self.across * s + self.down * t;
        let denominator = direction.dot(normal);
        if denominator.abs() < 1e-12 {
            return None;
        }
        let distance = (point - self.eye).dot(normal) / denominator;
        (distance > 0.0 && distance.is_finite()).then(|| self.eye + direction * distance)
    }
}

/// How the ground truth samples each pixel ([`GroundTruth::estimate`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampling {
    /// N: each of the two independent sets has N×N strata, one jittered ray each.
    pub samples_per_axis: u32,
    /// M: a stratum where the visibility varies is cut into M×M sub-strata with one jittered ray each,
    /// its own ray standing for the sub-stratum it fell in (1: no refinement).
    pub refine: u32,
}

impl Sampling {
    /// The `reference` technique's defaults: two sets of 12×12 strata, 2×2 rays in a stratum where
    /// the visibility varies.
    pub const DEFAULT: Self = Self { samples_per_axis: 12, refine: 2 };

    /// Two plain stratified sets of `samples_per_axis`² rays, without refinement.
    #[must_use]
    pub const fn uniform(samples_per_axis: u32) -> Self {
        Self { samples_per_axis, refine: 1 }
    }
}

/// One pixel's ground truth: the estimate and its own error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelEstimate {
    /// The visible fraction of the light, (A + B)/2 of the two independent estimates.
    pub visibility: f32,
    /// |A − B|/2: an estimate of the estimate's absolute error (for Gaussian errors its
    /// expectation is E|visibility − exact|, and its square is unbiased for the variance).
    pub noise: f32,
    /// Light samples evaluated.
    pub rays: u64,
}

/// The mean of the strata's visible fractions.
fn visible_fraction(strata: &[f32]) -> f32 {
    strata.iter().sum::<f32>() / strata.len().max(1) as f32
}

/// Whether the visibility of an N×N set (`strata`) varies at stratum `index`: its result differs
/// from one of its four neighbours'. A neighbour given a part of the light's exact share (`exact`,
/// strictly between 0 and 1) says nothing of where its edges run, and is not compared.
fn varies(strata: &[f32], exact: &[bool], n: u32, index: usize) -> bool {
    let n = n as usize;
    let (i, j) = (index % n, index / n);
    let own = strata[index];
    let differs = |neighbour: usize| {
        let value = strata[neighbour];
        value != own && !(exact[neighbour] && value > 0.0 && value < 1.0)
    };
    (i > 0 && differs(index - 1)) || (i + 1 < n && differs(index + 1)) || (j > 0 && differs(index - n)) || (j + 1 < n && differs(index + n))
}

impl GroundTruth {
    /// Visible fraction of `light` from `point`, with one set of `samples_per_axis`² stratified
    /// samples jittered by `rng`. Points behind the light's plane see none of it.
    /// With a footprint, each sample also starts from its own point of the
    /// pixel's footprint on the tangent plane (stratified too, the pixel's
    /// strata paired with the light's in a random order): the visibility
    /// averaged over the pixel, what a screen-space prefilter aims at.
    /// [`GroundTruth::estimate`] is what the ground truth traces: two such sets, refined where
    /// the visibility varies, with the noise they imply.
    #[must_use]
    pub fn visibility(&self, light: &RectLight, point: &SurfacePoint, samples_per_axis: u32, rng: &mut SplitMix64) -> f32 {
        if point.footprint.is_none() && (point.position - light.centre).dot(light.normal()) <= 0.0 {
            return 0.0;
        }
        visible_fraction(&self.stratified(light, point, samples_per_axis.max(1), rng, true))
    }

    /// [`GroundTruth::visibility`] one ray at a time through the BVH: the definition the
    /// shortcuts must match (tests compare them).
    #[must_use]
    pub fn visibility_per_ray(&self, light: &RectLight, point: &SurfacePoint, n: u32, rng: &mut SplitMix64) -> f32 {
        if point.footprint.is_none() && (point.position - light.centre).dot(light.normal()) <= 0.0 {
            return 0.0;
        }
        visible_fraction(&self.stratified(light, point, n.max(1), rng, false))
    }

    /// The estimate the ground truth traces for one pixel, and its own error.
    ///
    /// Two independent stratified sets of `samples_per_axis`² jittered rays, A and B. Each set is
    /// then refined where the visibility varies across the light: a stratum whose result in the
    /// other set differs from one of its four neighbours' (an edge of the visible region crosses
    /// it or passes near) is decided exactly when at most four triangles can block its rays (the
    /// area their projection covers, `reference/coverage.rs`), and otherwise is cut into `refine`²
    /// sub-strata: its own ray, uniform over the stratum and so over the sub-stratum it fell in,
    /// stands for that one, and each of the others gets a fresh jittered ray.
    /// A part of the light whose pyramid holds at most four triangles, or that at most six convex
    /// pieces' and other triangles' projections meet ([`GroundTruth::with_convex_pieces`]), is
    /// decided exactly for both sets at once, before any ray (in the pyramid shortcuts), and its
    /// strata are neither refined nor compared as neighbours. Each set is unbiased, since which strata it refines
    /// depends only on the other set's rays and on the triangles (not on its own jitter);
    /// the estimate is (A + B)/2 and its noise |A − B|/2, whose mean over pixels estimates the
    /// mean absolute error of the estimate (and its square the variance, pixel by pixel). Lit and
    /// umbra pixels that the BVH shortcuts decide exactly have no noise; a point light casts one
    /// ray. A pixel footprint is sampled without refinement (its strata pair light and pixel
    /// points at random).
    #[must_use]
    pub fn estimate(&self, light: &RectLight, point: &SurfacePoint, sampling: Sampling, rng: &mut SplitMix64) -> PixelEstimate {
        if point.footprint.is_none() && (point.position - light.centre).dot(light.normal()) <= 0.0 {
            return PixelEstimate { visibility: 0.0, noise: 0.0, rays: 0 };
        }
        let n = sampling.samples_per_axis.max(1);
        let shortcuts = self.traversal == Traversal::Shortcuts;
        let mut set_rngs = [rng.fork(), rng.fork()];
        let refine_seeds = [rng.next_u64(), rng.next_u64()];
        // The two sets share the pyramid shortcuts' gathers (the same triangles for any jitter).
        let shared = (shortcuts && point.footprint.is_none()).then(|| self.pyramid_visibility(light, point, n, &mut set_rngs, true));
        let (strata, exact, lists, stratum_list, base_jitter) = match shared {
            Some(mut rays) => {
                // Refinement reads where each stratum's own ray went (drawn already where a ray
                // was cast; the shortcuts decided every other stratum, which is not refined).
                if !rays.exact.iter().all(|e| *e) {
                    rays.draw_jitter();
                }
                (rays.strata, rays.exact, rays.lists, rays.stratum_list, rays.jitter)
            }
            None => {
                // Without a footprint, visibility_of_rays draws each stratum's jitter and nothing
                // else, in this order: the same draws from a copy give where each ray went, which
                // refinement needs. A footprint is not refined.
                let base_jitter = set_rngs
                    .iter()
                    .map(|rng| {
                        let mut rng = rng.clone();
                        let count = if point.footprint.is_none() { n * n } else { 0 };
                        (0..count).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect()
                    })
                    .collect();
                let strata = set_rngs.iter_mut().map(|rng| self.visibility_of_rays(light, point, n, rng, shortcuts)).collect();
                (strata, vec![false; (n * n) as usize], Vec::new(), vec![NO_LIST; (n * n) as usize], base_jitter)
            }
        };
        let refine = if point.footprint.is_some() { 1 } else { sampling.refine.max(1) };
        let sub_rays = refine * refine;
        let mut rays = 2 * u64::from(n * n);
        let mut sets = [0.0f32; 2];
        let mut recent = RecentBlockers::default();
        let (mut jitter, mut candidates) = (Vec::new(), Vec::new());
        let origins = self.origins(point);
        // A pixel every stratum of which a shortcut decided (lit, umbra, or the exact share of a
        // few triangles) has nothing to refine.
        let all_exact = exact.iter().all(|e| *e);
        for (k, set) in sets.iter_mut().enumerate() {
            if refine == 1 || all_exact {
                *set = visible_fraction(&strata[k]);
                continue;
            }
            let other = &strata[1 - k];
            let mut sum = 0.0f32;
            for (index, &value) in strata[k].iter().enumerate() {
                if exact[index] || !varies(other, &exact, n, index) {
                    // Exact: a shortcut decided every ray of this part of the light.
                    sum += value;
                    continue;
                }
                let window = Window::LIGHT.stratum(index as u32, n);
                let list = lists.get(stratum_list[index] as usize);
                // The stratum exactly, from the area its few triangles cover; else M×M rays
                // against the triangles its ray was tested against (those that can cross its own
                // pyramid), or, without a list, through the BVH as its ray went.
                let (exact_value, candidates) = match list {
                    Some(list) => {
                        // A stratum with a list lies on one side of the tangent plane.
                        let origin = origins[usize::from(point.normal.dot(light.point(window.min.x, window.min.y) - point.position) < 0.0)];
                        let candidates = self.stratum_candidates(light, origin, window, list, &mut candidates);
                        let exact_value =
                            (candidates.len() <= EXACT_CANDIDATES).then(|| self.exact_coverage(light, origin, window, candidates));
                        (exact_value, Some((origin, candidates)))
                    }
                    None => (None, None),
                };
                if let Some(value) = exact_value {
                    sum += value;
                    continue;
                }
                rays += u64::from(sub_rays - 1);
                let mut sub_rng = SplitMix64::for_pixel(refine_seeds[k], index as u64);
                jitter.clear();
                jitter.extend((0..sub_rays).map(|_| Vec2::new(sub_rng.next_f32(), sub_rng.next_f32())));
                // The stratum's own ray, uniform over the stratum, is uniform over the sub-stratum
                // it fell in: it stands for that one, and the others get fresh rays.
                let kept_cell = {
                    let cell = (base_jitter[k][index] * refine as f32).floor().clamp(Vec2::ZERO, Vec2::splat((refine - 1) as f32));
                    cell.y as usize * refine as usize + cell.x as usize
                };
                let visible = value as usize
                    + window
                        .jittered(&jitter, refine)
                        .enumerate()
                        .filter(|(cell, _)| *cell != kept_cell)
                        .filter(|(_, at)| match candidates {
                            Some((origin, candidates)) => !self.blocked_by(origin, light.point(at.x, at.y), candidates),
                            None => self.light_sample_visible(light, point, *at, shortcuts.then_some(&mut recent)),
                        })
                        .count();
                sum += visible as f32 / sub_rays as f32;
            }
            *set = sum / (n * n) as f32;
        }
        PixelEstimate { visibility: 0.5 * (sets[0] + sets[1]), noise: 0.5 * (sets[0] - sets[1]).abs(), rays }
    }

    /// Whether the ray from `point` to the light's point at `at` (in [-1, 1]² along its axes)
    /// reaches it, as [`GroundTruth::visibility_of_rays`] decides one sample of a point without a
    /// footprint; with `recent`, the pixel's last blockers are tried first (the same answer).
    fn light_sample_visible(&self, light: &RectLight, point: &SurfacePoint, at: Vec2, recent: Option<&mut RecentBlockers>) -> bool {
        let sample = light.point(at.x, at.y);
        let front = point.normal.dot(sample - point.position) >= 0.0;
        if point.closed && !front {
            return false;
        }
        let origin = self.origins(point)[usize::from(!front)];
        match recent {
            Some(recent) => !self.blocked_remembering(origin, sample, recent),
            None => self.unoccluded(origin, sample),
        }
    }

    /// One set of N² stratified samples of a point in front of the light: each stratum's result
    /// (0 or 1) at j·n + i. With `shortcuts`, a point without a footprint goes through
    /// the pyramid shortcuts ([`GroundTruth::pyramid_visibility`]); otherwise each ray goes
    /// through the BVH.
    fn stratified(&self, light: &RectLight, point: &SurfacePoint, n: u32, rng: &mut SplitMix64, shortcuts: bool) -> Vec<f32> {
        if shortcuts && point.footprint.is_none() {
            return self.pyramid_visibility(light, point, n, std::slice::from_mut(rng), false).strata.swap_remove(0);
        }
        self.visibility_of_rays(light, point, n, rng, shortcuts)
    }

    /// The ray origins off `point`'s surface: for light samples in front of its tangent plane
    /// (offset along the normal) and behind it (against it).
    pub(super) fn origins(&self, point: &SurfacePoint) -> [Vec3; 2] {
        let offset = point.normal * self.surface_offset;
        [point.position + offset, point.position - offset]
    }

    /// The N² rays of a pixel, each through the BVH, each stratum's result; with `remember`, each ray first tries the
    /// last few triangles that blocked the pixel's rays (neighbouring rays mostly hit the same
    /// ones), which changes no answer: a ray one of them blocks is blocked.
    fn visibility_of_rays(&self, light: &RectLight, point: &SurfacePoint, n: u32, rng: &mut SplitMix64, remember: bool) -> Vec<f32> {
        let n = n.max(1);
        let mut recent = RecentBlockers::default();
        // With a footprint, the pixel's strata in a random order: a fixed pairing with the
        // light's strata (such as (i, j) with (j, i)) correlates them and biases the average.
        let pixel_strata: Vec<u32> = match point.footprint {
            Some(_) => {
                let mut order: Vec<u32> = (0..n * n).collect();
                for k in (1..order.len()).rev() {
                    order.swap(k, (rng.next_u64() % (k as u64 + 1)) as usize);
                }
                order
            }
            None => Vec::new(),
        };
        let mut strata = vec![0.0f32; (n * n) as usize];
        for j in 0..n {
            for i in 0..n {
                let jitter = Vec2::new(rng.next_f32(), rng.next_f32());
                let stratum = (Vec2::new(i as f32, j as f32) + jitter) / n as f32 * 2.0 - Vec2::ONE;
                let sample = light.point(stratum.x, stratum.y);
                let position = match &point.footprint {
                    Some(footprint) => {
                        let cell = pixel_strata[(j * n + i) as usize];
                        let sub_pixel =
                            (Vec2::new((cell % n) as f32, (cell / n) as f32) + Vec2::new(rng.next_f32(), rng.next_f32())) / n as f32;
                        let position = footprint.on_plane(sub_pixel.x, sub_pixel.y, point.position, point.normal).unwrap_or(point.position);
                        if (position - light.centre).dot(light.normal()) <= 0.0 {
                            continue;
                        }
                        position
                    }
                    None => point.position,
                };
                // Leave the surface on the side facing this sample, so that it does not shadow itself;
                // a closed surface passes no light to its seen side from behind.
                let side = if point.normal.dot(sample - position) >= 0.0 { 1.0 } else { -1.0 };
                if point.closed && side < 0.0 {
                    continue;
                }
                let origin = position + point.normal * (side * self.surface_offset);
                let open = if remember { !self.blocked_remembering(origin, sample, &mut recent) } else { self.unoccluded(origin, sample) };
                strata[(j * n + i) as usize] = if open { 1.0 } else { 0.0 };
            }
        }
        strata
    }
}

/// SplitMix64 (Steele et al. 2014): a tiny, well-distributed generator; one
/// per pixel, seeded from the run's seed and the pixel's index.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator for pixel `index` of a run seeded with `seed`.
    #[must_use]
    pub fn for_pixel(seed: u64, index: u64) -> Self {
        let mut mixer = Self { state: seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15) };
        // Decorrelate neighbouring pixels before use.
        mixer.next_u64();
        mixer
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// An independent generator seeded from this one's next output.
    pub fn fork(&mut self) -> Self {
        let state = self.next_u64();
        let mut forked = Self { state };
        forked.next_u64();
        forked
    }

    /// A float uniform in `[0, 1)`.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// The points the ground truth samples, one per pixel (`None` where nothing
/// was drawn): the G-buffer's positions (`w` = coverage) and normals as read
/// back, with each pixel's footprint on its tangent plane when
/// `pixel_footprint` (the `footprint = pixel` parameter). These points are
/// part of the cache key, so the same view gives the same points.
#[must_use]
pub fn surface_points(
    positions: &[[f32; 4]],
    normals: &[[f32; 4]],
    camera: &crate::CameraUniform,
    pixel_footprint: bool,
) -> Vec<Option<SurfacePoint>> {
    let width = (camera.viewport[0] as usize).max(1);
    positions
        .iter()
        .zip(normals)
        .enumerate()
        .map(|(index, (p, n))| {
            (p[3] > 0.5).then(|| SurfacePoint {
                position: Vec3::new(p[0], p[1], p[2]),
                normal: Vec3::new(n[0], n[1], n[2]).normalize_or(Vec3::Y),
                closed: crate::GBuffer::flags(n[3]) & crate::GBuffer::CLOSED != 0,
                footprint: pixel_footprint.then(|| pixel_rays(camera, (index % width) as f32, (index / width) as f32)),
            })
        })
        .collect()
}

/// The camera rays through the pixel whose top-left corner is at (`x`, `y`), in pixels.
fn pixel_rays(camera: &crate::CameraUniform, x: f32, y: f32) -> PixelFootprint {
    let inverse = glam::Mat4::from_cols_array_2d(&camera.inverse_view_proj);
    let eye = Vec3::new(camera.position[0], camera.position[1], camera.position[2]);
    // Points of the far plane are affine in NDC, so the directions are affine in pixels.
    let direction = |x: f32, y: f32| {
        let ndc = glam::Vec4::new(x * camera.viewport[2] * 2.0 - 1.0, 1.0 - y * camera.viewport[3] * 2.0, 1.0, 1.0);
        let far = inverse * ndc;
        far.truncate() / far.w - eye
    };
    let corner = direction(x, y);
    PixelFootprint { eye, corner, across: direction(x + 1.0, y) - corner, down: direction(x, y + 1.0) - corner }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generator_is_uniform_enough_and_repeatable() {
        let mut a = SplitMix64::for_pixel(7, 3);
        let mut b = SplitMix64::for_pixel(7, 3);
        let samples: Vec<f32> = (0..10_000).map(|_| a.next_f32()).collect();
        assert!(samples.iter().all(|s| (0.0..1.0).contains(s)));
        let mean = samples.iter().sum::<f32>() / samples.len() as f32;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        assert_eq!(samples[0], b.next_f32());
        assert_ne!(SplitMix64::for_pixel(7, 4).next_u64(), SplitMix64::for_pixel(7, 3).next_u64());
    }
}
