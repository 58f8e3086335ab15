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

/// The counts of a counting frame (`--count-work`) against the counts by hand (a textureLoad is
/// one texel, of its format's bytes: the depth map's R32Float 4, the table's Rgba32Uint and the
/// G-buffer's Rgba32Float 16; a table texel stored is 16 bytes), on `parallel-square` under a point
/// light with a 128² map:
/// - the table's rows pass runs one thread per row, which loads the 128 depths of its row and
///   stores 128 sums; the columns pass the same per column: 128² texels loaded and 16 · 128²
///   bytes stored each;
/// - the filter loads two G-buffer texels at every pixel, and table entries at every covered pixel
///   (none is left to the shared rules here: no closed mesh, every surface in front of the light).
///   Under a point light every region is the one-texel box under the point (the search's and the
///   filter's extents are the least one), one sub-region whose four table columns of four entries
///   are 16 loads, none skipped when the point is at least 1.5 texels from the table's first row
///   and column (asserted). A search that finds no blocker ends there (no retry: the region is
///   already the least); one that finds some is refined twice over the same region, then filtered
///   over it, 64 loads, and exactly those pixels read below 1 (a blocker share above 1e-6).
#[test]
fn counted_work_is_the_tables_texels_and_16_entries_per_region() {
    let (width, height) = (96u32, 72u32);
    let size = 128u64;
    let settings = [("shadow_map_size", "128")];
    let gpu = gpu();
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.lights[0].half_size = Vec2::ZERO;
    let mut rendered = render(&gpu, &scene, &ssm_vssm::INFO, &settings, width, height).unwrap();
    let params = ssm_vssm::INFO.params_from(settings).unwrap();
    let work = rendered.renderer.count_work(&ssm_vssm::INFO, &params).unwrap();
    println!("{}", work.passes_column());
    let visibility = rendered.renderer.read_visibility(0, "vssm").unwrap();
    let positions = rendered.renderer.read_positions().unwrap();
    let frame = &rendered.renderer.scene.light_frames[0];
    let (mut found, mut not_found) = (0u64, 0u64);
    for (position, visibility) in positions.iter().zip(&visibility) {
        if position[3] < 0.5 {
            continue;
        }
        let texel = frame.uv_depth(glam::Vec3::new(position[0], position[1], position[2])).truncate() * size as f32;
        assert!(texel.min_element() > 2.0 && texel.max_element() < size as f32 - 1.0, "lookup at texel {texel} too near the map's edge");
        if *visibility < 1.0 { found += 1 } else { not_found += 1 }
    }
    let pixels = u64::from(width * height);
    assert!(found > 0 && not_found > 0, "{found} pixels in shadow, {not_found} lit: the case must have both");
    let pass = |name: &str| work.passes.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no {name} in {}", work.passes_column()));
    // The bytes those reads fetched: an R32Float depth is 4 bytes, an Rgba32Uint table texel and an
    // Rgba32Float G-buffer texel 16.
    for (name, texel_bytes) in [("vssm_sat_rows", 4), ("vssm_sat_columns", 16)] {
        let sat = pass(name);
        assert_eq!(
            (sat.counted_invocations, sat.texel_reads, sat.read_bytes, sat.storage_bytes),
            (size, size * size, texel_bytes * size * size, 16 * size * size),
            "{name}"
        );
    }
    let filter = pass("vssm_filter");
    let filter_reads = 2 * pixels + 16 * not_found + 64 * found;
    assert_eq!((filter.counted_invocations, filter.texel_reads, filter.read_bytes), (pixels, filter_reads, 16 * filter_reads));
    assert_eq!(work.total(|p| p.atomics), 0);
    assert_eq!(pass("vssm_shadow_map").texel_reads, 0);
    // Every pass that reads counts its bytes, so the frame's bytes read are known.
    for pass in work.passes.iter().filter(|p| p.texel_reads > 0) {
        assert!(pass.read_bytes > 0, "{} reads {} texels but counts no bytes", pass.name, pass.texel_reads);
    }
}
