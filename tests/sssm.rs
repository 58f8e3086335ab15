//! Buades et al. 2015 (`sssm`): reuse against its thresholds, and the exact cases.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::Vec3;
use ssm_core::metrics::compare;
use ssm_integration_tests::{Rendered, gpu, render};
use ssm_scene::{Camera, Scene, builtin};

const SIZE: (u32, u32) = (160, 120);

fn reuse_share(scene: &Scene, settings: &[(&str, &str)]) -> (Rendered, f64) {
    let gpu = gpu();
    let rendered = render(&gpu, scene, "sssm", settings, SIZE.0, SIZE.1).unwrap();
    // The registry's technique, rendered again to read its diagnostics.
    let info = ssm_core::Registry::global().unwrap().get("sssm").unwrap();
    let params = info.params_from(settings.iter().copied()).unwrap();
    let mut renderer = rendered.renderer;
    let mut technique = renderer.create_technique(info, &params).unwrap();
    renderer.render(technique.as_mut(), "sssm").unwrap();
    let diagnostics = technique.diagnostics(&renderer.gpu);
    let share = diagnostics.iter().find(|(k, _)| k == "sssm_reuse_share").map(|(_, v)| *v).unwrap();
    let visibility = renderer.read_visibility(0, "sssm").unwrap();
    (Rendered { renderer, visibility }, share)
}

/// `parallel-square` seen from straight above, screen axes along the light's: a receiver parallel to
/// the light and to the image plane, where screen-space and shadow-map filters sample the same points.
fn top_down_parallel_square() -> Scene {
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.camera = Camera {
        position: Vec3::new(0.0, 6.0, 0.0),
        target: Vec3::ZERO,
        up: Vec3::new(0.0, 0.0, -1.0),
        fov_y: 40f32.to_radians(),
        near: 0.1,
        far: 20.0,
    };
    scene
}

#[test]
fn zero_thresholds_reuse_nothing_and_larger_ones_reuse_more() {
    let scene = builtin("leaves").unwrap().build();
    let mut shares = Vec::new();
    for threshold in ["0", "0.002", "0.01", "0.05"] {
        let (_, share) = reuse_share(&scene, &[("alpha", threshold), ("beta", threshold)]);
        println!("alpha = beta = {threshold}: reuse share {share:.4}");
        shares.push(share);
    }
    assert_eq!(shares[0], 0.0, "with α = β = 0 nothing is reused");
    for pair in shares.windows(2) {
        assert!(pair[1] > pair[0], "reuse grows with the thresholds: {shares:?}");
    }
}

#[test]
fn error_grows_with_the_thresholds() {
    // The direction of the paper's Tables 5 and 6.
    let scene = builtin("leaves").unwrap().build();
    let gpu = gpu();
    let reference = render(&gpu, &scene, "reference", &[("samples", "12"), ("cache", "false")], SIZE.0, SIZE.1).unwrap();
    let covered: Vec<bool> = reference.renderer.read_positions().unwrap().iter().map(|p| p[3] > 0.5).collect();
    let error = |threshold: &str| {
        let rendered = render(&gpu, &scene, "sssm", &[("alpha", threshold), ("beta", threshold)], SIZE.0, SIZE.1).unwrap();
        compare(&reference.visibility, &rendered.visibility, &covered, SIZE.0 as usize, SIZE.1 as usize).rmse
    };
    let (none, large) = (error("0"), error("0.1"));
    println!("leaves RMSE: alpha = beta = 0: {none:.4}, 0.1: {large:.4}");
    assert!(large > none, "reusing across depth gaps adds error: {none} vs {large}");
}

/// With α = β = 0 every row is read directly, so SSSM with the mean filter is PCSS's n×n blocker
/// search and m×m filter evaluated at the same points: on a receiver parallel to the light and to
/// the image plane the two agree up to the quantisation of screen taps to pixels (tolerance 0.01
/// mean, stated below). With reuse on, a parallel receiver keeps every light depth equal, so the
/// blocker rows are reused exactly; the blur rows carry each neighbour's own kernel width, which
/// varies across the penumbra, hence a looser bound.
#[test]
fn on_a_parallel_receiver_sssm_with_the_mean_filter_equals_pcss() {
    let scene = top_down_parallel_square();
    let gpu = gpu();
    let pcss = render(&gpu, &scene, "pcss", &[("blocker_kernel", "7"), ("pcf_kernel", "15")], SIZE.0, SIZE.1).unwrap();
    let receives: Vec<bool> = pcss.renderer.read_normals().unwrap().iter().map(|n| n[3] > 0.5).collect();
    let difference = |settings: &[(&str, &str)]| {
        let sssm = render(&gpu, &scene, "sssm", settings, SIZE.0, SIZE.1).unwrap();
        let diffs: Vec<f32> =
            sssm.visibility.iter().zip(&pcss.visibility).zip(&receives).filter(|(_, r)| **r).map(|((a, b), _)| (a - b).abs()).collect();
        diffs.iter().sum::<f32>() / diffs.len() as f32
    };
    let exact = difference(&[("filter", "mean"), ("blocker_kernel", "7"), ("blur_kernel", "15"), ("alpha", "0"), ("beta", "0")]);
    let reusing = difference(&[("filter", "mean"), ("blocker_kernel", "7"), ("blur_kernel", "15"), ("alpha", "0.01"), ("beta", "0.01")]);
    println!("mean |sssm - pcss| on the receiver: no reuse {exact:.5}, with reuse {reusing:.5}");
    assert!(exact < 0.01, "{exact}");
    assert!(reusing < 0.03, "{reusing}");
}

#[test]
fn kernels_wider_than_the_screen_and_zero_penumbrae_stay_in_range() {
    let gpu = gpu();
    // A light 20 times the occluder on a 32×24 image: blocker windows and blurs far wider than the screen.
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.lights[0].half_size *= 20.0;
    let wide =
        render(&gpu, &scene, "sssm", &[("blocker_kernel", "64"), ("blur_kernel", "128"), ("alpha", "0.05"), ("beta", "0.05")], 32, 24)
            .unwrap();
    assert!(wide.visibility.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)));
    // A point light: zero penumbra everywhere, so the hard value is kept.
    scene.lights[0].half_size *= 0.0;
    let hard = render(&gpu, &scene, "sssm", &[], 64, 48).unwrap();
    let covered = hard.covered_visibility();
    assert!(covered.iter().all(|v| *v == 0.0 || *v == 1.0), "a zero penumbra keeps the hard shadow");
    assert!(covered.contains(&0.0) && covered.contains(&1.0));
}
