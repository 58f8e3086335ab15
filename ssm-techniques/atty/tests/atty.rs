//! Atty et al. 2006 (`atty`) against the exact answer and against its own
//! paper's claims: the discretisation bound of Sec. 5.1.1, Appendix A's FP16
//! failure, the two-sided variant of Sec. 3.5, and a point light.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::Vec2;
use ssm_core::LightFrame;
use ssm_core::metrics::compare;
use ssm_scene::{Scene, builtin};
use ssm_testing::{gpu, render, scene_from_manifest};

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
    let tan = parallel_square_tan_half();
    let ssm = 512.0;
    let mut errors = Vec::new();
    for n in [33u32, 63, 127, 255] {
        let (error, worst) = parallel_square_errors(&[("occluder_map_size", &n.to_string()), ("ssm_size", "512")]);
        let epsilon = 4.0 * tan / n as f32;
        let bound = f64::from(2.0 * epsilon + epsilon * epsilon + 2.0 * 4.0 * tan / ssm);
        println!("occluder map {n}²: penumbra MAE {error:.4}, largest error {worst:.4} (bound on it {bound:.4})");
        assert!(worst <= bound, "N = {n}: the largest error {worst} is above the discretisation bound {bound}");
        errors.push(error);
    }
    for pair in errors.windows(2) {
        assert!(pair[1] < pair[0], "the error falls as the occluder map grows: {errors:?}");
    }
    assert!(errors[3] < errors[0] / 5.0, "{errors:?}");
}

/// Appendix A, Eq. 4: FP16 has a 10-bit mantissa, so patches hiding less than 2⁻¹⁰ of the light
/// are lost once the sum nears 1. On parallel-square a patch hides (2·z_O·tan/N · 2)² of the unit
/// light: above 2⁻¹⁰ at N = 128, far below at N = 1024. FP32 (23 bits) is safe at both.
#[test]
fn fp16_accumulation_fails_at_high_resolution_and_fp32_does_not() {
    let tan = parallel_square_tan_half();
    let hidden_by_one_patch = |n: f32| (2.0 * 2.0 * tan / n * 2.0).powi(2);
    assert!(
        hidden_by_one_patch(128.0) > 2f32.powi(-10) && hidden_by_one_patch(1024.0) < 2f32.powi(-10),
        "the paper's condition separates the two sizes"
    );
    // One micro-patch per texel, as the paper (no merging).
    let error = |n: &str, accumulation: &str| {
        parallel_square_error(&[("occluder_map_size", n), ("accumulation", accumulation), ("ssm_size", "128"), ("merge_tolerance", "0")])
    };
    let (f16_low, f16_high) = (error("128", "f16"), error("1024", "f16"));
    let (f32_low, f32_high) = (error("128", "f32"), error("1024", "f32"));
    println!("penumbra MAE: f16 at 128² {f16_low:.4}, at 1024² {f16_high:.4}; f32 at 128² {f32_low:.4}, at 1024² {f32_high:.4}");
    assert!(f16_high > 10.0 * f16_low, "FP16 at 1024² ({f16_high}) must be far worse than at 128² ({f16_low})");
    assert!(f16_high > 0.1, "{f16_high}");
    assert!(f32_low < 0.03 && f32_high < 0.03, "FP32 stays accurate: {f32_low}, {f32_high}");
    // Merging the square's equal-depth texels into blocks (the default) draws a few large patches
    // instead of 1024² tiny ones: each hides far more than 2⁻¹⁰ of the light, so FP16 recovers.
    let merged = parallel_square_error(&[("occluder_map_size", "1024"), ("accumulation", "f16"), ("ssm_size", "128")]);
    println!("f16 at 1024² with merged patches: {merged:.4}");
    assert!(merged < 0.03, "merged patches keep FP16 accurate: {merged}");
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

/// `receiver_tolerance` decides which receiver-map depths count as the receiver looked up. On a
/// platform standing on the ground, the platform's side faces lie below its top edge as the
/// light sees them: within a few texel footprints they are the top's receiver, past it they are
/// hidden (in umbra, as the ground truth has them, facing away from the light). A tolerance so
/// large that no receiver is ever hidden lights them and reads the top's occlusion across the
/// depth edge.
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
    let (default, unbounded) = (
        error_against_reference(&scene, &[("ssm_size", "128")]),
        error_against_reference(&scene, &[("ssm_size", "128"), ("receiver_tolerance", "64")]),
    );
    println!("platform: penumbra MAE with receiver_tolerance 2 (default) {default:.4}, 64 {unbounded:.4}");
    assert!(default < 0.5 * unbounded, "{default} vs {unbounded}");
}

/// Bounding each micro-patch's penumbra rectangle by the deepest receiver under it (a max-pyramid
/// of the receiver map) instead of the far plane drops only SSM texels the patch hides nothing
/// at: the same visibility, one- and two-sided, on a floating occluder, an occluder touching its
/// receiver, foliage, a receiver with objects of role `both`, and an SSM whose side is not a
/// power of two (the pyramid's odd levels).
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
        println!("{scene_name} {settings:?}: largest difference {largest:e}, {shadowed} pixels in shadow or penumbra");
        assert!(shadowed > 0, "{scene_name}: the case has shadow");
        assert!(largest <= 1e-4, "{scene_name} {settings:?}: bounded and unbounded differ by {largest}");
    }
}

/// Sec. 5.1.2: micro-patches at one depth hide parts of the light that join exactly, so drawing
/// an aligned block of equal-depth texels as one patch changes nothing: on parallel-square (a
/// flat occluder parallel to the light) merged and unmerged patches give the same pixels, and on
/// floating-sphere (depths that change from texel to texel) the default tolerance of 0.01 patch
/// widths changes them by no more than 0.01.
#[test]
fn merging_equal_depth_texels_keeps_the_pixels() {
    let gpu = gpu();
    for (scene_name, bound) in [("parallel-square", 1e-4f32), ("floating-sphere", 0.01)] {
        let scene = builtin(scene_name).unwrap().build();
        let with = |merge: &'static str| {
            render(&gpu, &scene, &ssm_atty::INFO, &[("merge_tolerance", merge), ("occluder_map_size", "256")], SIZE.0, SIZE.1)
                .unwrap()
                .visibility
        };
        let (merged, unmerged) = (with("0.01"), with("0"));
        let largest = merged.iter().zip(&unmerged).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        println!("{scene_name}: merged and unmerged patches differ by at most {largest:e}");
        assert!(largest <= bound, "{scene_name}: {largest}");
    }
}
