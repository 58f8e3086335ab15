//! The baselines on every built-in scene, on the software adapter, with
//! numerical assertions on the analytic `parallel-square`.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::Vec3;
use ssm_integration_tests::{at, gpu, parallel_square_exact, pixel_of, render};
use ssm_scene::{BUILTIN_SCENES, builtin};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

#[test]
fn parallel_square_umbra_and_lit_region() {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let umbra_centre = pixel_of(&scene, WIDTH, HEIGHT, Vec3::ZERO);
    let outside_penumbra = pixel_of(&scene, WIDTH, HEIGHT, Vec3::new(2.5, 0.0, 0.0));
    assert_eq!(parallel_square_exact(0.0, 0.0), 0.0);
    assert_eq!(parallel_square_exact(2.5, 0.0), 1.0);
    for technique in ["hard", "pcss"] {
        let rendered = render(&gpu, &scene, technique, &[], WIDTH, HEIGHT).unwrap();
        let umbra = at(&rendered, umbra_centre);
        let lit = at(&rendered, outside_penumbra);
        assert!(umbra < 0.05, "{technique}: umbra centre reads {umbra}");
        assert!(lit > 0.95, "{technique}: lit receiver reads {lit}");
    }
}

#[test]
fn pcss_follows_the_analytic_penumbra_and_hard_does_not() {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let hard = render(&gpu, &scene, "hard", &[], WIDTH, HEIGHT).unwrap();
    let pcss = render(&gpu, &scene, "pcss", &[("pcf_kernel", "24"), ("blocker_kernel", "12")], WIDTH, HEIGHT).unwrap();
    // Along the x axis through the penumbra: the exact visibility rises from 0 at x = 0.5 to 1 at x = 1.5.
    let (mut hard_error, mut pcss_error, mut samples) = (0.0, 0.0, 0);
    for step in 0..=20 {
        let x = 0.5 + step as f32 * 0.05;
        let pixel = pixel_of(&scene, WIDTH, HEIGHT, Vec3::new(x, 0.0, 0.0));
        let exact = parallel_square_exact(x, 0.0);
        hard_error += (at(&hard, pixel) - exact).abs();
        pcss_error += (at(&pcss, pixel) - exact).abs();
        samples += 1;
    }
    let (hard_error, pcss_error) = (hard_error / samples as f32, pcss_error / samples as f32);
    // Hard shadows are off by 0.25 on average across a linear ramp; PCSS on parallel planes is close to exact,
    // up to the pixel footprint (about 0.05 world units here) and the regular-grid quantisation.
    assert!(pcss_error < 0.08, "pcss penumbra error {pcss_error}");
    assert!(pcss_error < hard_error * 0.5, "pcss {pcss_error} vs hard {hard_error}");
    // Half-way through the penumbra, half the light is visible.
    let middle = at(&pcss, pixel_of(&scene, WIDTH, HEIGHT, Vec3::new(1.0, 0.0, 0.0)));
    assert!((middle - 0.5).abs() < 0.1, "pcss at the middle of the penumbra reads {middle}");
}

#[test]
fn every_builtin_scene_renders_with_both_baselines() {
    let gpu = gpu();
    for entry in BUILTIN_SCENES {
        let scene = entry.build();
        for technique in ["hard", "pcss"] {
            let rendered =
                render(&gpu, &scene, technique, &[], WIDTH, HEIGHT).unwrap_or_else(|e| panic!("{} / {technique}: {e}", entry.name));
            let shadowed = rendered.visibility.iter().filter(|v| **v < 0.5).count();
            let lit = rendered.visibility.iter().filter(|v| **v > 0.5).count();
            // Every built-in scene casts a visible shadow onto a lit receiver.
            assert!(shadowed > 50, "{} / {technique}: only {shadowed} shadowed pixels", entry.name);
            assert!(lit > shadowed, "{} / {technique}: {lit} lit vs {shadowed} shadowed", entry.name);
        }
    }
}

#[test]
fn pcss_receiver_plane_test_removes_self_shadowing_at_grazing_light() {
    // A light 12 units to the side, 0.25 above a bare receiver: nothing occludes it.
    let gpu = gpu();
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.instances.retain(|i| i.name == "ground");
    scene.lights[0] =
        ssm_scene::RectLight::try_facing(Vec3::new(-12.0, 0.25, 0.0), Vec3::new(1.0, -0.02, 0.0), Vec3::Z, glam::Vec2::ONE, 1.0).unwrap();
    let lit_share = |settings: &[(&str, &str)]| {
        let rendered = render(&gpu, &scene, "pcss", settings, WIDTH, HEIGHT).unwrap();
        let covered = rendered.covered_visibility();
        covered.iter().filter(|v| **v > 0.95).count() as f32 / covered.len() as f32
    };
    let with_plane = lit_share(&[]);
    let without_plane = lit_share(&[("receiver_plane", "false")]);
    assert!(with_plane > 0.99, "with the receiver plane, {:.1}% of the bare receiver reads lit", with_plane * 100.0);
    assert!(without_plane < 0.9, "without it, the receiver shadows itself: {:.1}% lit", without_plane * 100.0);
}
