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
/// table's fractional edges). What is left is the map's: the rasteriser places each edge of the
/// square within half a texel of the truth. The filter region of a floor point is the light seen
/// through the square's plane, 2 · 0.5 · (4 − 2) / (4 · 2) / 2.04 · 1024 = 62.7 texels wide (the
/// frame's half-angle tangent is 2.04, its 1024² map), so an edge crossing it moves the lit
/// fraction by at most 0.5 / 62.7 = 0.008: the bound on the penumbra's mean error, which only its
/// corners (two edges) can exceed. PCSS's 15×15 grid bands instead (a tap is all or nothing):
/// VSSM must be below it.
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
    assert!(errors[0] < 0.5 / 62.7, "vssm {}", errors[0]);
    assert!(errors[0] < errors[1], "vssm {} against pcss {}", errors[0], errors[1]);
}

/// The paper's kernel subdivision: one region's moments mix receivers and occluders at several
/// depths, Chebyshev's bound then says lit where the ground truth is dark (VSM's light bleeding);
/// sub-regions each hold fewer depths. On the `forest` (leaf cards at many heights in each crown)
/// and the `leaves` (hundreds of cards at every height) subdividing into 4×4 lowers both the
/// light leaked into the ground truth's umbra and the penumbra error.
#[test]
fn subdividing_the_kernel_cuts_light_bleeding() {
    for name in ["forest", "leaves"] {
        let scene = builtin(name).unwrap().build();
        let plain = error_against_reference(&scene, &ssm_vssm::INFO, &[("subdivision", "1")], 8, SIZE);
        let divided = error_against_reference(&scene, &ssm_vssm::INFO, &[("subdivision", "4")], 8, SIZE);
        println!(
            "{name}: subdivision 1: penumbra MAE {:.4}, umbra leak {:.4}; 4: {:.4}, {:.4}",
            plain.mae_penumbra, plain.umbra_leak, divided.mae_penumbra, divided.umbra_leak
        );
        assert!(divided.umbra_leak < plain.umbra_leak, "{name}: {} against {}", divided.umbra_leak, plain.umbra_leak);
        assert!(divided.mae_penumbra < plain.mae_penumbra, "{name}: {} against {}", divided.mae_penumbra, plain.mae_penumbra);
    }
}

/// A point light: every region is the one-texel box under the point, whose depths make the bound
/// a step but for that texel: the hard shadow of `pcss` (which reduces to `hard`'s there),
/// anti-aliased over one texel. So a pixel may differ from it in which side of 0.5 it is on, or
/// lie strictly between 0 and 1, only on the hard shadow's edge: where PCSS's image has both a lit
/// and a dark pixel among the pixel and its eight neighbours.
#[test]
fn a_point_light_gives_the_hard_shadow() {
    let gpu = gpu();
    let mut scene = builtin("floating-sphere").unwrap().build();
    scene.lights[0].half_size = Vec2::ZERO;
    let hard = render(&gpu, &scene, &ssm_pcss::INFO, &[], SIZE.0, SIZE.1).unwrap();
    let vssm = render(&gpu, &scene, &ssm_vssm::INFO, &[], SIZE.0, SIZE.1).unwrap();
    let covered = vssm.coverage();
    let (width, height) = (SIZE.0 as i32, SIZE.1 as i32);
    let on_edge = |x: i32, y: i32| {
        let around: Vec<f32> = (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
            .filter(|(x, y)| (0..width).contains(x) && (0..height).contains(y))
            .map(|(x, y)| hard.visibility[(y * width + x) as usize])
            .collect();
        around.iter().any(|v| *v > 0.5) && around.iter().any(|v| *v < 0.5)
    };
    let (mut flipped, mut soft, mut off_edge) = (0, 0, Vec::new());
    for y in 0..height {
        for x in 0..width {
            let i = (y * width + x) as usize;
            let (v, h) = (vssm.visibility[i], hard.visibility[i]);
            if !covered[i] {
                continue;
            }
            let differs = (v - 0.5) * (h - 0.5) < 0.0 || (v > 0.02 && v < 0.98);
            flipped += usize::from((v - 0.5) * (h - 0.5) < 0.0);
            soft += usize::from(v > 0.02 && v < 0.98);
            if differs && !on_edge(x, y) {
                off_edge.push((x, y, v, h));
            }
        }
    }
    println!(
        "point light: {flipped} pixels on the other side of 0.5 from the hard shadow, {soft} between 0 and 1, {} of them off its edge",
        off_edge.len()
    );
    assert!(off_edge.is_empty(), "off the hard shadow's edge (x, y, vssm, pcss): {off_edge:?}");
}
