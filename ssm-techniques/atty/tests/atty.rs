//! Atty et al. 2006 (`atty`) against the exact answer and against its own
//! paper's claims: the discretisation bound of Sec. 5.1.1, Appendix A's FP16
//! failure, the two-sided variant of Sec. 3.5, and a point light; the shortcuts
//! of the micro-patch list against derived bounds; and the receiver-plane test
//! on interiors, coplanar surfaces and contact.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::{Mat4, Quat, Vec2, Vec3};
use ssm_core::LightFrame;
use ssm_core::metrics::compare;
use ssm_scene::{Role, Scene, builtin};
use ssm_testing::{at, gpu, mean_abs_difference, pixel_of, reference, render, scene_from_manifest};

const SIZE: (u32, u32) = (160, 120);

/// Penumbra MAE of `atty` with `settings` on parallel-square, against the exact
/// visibility at the same G-buffer points.
fn parallel_square_error(settings: &[(&str, &str)]) -> f64 {
    parallel_square_errors(settings).0
}

/// (Penumbra MAE, largest error over the pixels in umbra or penumbra) of `atty` with `settings` on
/// parallel-square, against the exact visibility at the same G-buffer points.
fn parallel_square_errors(settings: &[(&str, &str)]) -> (f64, f64) {
    let scene = builtin("parallel-square").unwrap().build();
    let rendered = render(&gpu(), &scene, &ssm_atty::INFO, settings, SIZE.0, SIZE.1).unwrap();
    let exact = rendered.parallel_square_exact();
    let covered = rendered.coverage();
    let mae = compare(&exact, &rendered.visibility, &covered, SIZE.0 as usize, SIZE.1 as usize).mae_penumbra;
    let max = exact
        .iter()
        .zip(&rendered.visibility)
        .zip(&covered)
        .filter(|((e, _), c)| **c && **e < 1.0)
        .map(|((e, v), _)| f64::from((e - v).abs()))
        .fold(0.0, f64::max);
    (mae, max)
}

/// The shared light frame's half-angle tangent on parallel-square (the same along u and v).
fn parallel_square_tan_half() -> f32 {
    let scene = builtin("parallel-square").unwrap().build();
    LightFrame::fit(&scene.lights[0], &scene.bounds()).tan_half.x
}

/// Penumbra MAE of `atty` with `settings` against a 16×16-sample ground truth on `scene`.
fn error_against_reference(scene: &Scene, settings: &[(&str, &str)]) -> f64 {
    ssm_testing::error_against_reference(scene, &ssm_atty::INFO, settings, 16, SIZE).mae_penumbra
}

/// Sec. 5.1.1: each micro-patch over- or under-estimates the occluder by at most half a texel.
/// On parallel-square (occluder at depth z_O = 2, receiver at z_R = 4, unit light) an edge off by
/// δ = z_O·tan/N moves its back-projection on the light by δ·z_R/(z_R − z_O) = 2δ, so each 1-D
/// overlap o_u, o_v of the occluder's image with the light (Sec. 4.2) is off by at most
/// ε = 2δ = 4·tan/N (the image is twice the light's width, so one edge at a time lies on it).
/// The hidden fraction o_u·o_v is then off by at most ε(o_u + o_v) + ε² ≤ 2ε + ε² (both axes
/// in penumbra, at the penumbra's corners). The SSM is read with bilinear interpolation: at the
/// kinks of the piecewise-linear overlaps (slope 1 per world unit here) that adds at most half an
/// SSM texel at z_R per axis, 2·(4·tan/S). Overlaps between patches (Sec. 5.1.2) vanish: every
/// patch has the same depth. Power-of-two sizes put the square's edges at the same fraction of a
/// texel (the paper's own remark, Sec. 5.2.3), so the sizes here are not powers of two. The bound
/// is on each pixel's error, so it is asserted on the largest error over the pixels in umbra or
/// penumbra; the mean error is asserted to fall with N.
#[test]
fn parallel_square_error_is_within_the_discretisation_bound_and_falls_with_the_map_size() {
    let ssm = 512.0;
    let mut errors = Vec::new();
    for n in [33u32, 63, 127, 255] {
        let (error, worst) = parallel_square_errors(&[("occluder_map_size", &n.to_string()), ("ssm_size", "512")]);
        let bound = f64::from(discretisation_bound(n as f32, ssm));
        println!("occluder map {n}²: penumbra MAE {error:.4}, largest error {worst:.4} (bound on it {bound:.4})");
        assert!(worst <= bound, "N = {n}: the largest error {worst} is above the discretisation bound {bound}");
        errors.push(error);
    }
    for pair in errors.windows(2) {
        assert!(pair[1] < pair[0], "the error falls as the occluder map grows: {errors:?}");
    }
    assert!(errors[3] < errors[0] / 5.0, "{errors:?}");
}

/// The fraction of the unit light that one micro-patch of an `n`² occluder map hides on
/// parallel-square: its width 2·z_O·tan/N back-projected from z_R = 4 through z_O = 2 (scale 2),
/// squared (the light is 1 × 1).
fn parallel_square_patch_share(n: f32) -> f32 {
    (2.0 * 2.0 * parallel_square_tan_half() / n * 2.0).powi(2)
}

/// The most micro-patches one receiver point of parallel-square sees (the occluder map's texels
/// whose back-projection from it meets the light): the pyramid from the point to the light is
/// l·(z_R − z_O)/z_R = 0.25 wide on each side at the occluder's depth, 0.25/(z_O·tan) in ndc,
/// that many times N/2 texels, plus the two texels its edges cut, per axis.
fn parallel_square_patches_per_point(n: f32) -> f32 {
    (n * 0.25 / (2.0 * parallel_square_tan_half()) + 2.0).powi(2)
}

/// Appendix A, Eq. 4: FP16 has a 10-bit mantissa, so near a sum of 1 its numbers are 2⁻¹¹ to
/// 2⁻¹⁰ apart, and adding a patch that hides ε of the light is off by up to half that spacing:
/// where ε is well above 2⁻¹⁰ that is a small share of each addition, where it is below, a whole
/// addition is lost or doubled. On parallel-square (merge_tolerance 0: one patch per texel, as the
/// paper) ε = 0.016 at 128² and 2.5·10⁻⁴ at 1024², on either side of 2⁻¹⁰. At 128² FP16 then
/// differs from FP32 by its rounding alone: per pixel at most 2⁻¹¹ (one spacing below 1, either
/// rounding mode) per patch the point sees, plus one for storing the result; at 1024² it must be
/// off by more than that allowance beyond FP32's own error, and FP32 (23 bits) stays within the
/// discretisation bound at both sizes. Merged patches (the default) are far larger: FP16 is back
/// within the allowance at 1024².
#[test]
fn fp16_accumulation_fails_at_high_resolution_and_fp32_does_not() {
    let fp16_spacing_at_one = 2f32.powi(-10);
    assert!(
        parallel_square_patch_share(128.0) > fp16_spacing_at_one && parallel_square_patch_share(1024.0) < fp16_spacing_at_one,
        "the paper's condition separates the two sizes"
    );
    let run = |n: &str, accumulation: &str, merge: &str| {
        let scene = builtin("parallel-square").unwrap().build();
        // The paper's mode (no receiver plane), whose claim Appendix A is.
        let settings = [
            ("occluder_map_size", n),
            ("accumulation", accumulation),
            ("ssm_size", "128"),
            ("merge_tolerance", merge),
            ("receiver_plane", "false"),
        ];
        let rendered = render(&gpu(), &scene, &ssm_atty::INFO, &settings, SIZE.0, SIZE.1).unwrap();
        let (exact, covered) = (rendered.parallel_square_exact(), rendered.coverage());
        (rendered.visibility, exact, covered)
    };
    let penumbra_error = |(visibility, exact, covered): &(Vec<f32>, Vec<f32>, Vec<bool>)| {
        compare(exact, visibility, covered, SIZE.0 as usize, SIZE.1 as usize).mae_penumbra as f32
    };
    let allowance = (parallel_square_patches_per_point(128.0) + 1.0) * 2f32.powi(-11);
    // 128²: FP16 is FP32 give or take its rounding; FP32 within the discretisation bound.
    let (f16_low, f32_low) = (run("128", "f16", "0"), run("128", "f32", "0"));
    let largest = f16_low.0.iter().zip(&f32_low.0).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    println!("f16 against f32 at 128²: largest difference {largest:.4} (rounding allowance {allowance:.4})");
    assert!(largest <= allowance, "{largest}");
    // 1024²: FP16 fails, FP32 does not.
    let (f16_high, f32_high) = (run("1024", "f16", "0"), run("1024", "f32", "0"));
    let (f16_error, f32_error) = (penumbra_error(&f16_high), penumbra_error(&f32_high));
    println!(
        "penumbra MAE at 1024²: f16 {f16_error:.4}, f32 {f32_error:.4}; at 128²: f16 {:.4}, f32 {:.4}",
        penumbra_error(&f16_low),
        penumbra_error(&f32_low)
    );
    assert!(f16_error > f32_error + allowance, "FP16 at 1024² must fail: {f16_error} against {f32_error}");
    for (n, f32_run) in [(128.0f32, &f32_low), (1024.0, &f32_high)] {
        let worst = worst_error_in_shadow(f32_run);
        let bound = discretisation_bound(n, 128.0);
        println!("f32 at {n}²: largest error in umbra or penumbra {worst:.4} (bound {bound:.4})");
        assert!(worst <= bound, "FP32 at {n}²: {worst} above {bound}");
    }
    // Merged patches at 1024² (the default).
    let merged = penumbra_error(&run("1024", "f16", "0.01"));
    println!("f16 at 1024² with merged patches: penumbra MAE {merged:.4}");
    assert!(merged <= f32_error + allowance, "merged patches keep FP16 accurate: {merged}");
}

/// The default receiver model (`receiver_plane`) is no less accurate than the paper's mode on the
/// paper's own analytic case (parallel-square, Sec. 5.2), at occluder maps near 256² and 1024².
/// A single map size is not a fair judge: how the square's edges fall on the occluder map's texel
/// grid (its phase) moves the error several times over and flips its sign (at 160×120: the paper's
/// mode 0.0037 to 0.0279 penumbra MAE between 252² and 259²), and the paper's mode reads the SSM
/// at a lookup moved off the surface, which shifts the shadow against that phase by a fraction of
/// a texel: better at some sizes (256², 1024²), worse at others. So each mode is judged by its mean
/// over eight consecutive sizes, a whole cycle of the phase. Seen red with the receiver-plane
/// projection's bilinear lookup half a texel off (0.0174 against 0.0156 near 256²).
#[test]
fn the_default_is_no_less_accurate_than_the_papers_mode_over_the_grid_phase() {
    for around in [256u32, 1024] {
        let sizes: Vec<String> = (around - 4..around + 4).map(|n| n.to_string()).collect();
        let mean_error = |receiver_plane: &str| {
            sizes.iter().map(|n| parallel_square_error(&[("occluder_map_size", n), ("receiver_plane", receiver_plane)])).sum::<f64>()
                / sizes.len() as f64
        };
        let (default, paper) = (mean_error("true"), mean_error("false"));
        println!("occluder maps {}² to {}²: mean penumbra MAE, default {default:.5}, the paper's mode {paper:.5}", around - 4, around + 3);
        assert!(default <= paper, "around {around}²: the default's {default} is above the paper mode's {paper}");
    }
}

/// The largest |visibility − exact| over the covered pixels in umbra or penumbra (exact < 1).
fn worst_error_in_shadow((visibility, exact, covered): &(Vec<f32>, Vec<f32>, Vec<bool>)) -> f32 {
    visibility.iter().zip(exact).zip(covered).filter(|((_, e), c)| **c && **e < 1.0).map(|((v, e), _)| (v - e).abs()).fold(0.0, f32::max)
}

/// Sec. 5.1.1's bound on one pixel's error on parallel-square with an `n`² occluder map and an
/// `ssm`² soft shadow map (derived in the test above): 2ε + ε² with ε = 4·tan/N, plus the SSM's
/// bilinear reading, 2·(4·tan/S).
fn discretisation_bound(n: f32, ssm: f32) -> f32 {
    let tan = parallel_square_tan_half();
    let epsilon = 4.0 * tan / n;
    2.0 * epsilon + epsilon * epsilon + 2.0 * 4.0 * tan / ssm
}

/// Sec. 3.5: the two-sided variant adds the farthest back faces as a second layer of micro-patches
/// and keeps the larger occlusion. On a thick occluder (floating-sphere's sphere, whose lower
/// half's back faces are seen from the light) that layer must matter: it may only darken (the
/// maximum of two occlusions), it must darken a clear share of the receiver's pixels, and it must
/// bring the penumbra error down. On the square, which has no thickness, it changes nothing.
#[test]
fn two_sided_darkens_where_the_back_faces_hide_more_and_is_more_accurate() {
    let sphere = builtin("floating-sphere").unwrap().build();
    let gpu = gpu();
    let one = render(&gpu, &sphere, &ssm_atty::INFO, &[], SIZE.0, SIZE.1).unwrap();
    let two = render(&gpu, &sphere, &ssm_atty::INFO, &[("two_sided", "true")], SIZE.0, SIZE.1).unwrap();
    let receives = one.receivers();
    let pairs: Vec<(f32, f32)> =
        one.visibility.iter().zip(&two.visibility).zip(&receives).filter(|(_, r)| **r).map(|((a, b), _)| (*a, *b)).collect();
    let lighter = pairs.iter().filter(|(a, b)| b > &(a + 1e-4)).count();
    let darkened = pairs.iter().filter(|(a, b)| b < &(a - 0.02)).count() as f64 / pairs.len() as f64;
    let (error_one, error_two) = (error_against_reference(&sphere, &[]), error_against_reference(&sphere, &[("two_sided", "true")]));
    println!(
        "floating-sphere: two-sided darkens {:.2}% of receiver pixels by more than 0.02; penumbra MAE one-sided {error_one:.4}, two-sided {error_two:.4}",
        darkened * 100.0
    );
    assert_eq!(lighter, 0, "the second layer can only add occlusion");
    assert!(darkened > 0.02, "the back faces must darken part of the penumbra: {darkened}");
    assert!(error_two < 0.95 * error_one, "two-sided {error_two} must beat one-sided {error_one} by 5%");
    let (one, two) = (parallel_square_error(&[]), parallel_square_error(&[("two_sided", "true")]));
    assert!((one - two).abs() < 1e-6, "parallel-square: one-sided {one}, two-sided {two}");
}

/// A point light: every micro-patch hides all or nothing, and the result is the hard shadow of
/// the discretised occluder (Sec. 5.2.4).
#[test]
fn a_point_light_gives_the_hard_shadow() {
    let mut scene = builtin("floating-sphere").unwrap().build();
    scene.lights[0].half_size = Vec2::ZERO;
    let gpu = gpu();
    let atty = render(&gpu, &scene, &ssm_atty::INFO, &[("occluder_map_size", "512"), ("ssm_size", "1024")], SIZE.0, SIZE.1).unwrap();
    let exact = ssm_testing::reference(&gpu, &scene, 1, SIZE);
    let receives = atty.receivers();
    let compared: Vec<(f32, f32)> =
        atty.visibility.iter().zip(&exact.visibility).zip(&receives).filter(|(_, r)| **r).map(|((a, e), _)| (*a, *e)).collect();
    let penumbra = compared.iter().filter(|(a, _)| *a > 0.02 && *a < 0.98).count() as f32 / compared.len() as f32;
    let wrong = compared.iter().filter(|(a, e)| (a - e).abs() > 0.5).count() as f32 / compared.len() as f32;
    println!("point light: {:.2}% of receiver pixels in a penumbra, {:.2}% on the wrong side", penumbra * 100.0, wrong * 100.0);
    assert!(penumbra < 0.01, "a point light casts no penumbra: {penumbra}");
    assert!(wrong < 0.01, "{wrong} of pixels disagree with the exact hard shadow");
}

/// Without `receiver_plane` (the paper's receiver map of depths alone), `receiver_tolerance`
/// decides which receiver-map depths count as the receiver looked up. On a platform standing on
/// the ground, the platform's side faces lie below its top edge as the light sees them: within a
/// few texel footprints they are the top's receiver, past it they are hidden (in umbra, as the
/// ground truth has them, facing away from the light). A tolerance so large that no receiver is
/// ever hidden lights them and reads the top's occlusion across the depth edge. With
/// `receiver_plane` (the default) each point is compared with its texel's receiver plane along its
/// own ray, which separates the surfaces whatever the tolerance.
#[test]
fn the_receiver_tolerance_separates_receivers_at_a_depth_edge() {
    let text = r#"
[camera]
position = [-1.0, 5.0, 5.0]
target = [0.5, 0.0, 0.0]
[[light]]
centre = [0.0, 4.0, 0.0]
normal = [0.0, -1.0, 0.0]
size = [1.0, 1.0]
[[object]]
primitive = "plane"
size = [1.0, 1.0]
translate = [0.0, 2.5, 0.0]
role = "occluder"
[[object]]
primitive = "box"
size = [3.0, 1.0, 4.0]
translate = [1.5, 0.5, 0.0]
role = "receiver"
[[object]]
primitive = "plane"
size = [10.0, 10.0]
role = "receiver"
"#;
    let scene = scene_from_manifest(text);
    let error = |plane: &'static str, tolerance: &'static str| {
        error_against_reference(&scene, &[("ssm_size", "128"), ("receiver_plane", plane), ("receiver_tolerance", tolerance)])
    };
    let (default, unbounded) = (error("false", "2"), error("false", "64"));
    let (plane_default, plane_unbounded) = (error("true", "2"), error("true", "64"));
    println!(
        "platform: penumbra MAE with receiver_tolerance 2 (default) {default:.4}, 64 {unbounded:.4}; with receiver_plane {plane_default:.4}, {plane_unbounded:.4}"
    );
    assert!(default < 0.5 * unbounded, "{default} vs {unbounded}");
    assert!(plane_default < 0.5 * unbounded && plane_unbounded < 0.5 * unbounded, "{plane_default}, {plane_unbounded} vs {unbounded}");
}

/// The unit roundoff of f32.
const UNIT_ROUNDOFF: f64 = 1.0 / (1u64 << 24) as f64;

/// γ_n = n·u/(1 − n·u): recursive summation of n + 1 terms in f32 is within γ_n·Σ|x_i| of the
/// exact sum (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., Eq. 4.4).
fn gamma(n: f64) -> f64 {
    n * UNIT_ROUNDOFF / (1.0 - n * UNIT_ROUNDOFF)
}

/// What bounds how many micro-patches one receiver point of `scene` sees, for an `n`² occluder
/// map: the half extent l of the light (the larger), the nearest occluder depth z_min (from its
/// bounding box) and the frame's smaller half-angle tangent (the frame that `LightFrame::fit`
/// fits to the scene's bounds; the renderer's is the same or wider, which only lowers the count).
/// Patches that hide part of the light from a point lie in the pyramid from the point to the
/// light, at most l/z wide on each side of its axis in ndc·tan at depth z (≤ 2l/(z·tan) across),
/// one patch centre per 2/N of ndc, plus the two patches its edges cut: at most
/// (N·l/(z_min·tan) + 2)² per point, per occluder map (one layer; merged patches are fewer).
fn patches_per_point(scene: &Scene, n: f64) -> f64 {
    let light = &scene.lights[0];
    let frame = LightFrame::fit(light, &scene.bounds());
    let occluders = scene.bounds_where(Role::casts);
    let nearest = occluders.corners().iter().map(|c| (*c - light.centre).dot(light.normal())).fold(f32::INFINITY, f32::min);
    let (half, tan) = (f64::from(light.half_size.max_element()), f64::from(frame.tan_half.min_element()));
    (n * half / (f64::from(nearest.max(frame.near)) * tan) + 2.0).powi(2)
}

/// Bounding each micro-patch's penumbra rectangle by the deepest receiver under it (a max-pyramid
/// of the receiver map) instead of the far plane drops only SSM texels the patch hides nothing
/// at: the SSM texels get the same occlusion terms, added in another order (the patch list is
/// appended with atomics, in no fixed order). Each texel's f32 sum of its M non-negative terms is
/// then within γ_{M−1} of the exact sum S (Higham, Eq. 4.4), so the two differ by at most
/// 2·γ_{M−1}·S; the visibility clamps S to [0, 1] and blends texels with the same weights, and
/// each of its four operations rounds by at most u: |Δ| ≤ 2·γ_{M−1}·(1 + 2γ_{M−1}) + 4u, with M
/// from [`patches_per_point`]. Cases: a floating occluder, one- and two-sided, an occluder
/// touching its receiver, foliage, a receiver with objects of role `both`, and an SSM whose side
/// is not a power of two (the pyramid's odd levels).
#[test]
fn bounding_rectangles_by_the_receivers_keeps_every_pixel() {
    let gpu = gpu();
    let cases: [(&str, &[(&str, &str)]); 6] = [
        ("floating-sphere", &[]),
        ("floating-sphere", &[("two_sided", "true")]),
        ("contact", &[]),
        ("leaves", &[("occluder_map_size", "200")]),
        ("sphere-cube", &[("two_sided", "true"), ("self_shadow_tolerance", "2")]),
        ("parallel-square", &[("ssm_size", "300"), ("occluder_map_size", "127")]),
    ];
    for (scene_name, settings) in cases {
        let scene = builtin(scene_name).unwrap().build();
        let with = |bound: &'static str| {
            let mut all = settings.to_vec();
            all.push(("penumbra_bound", bound));
            render(&gpu, &scene, &ssm_atty::INFO, &all, SIZE.0, SIZE.1).unwrap().visibility
        };
        let (receivers, far) = (with("receivers"), with("far_plane"));
        let largest = receivers.iter().zip(&far).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        let shadowed = far.iter().filter(|v| **v < 0.999).count();
        let n = settings.iter().find(|(name, _)| *name == "occluder_map_size").map_or(256.0, |(_, v)| v.parse().unwrap());
        let terms = patches_per_point(&scene, n);
        let bound = 2.0 * gamma(terms - 1.0) * (1.0 + 2.0 * gamma(terms - 1.0)) + 4.0 * UNIT_ROUNDOFF;
        println!(
            "{scene_name} {settings:?}: largest difference {largest:e} (bound {bound:.2e}, {terms:.0} patches a point sees at most), {shadowed} pixels in shadow or penumbra"
        );
        assert!(shadowed > 0, "{scene_name}: the case has shadow");
        assert!(f64::from(largest) <= bound, "{scene_name} {settings:?}: bounded and unbounded differ by {largest}, above {bound}");
    }
}

/// An occluder square like parallel-square's, at depths z_P ∈ [z_min, z_max] below a light of
/// half extent `light_half` over a receiver plane at depth `receiver_depth`, seen through an `n`²
/// occluder map of half-angle tangent `tan`: what the bounds of [`merging_equal_depth_texels_keeps_the_pixels`] read.
#[derive(Clone, Copy, Debug)]
struct SquareCase {
    n: f64,
    tan: f64,
    light_half: f64,
    depths: (f64, f64),
    receiver_depth: f64,
}

impl SquareCase {
    /// Back-projected width of one patch at depth z, over the light's width: (2·z·tan/N)·z_R/(z_R − z)/(2l).
    fn patch_share(&self, z: f64) -> f64 {
        2.0 * z * self.tan / self.n * self.receiver_depth / (self.receiver_depth - z) / (2.0 * self.light_half)
    }

    /// Patches per axis whose back-projection from one receiver point meets the light, at depth z:
    /// its pyramid to the light is l·(z_R − z)/z_R wide on each side, in ndc that over z·tan, one
    /// patch per 2/N, plus the two its edges cut.
    fn patches_per_axis(&self, z: f64) -> f64 {
        self.n * self.light_half * (self.receiver_depth - z) / (z * self.receiver_depth * self.tan) + 2.0
    }

    /// The f32 rounding of one point's sum of hidden fractions (`hidden_fraction` in
    /// atty_geometry.wgsl, its inputs as atty_accumulation.wgsl forms them). Every lateral value is
    /// at most L = z_R·tan in magnitude; the receiver and the patch centre carry up to 5 roundings
    /// each (ndc from the texel, times depth, times tan), the scale s = z_R/(z_R − z_P) two, and
    /// the edge `low = R + (c − h − R)·s` four more, those before the scaling magnified by s. For
    /// an edge inside the light (|low| ≤ l, |c − h − R| ≤ (L + l)/s) that is
    /// |δlow| ≤ u·(5L + 12L·s + 3(L + l) + l), and on the normalised edge A = (low + l)/(2l),
    /// δA ≤ (|δlow| + 2ul)/(2l) + u. A hidden fraction o_u·o_v (each o a difference of two
    /// clamped edges) is then off by 2δA·(o_u + o_v) + 4δA²; the patches at one depth tile the
    /// light, so the o_v of those meeting it sum to at most (patches per axis)·1 and the same for
    /// o_u. The f32 sum of M terms adds γ_{M−1}·S, S ≤ 1 + (its own error) (Higham, Eq. 4.4).
    fn rounding(&self) -> f64 {
        let u = UNIT_ROUNDOFF;
        let z = self.depths.1;
        let big_l = self.receiver_depth * self.tan;
        let (l, s) = (self.light_half, self.receiver_depth / (self.receiver_depth - z));
        let edge = u * (5.0 * big_l + 12.0 * big_l * s + 3.0 * (big_l + l) + l);
        let delta = (edge + 2.0 * u * l) / (2.0 * l) + u;
        let per_axis = self.patches_per_axis(self.depths.0);
        let terms = per_axis * per_axis;
        let terms_error = 2.0 * delta * 2.0 * per_axis + 4.0 * delta * delta * terms;
        terms_error + gamma(terms - 1.0) * (1.0 + terms_error)
    }

    /// Sec. 5.1.2, Eq. 1, for merging: a block whose depths differ by at most τ patch widths is
    /// drawn as one patch at the middle of its range, so each texel's patch moves by
    /// δ ≤ τ·(2·z·tan/N)/2 in depth, while at a common depth the block's patches join exactly (its
    /// hidden fraction is the sum of theirs there). Moving a patch of fixed image area from z by δ
    /// moves each back-projected edge that lies on the light (|a − a_R| ≤ l(z_R − z)/(z·z_R) for
    /// its ray a) by at most δ·l·z_R/(z(z_R − z)), which is e ≤ τ·tan·z_R/(N(z_R − z)) of the
    /// light's width; its hidden fraction changes by at most 2e(o_u + o_v) + 4e² ≤ 4e·b(1 + e/b).
    /// The patches that meet the light lie in the point's pyramid, at most patches_per_axis² of
    /// them at the nearest depth, each with e·b largest at the deepest: the bound is their product.
    fn merge_error(&self, tolerance: f64) -> f64 {
        let (near, far) = self.depths;
        let e = tolerance * self.tan * self.receiver_depth / (self.n * (self.receiver_depth - far));
        let b = self.patch_share(far);
        let count = self.patches_per_axis(near).powi(2);
        count * 4.0 * e * b * (1.0 + e / self.patch_share(near))
    }
}

/// Sec. 5.1.2: micro-patches at one depth hide parts of the light that join exactly, so drawing
/// an aligned block of equal-depth texels as one patch changes nothing but the rounding: on
/// parallel-square (a flat occluder parallel to the light) merged and unmerged patches differ by
/// at most the f32 rounding of both sums ([`SquareCase::rounding`]). Tilted by 0.002 (a depth
/// change of 0.002 patch widths per texel), blocks of up to 4 × 4 texels merge at the default
/// tolerance of 0.01 widths although their depths differ, which changes each pixel by at most
/// Eq. 1's bound for a depth error of half the tolerance ([`SquareCase::merge_error`]).
/// (floating-sphere merges nothing: a sphere's depths change by more than 0.01 widths from one
/// texel to the next everywhere at 256².)
#[test]
fn merging_equal_depth_texels_keeps_the_pixels() {
    let gpu = gpu();
    let tan = f64::from(parallel_square_tan_half());
    let tilt = 0.002f32;
    let mut tilted = builtin("parallel-square").unwrap().build();
    let occluder = tilted.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.transform = Mat4::from_rotation_translation(Quat::from_rotation_x(tilt.atan()), Vec3::new(0.0, 2.0, 0.0));
    let half_depth_range = 0.5 * f64::from(tilt);
    let flat = SquareCase { n: 256.0, tan, light_half: 0.5, depths: (2.0, 2.0), receiver_depth: 4.0 };
    let sloped = SquareCase { depths: (2.0 - half_depth_range, 2.0 + half_depth_range), ..flat };
    let cases = [
        ("parallel-square", builtin("parallel-square").unwrap().build(), 2.0 * flat.rounding()),
        ("parallel-square tilted by 0.002", tilted, sloped.merge_error(0.01) + 2.0 * sloped.rounding()),
    ];
    for (name, scene, bound) in cases {
        let with = |merge: &'static str| {
            render(&gpu, &scene, &ssm_atty::INFO, &[("merge_tolerance", merge), ("occluder_map_size", "256")], SIZE.0, SIZE.1)
                .unwrap()
                .visibility
        };
        let (merged, unmerged) = (with("0.01"), with("0"));
        let largest = merged.iter().zip(&unmerged).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        let shadowed = unmerged.iter().filter(|v| **v < 0.999).count();
        println!("{name}: merged and unmerged patches differ by at most {largest:e} (bound {bound:.2e})");
        assert!(shadowed > 100, "{name}: the case has shadow");
        assert!(f64::from(largest) <= bound, "{name}: {largest} above {bound}");
    }
}

/// The acceptance bound of the project's issue #39 on interior and contact scenes: every technique
/// within this mean absolute error of the ground truth, over the pixels a surface covers (the
/// extremes matrix's common bound, tests/extremes.rs).
const INTERIOR_BOUND: f32 = 0.1;

/// Rays per axis of the ground truth here, as in the extremes matrix: its mean error over a
/// penumbra is below N^-1.5 = 0.044 (tests/reference.rs), its per-pixel error 4/N where one edge
/// crosses the light.
const TRUTH_SAMPLES: u32 = 8;

/// A closed box room of `size` (role both) with `furniture`, its light and camera inside.
fn room(
    size: [f32; 3],
    (centre, normal, light): ([f32; 3], [f32; 3], [f32; 2]),
    (eye, target): ([f32; 3], [f32; 3]),
    furniture: &str,
) -> Scene {
    scene_from_manifest(&format!(
        "[camera]\nposition = {eye:?}\ntarget = {target:?}\n[[light]]\ncentre = {centre:?}\nnormal = {normal:?}\nsize = {light:?}\n\
         [[object]]\nprimitive = \"box\"\nsize = {size:?}\ntranslate = [0.0, {}, 0.0]\nrole = \"both\"\n{furniture}",
        size[1] * 0.5
    ))
}

/// A box of role both, as manifest text.
fn both_box(size: [f32; 3], at: [f32; 3]) -> String {
    format!("[[object]]\nprimitive = \"box\"\nsize = {size:?}\ntranslate = {at:?}\nrole = \"both\"\n")
}

/// Mean |visibility − truth| of `atty` with `settings` on `scene`, over the covered pixels.
fn mean_error(scene: &Scene, truth: &[f32], settings: &[(&str, &str)]) -> f32 {
    let rendered = render(&gpu(), scene, &ssm_atty::INFO, settings, SIZE.0, SIZE.1).unwrap();
    mean_abs_difference(&rendered.visibility, truth, &rendered.coverage())
}

/// Interiors (every surface role both, the light and the camera inside a closed room): a flat wall
/// in both maps became micro-patches at its texels' centre depths, drawn parallel to the light,
/// and those of its texels next to a point of it hid that point: at grazing angles to the light a
/// texel's depth spans many patch widths, so half of every texel sat behind its own patch, a moiré
/// over the walls (mean error 0.21 to 0.39 here). The receiver-plane test (`receiver_plane`, the
/// default) counts a patch on or behind a receiver's tangent plane as hiding nothing: the rooms
/// come within the project's bound, and without it they do not. Three rooms: the extremes
/// matrix's, a smaller one under a tilted light with a sphere, and one lit from beside a wall.
#[test]
fn a_room_lit_from_inside_does_not_shadow_itself() {
    let gpu = gpu();
    let sphere = "[[object]]\nprimitive = \"sphere\"\nsize = [0.3]\ntranslate = [0.8, 0.3, 0.5]\nrole = \"both\"\n";
    let rooms = [
        (
            "the matrix's room",
            room(
                [8.0, 3.0, 8.0],
                ([0.3, 2.7, -0.2], [0.0, -1.0, 0.0], [0.8, 0.6]),
                ([-2.5, 1.6, 2.5], [0.5, 0.3, -0.5]),
                &both_box([1.0, 0.8, 1.0], [0.5, 0.4, -0.5]),
            ),
        ),
        (
            "a small room under a tilted light",
            room(
                [4.0, 2.5, 5.0],
                ([1.0, 2.3, 0.5], [-0.3, -1.0, 0.2], [0.5, 0.5]),
                ([-1.5, 1.2, 2.0], [0.5, 0.5, -1.0]),
                &(both_box([0.8, 0.6, 0.8], [-0.5, 0.3, -1.0]) + sphere),
            ),
        ),
        (
            "a room lit from beside a wall",
            room(
                [6.0, 3.0, 6.0],
                ([-2.8, 1.8, 0.0], [1.0, -0.3, 0.0], [0.6, 0.9]),
                ([2.5, 1.5, 2.5], [-1.0, 1.0, -1.0]),
                &(both_box([0.6, 1.2, 0.6], [0.0, 0.6, 0.0]) + &both_box([1.5, 0.1, 1.0], [1.5, 0.9, -1.5])),
            ),
        ),
    ];
    for (name, mut scene) in rooms {
        let truth = reference(&gpu, &scene, TRUTH_SAMPLES, SIZE).visibility;
        let (with, without) = (mean_error(&scene, &truth, &[]), mean_error(&scene, &truth, &[("receiver_plane", "false")]));
        // The paper's split for comparison: the room's walls receivers only, in no occluder map.
        scene.instances[0].role = Role::Receiver;
        let split = mean_error(&scene, &truth, &[("receiver_plane", "false")]);
        println!(
            "{name}: mean |error| {with:.4} with the receiver-plane test, {without:.4} without, {split:.4} without but with the walls receivers only"
        );
        assert!(with <= INTERIOR_BOUND, "{name}: {with}");
        assert!(without > INTERIOR_BOUND, "{name}: the case must show the moiré without the test ({without})");
    }
}

/// An occluder quad lying in the receiver's plane (under a tilted light, so that the floor's depth
/// changes across a texel) hides nothing in the ground truth: its rays leave the floor upwards.
/// Its micro-patches, at their texels' centre depths, hid the floor's points behind them in each
/// texel (a moiré over the quad); on the floor's tangent plane, they hide nothing with the
/// receiver-plane test. The quad's pixels must read the truth (lit, but where the block's shadow
/// falls) to within the ground truth's own per-pixel error, 4/N where one edge crosses the light.
#[test]
fn an_occluder_in_the_receivers_plane_hides_nothing() {
    let gpu = gpu();
    let scene = scene_from_manifest(
        "[camera]\nposition = [0.0, 4.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[light]]\ncentre = [0.5, 3.0, 0.0]\nnormal = [-0.2, -1.0, 0.0]\nsize = [1.0, 1.0]\n\
         [[object]]\nprimitive = \"plane\"\nsize = [8.0, 8.0]\nrole = \"receiver\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [2.0, 2.0]\nrole = \"occluder\"\n\
         [[object]]\nprimitive = \"box\"\nsize = [0.5, 0.5, 0.5]\ntranslate = [-1.5, 1.0, 1.0]\nrole = \"both\"\n",
    );
    let truth = reference(&gpu, &scene, TRUTH_SAMPLES, SIZE).visibility;
    let quad_error = |settings: &[(&str, &str)]| {
        let rendered = render(&gpu, &scene, &ssm_atty::INFO, settings, SIZE.0, SIZE.1).unwrap();
        let on_quad: Vec<bool> = rendered
            .renderer
            .read_positions()
            .unwrap()
            .iter()
            .map(|p| p[3] > 0.5 && p[1].abs() < 1e-3 && p[0].abs() < 0.95 && p[2].abs() < 0.95)
            .collect();
        assert!(on_quad.iter().filter(|q| **q).count() > 200, "the camera sees the quad");
        let worst = rendered
            .visibility
            .iter()
            .zip(&truth)
            .zip(&on_quad)
            .filter(|(_, q)| **q)
            .map(|((v, t), _)| (v - t).abs())
            .fold(0.0f32, f32::max);
        (mean_abs_difference(&rendered.visibility, &truth, &on_quad), worst)
    };
    let ((with, worst), (without, _)) = (quad_error(&[]), quad_error(&[("receiver_plane", "false")]));
    let truth_error = 4.0 / TRUTH_SAMPLES as f32;
    println!(
        "coplanar quad: mean |error| over its pixels {with:.4} (largest {worst:.4}) with the receiver-plane test, {without:.4} without"
    );
    assert!(worst <= truth_error, "{worst}");
    assert!(without > 0.1, "the case must show the moiré without the test ({without})");
}

/// The receiver-plane test must not cost the shadows of real occluders close to a receiver: a
/// block resting on a floor (both role both) hides the whole light from the floor right beside its
/// shadowed side (every segment from there to the light passes through the block, see below), and
/// a plate hovering 0.05 above the floor keeps its umbra on the floor where the camera sees past
/// its edge. And on `contact` (the extremes matrix's "occluder touching the
/// receiver") the error stays within the project's bound.
#[test]
fn occluders_touching_the_receiver_keep_their_shadows() {
    let gpu = gpu();
    // Light over x = −1.5: from (0.52, 0, 0), 0.02 past the block's far face, the light's points
    // (x ≤ −1, y = 4) are seen over the block's top edge (x = 0.5, y = 1) only at heights of at
    // most 4 · 0.02/1.52 < 0.06 when crossing x = 0.5: below the top, through the block.
    let block = scene_from_manifest(
        "[camera]\nposition = [3.0, 2.5, 3.0]\ntarget = [0.5, 0.0, 0.0]\n\
         [[light]]\ncentre = [-1.5, 4.0, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [1.0, 1.0]\n\
         [[object]]\nprimitive = \"plane\"\nsize = [8.0, 8.0]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"box\"\nsize = [1.0, 1.0, 1.0]\ntranslate = [0.0, 0.5, 0.0]\nrole = \"both\"\n",
    );
    let beside = pixel_of(&block, SIZE.0, SIZE.1, Vec3::new(0.52, 0.0, 0.0));
    let rendered = render(&gpu, &block, &ssm_atty::INFO, &[], SIZE.0, SIZE.1).unwrap();
    let truth = reference(&gpu, &block, TRUTH_SAMPLES, SIZE);
    println!("block on the floor: visibility beside it {:.4} (truth {:.4})", at(&rendered, beside), at(&truth, beside));
    assert!(at(&truth, beside) == 0.0, "the ground truth has umbra there");
    assert!(at(&rendered, beside) <= 4.0 / TRUTH_SAMPLES as f32, "{}", at(&rendered, beside));
    // A square occluder a hundredth and more above a floor parallel to the light (where the paper's
    // receiver map needs no plane test), from a third of a patch width up, under a large light
    // off to its side: its shadow shows past its edge. With no normal offset both projections
    // read the same texels, so the receiver-plane test must leave the accumulated terms as they
    // are, up to their order (bound as in bounding_rectangles_by_the_receivers_keeps_every_pixel).
    for height in [0.01f32, 0.05, 0.1] {
        let scene = scene_from_manifest(&format!(
            "[camera]\nposition = [1.6, 1.2, 1.6]\ntarget = [0.4, 0.0, 0.4]\n\
             [[light]]\ncentre = [-1.5, 3.0, -1.5]\nnormal = [0.0, -1.0, 0.0]\nsize = [3.0, 3.0]\n\
             [[object]]\nprimitive = \"plane\"\nsize = [4.0, 4.0]\nrole = \"receiver\"\n\
             [[object]]\nprimitive = \"plane\"\nsize = [1.0, 1.0]\ntranslate = [0.0, {height}, 0.0]\nrole = \"occluder\"\n"
        ));
        let with = |plane: &'static str| {
            render(&gpu, &scene, &ssm_atty::INFO, &[("normal_offset", "0"), ("receiver_plane", plane)], SIZE.0, SIZE.1).unwrap().visibility
        };
        let (on, off) = (with("true"), with("false"));
        let largest = on.iter().zip(&off).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        let terms = patches_per_point(&scene, 256.0);
        let bound = 2.0 * gamma(terms - 1.0) * (1.0 + 2.0 * gamma(terms - 1.0)) + 4.0 * UNIT_ROUNDOFF;
        let shadowed = off.iter().filter(|v| **v < 0.999).count();
        let light = &scene.lights[0];
        let width = 2.0 * (3.0 - height) * LightFrame::fit(light, &scene.bounds()).tan_half.min_element() / 256.0;
        println!(
            "square {height} above the floor ({:.2} patch widths): the receiver-plane test changes pixels by at most {largest:e} (bound {bound:.2e}); {shadowed} pixels in shadow",
            height / width
        );
        assert!(shadowed > 100, "the square casts a shadow");
        assert!(f64::from(largest) <= bound, "{height}: {largest}");
    }
    let contact = builtin("contact").unwrap().build();
    let truth = reference(&gpu, &contact, TRUTH_SAMPLES, SIZE).visibility;
    let error = mean_error(&contact, &truth, &[]);
    println!("contact: mean |error| {error:.4}");
    assert!(error <= INTERIOR_BOUND, "{error}");
}

/// A wall standing on the ground beside a light lower than its top: the light sees the wall edge
/// on (the wall is nearly parallel to its rays), and no light reaches the ground behind it, whose
/// every point is exactly dark in the truth (as the ground outside a box around a light, the
/// extremes matrix's "light sealed inside a box"). A ground point just behind the wall lies at
/// nearly the wall's depth along the light's ray, so a depth tolerance reads it as the wall and
/// gives it the wall's light; behind the wall's plane along its own ray (`receiver_plane`), it is
/// hidden. Every pixel of the ground behind the wall must read at most the truth's per-pixel
/// error, 4/N (here 0: none of its rays reach the light).
#[test]
fn no_light_passes_a_wall_seen_edge_on() {
    let gpu = gpu();
    let scene = scene_from_manifest(
        "[camera]\nposition = [4.0, 3.0, 1.0]\ntarget = [1.0, 0.0, 0.0]\n\
         [[light]]\ncentre = [0.0, 0.8, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.5, 0.5]\n\
         [[object]]\nprimitive = \"box\"\nsize = [0.1, 2.0, 6.0]\ntranslate = [1.05, 1.0, 0.0]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [10.0, 10.0]\nrole = \"receiver\"\n",
    );
    let brightest = |settings: &[(&str, &str)]| {
        let rendered = render(&gpu, &scene, &ssm_atty::INFO, settings, SIZE.0, SIZE.1).unwrap();
        let behind: Vec<bool> =
            rendered.renderer.read_positions().unwrap().iter().map(|p| p[3] > 0.5 && p[1].abs() < 1e-3 && p[0] > 1.1).collect();
        assert!(behind.iter().filter(|b| **b).count() > 1000, "the camera sees the ground behind the wall");
        rendered.visibility.iter().zip(&behind).filter(|(_, b)| **b).map(|(v, _)| *v).fold(0.0f32, f32::max)
    };
    let (with, without) = (brightest(&[]), brightest(&[("receiver_plane", "false")]));
    println!("wall seen edge on: brightest ground pixel behind it {with:.4} with the receiver-plane test, {without:.4} without");
    assert!(with <= 4.0 / TRUTH_SAMPLES as f32, "light passes the wall: {with}");
}
