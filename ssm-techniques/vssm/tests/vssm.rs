//! `vssm` (Yang et al. 2010) against the exact visibility, against `pcss`, and its kernel
//! subdivision against VSM's light bleeding.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::Vec2;
use ssm_core::metrics::compare;
use ssm_scene::builtin;
use ssm_testing::{error_against_reference, gpu, render};

const SIZE: (u32, u32) = (160, 120);

/// On `parallel-square` each region's depths take two values, the square's and the floor's, for
/// which Chebyshev's bound is exact: the blocker estimate and the fraction lit are the exact
/// ones, and the filter is a box over texels weighted by their exact areas (the summed-area
/// table's fractional edges). So VSSM is within the map's resolution of the exact visibility:
/// below PCSS's error, whose 15×15 grid bands.
#[test]
fn parallel_square_is_exact_up_to_the_map() {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let mut errors = Vec::new();
    for (info, settings) in [(&ssm_vssm::INFO, &[][..]), (&ssm_pcss::INFO, &[][..])] {
        let rendered = render(&gpu, &scene, info, settings, 320, 240).unwrap();
        let exact = rendered.parallel_square_exact();
        let metrics = compare(&exact, &rendered.visibility, &rendered.coverage(), 320, 240);
        println!("parallel-square: {} penumbra MAE {:.4} against the exact visibility", info.name, metrics.mae_penumbra);
        errors.push(metrics.mae_penumbra);
    }
    assert!(errors[0] < 0.008, "vssm {}", errors[0]);
    assert!(errors[0] < 0.6 * errors[1], "vssm {} against pcss {}", errors[0], errors[1]);
}

/// The paper's kernel subdivision: one region's moments mix receivers and occluders at several
/// depths, Chebyshev's bound then says lit where the ground truth is dark (VSM's light bleeding);
/// sub-regions each hold fewer depths. On `sphere-cube` (a cube of spheres over the floor: each
/// region of its shadow holds the floor and spheres at many depths) subdividing into 4×4 lowers
/// both the light leaked into the ground truth's umbra and the penumbra error.
#[test]
fn subdividing_the_kernel_cuts_light_bleeding() {
    let scene = builtin("sphere-cube").unwrap().build();
    let plain = error_against_reference(&scene, &ssm_vssm::INFO, &[("subdivision", "1")], 8, SIZE);
    let divided = error_against_reference(&scene, &ssm_vssm::INFO, &[("subdivision", "4")], 8, SIZE);
    println!(
        "sphere-cube: subdivision 1: penumbra MAE {:.4}, umbra leak {:.4}; 4: {:.4}, {:.4}",
        plain.mae_penumbra, plain.umbra_leak, divided.mae_penumbra, divided.umbra_leak
    );
    assert!(divided.umbra_leak < 0.7 * plain.umbra_leak, "{} against {}", divided.umbra_leak, plain.umbra_leak);
    assert!(divided.mae_penumbra < 0.7 * plain.mae_penumbra, "{} against {}", divided.mae_penumbra, plain.mae_penumbra);
}

/// A point light: every region is the one-texel box under the point, whose depths make the bound
/// nearly a step: the hard shadow of `pcss` (which reduces to `hard`'s there), but for the box's
/// edge and the sphere's surfaces the light grazes, whose own depths spread within a texel.
#[test]
fn a_point_light_gives_the_hard_shadow() {
    let gpu = gpu();
    let mut scene = builtin("floating-sphere").unwrap().build();
    scene.lights[0].half_size = Vec2::ZERO;
    let hard = render(&gpu, &scene, &ssm_pcss::INFO, &[], SIZE.0, SIZE.1).unwrap();
    let vssm = render(&gpu, &scene, &ssm_vssm::INFO, &[], SIZE.0, SIZE.1).unwrap();
    let covered = vssm.coverage();
    let total = covered.iter().filter(|c| **c).count() as f32;
    let flipped =
        vssm.visibility.iter().zip(&hard.visibility).zip(&covered).filter(|((v, h), c)| **c && (**v - 0.5) * (**h - 0.5) < 0.0).count();
    let soft = vssm.visibility.iter().zip(&covered).filter(|(v, c)| **c && **v > 0.02 && **v < 0.98).count();
    println!(
        "point light: {:.2}% of pixels on the other side of 0.5 from the hard shadow, {:.2}% between 0 and 1",
        100.0 * flipped as f32 / total,
        100.0 * soft as f32 / total
    );
    assert!((flipped as f32) < 0.01 * total, "{flipped} of {total} pixels");
    assert!((soft as f32) < 0.04 * total, "{soft} of {total} pixels are neither lit nor dark");
}
