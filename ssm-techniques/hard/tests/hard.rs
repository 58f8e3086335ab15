//! `hard` on the analytic case, and on every built-in scene against its exact
//! hard shadow (the ground truth with a point light at the light's centre).

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::Vec3;
use ssm_scene::builtin;
use ssm_testing::{at, gpu, parallel_square_exact, pixel_of, render};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

#[test]
fn parallel_square_umbra_and_lit_region() {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    assert_eq!((parallel_square_exact(0.0, 0.0), parallel_square_exact(2.5, 0.0)), (0.0, 1.0));
    let rendered = render(&gpu, &scene, &ssm_hard::INFO, &[], WIDTH, HEIGHT).unwrap();
    let umbra = at(&rendered, pixel_of(&scene, WIDTH, HEIGHT, Vec3::ZERO));
    let lit = at(&rendered, pixel_of(&scene, WIDTH, HEIGHT, Vec3::new(2.5, 0.0, 0.0)));
    assert!(umbra < 0.05, "umbra centre reads {umbra}");
    assert!(lit > 0.95, "lit receiver reads {lit}");
    assert!(rendered.visibility.iter().all(|v| *v == 0.0 || *v == 1.0), "a hard shadow has no penumbra");
}

#[test]
fn every_builtin_scene_casts_a_shadow_on_a_lit_receiver() {
    ssm_testing::every_builtin_scene_casts_a_shadow(&gpu(), &ssm_hard::INFO, WIDTH, HEIGHT);
}

/// Every built-in scene at 128×96 against its exact hard shadow: the ground truth with the light
/// shrunk to a point at its centre (one ray per pixel, exact up to the surface offset), which is
/// what a hard shadow map from the light's centre approximates. The map is sampled at texels, not
/// at the pixels' points (and half a texel off the surface, the normal offset), so the two may
/// disagree along a shadow's edge: a pixel that differs must have a pixel within two (the
/// largest texel footprint on these scenes at this size, plus the offset) on the other side of
/// the exact edge, or the image's border within two (an edge may run along it). At most
/// `STRAY_SHARE` of the covered pixels may differ elsewhere: the terminator of a face the light
/// grazes, where the map's depth slope is steepest (11 of 8,868 pixels on `contact`). This
/// replaces blessed images, which only said that the output had not changed. It is hard's own
/// output: the framework's own-surface share, which gives a closed surface straddling the area
/// light that light's share (tests/own_surface.rs), is no part of a point light's hard shadow.
#[test]
fn every_builtin_scene_matches_its_exact_hard_shadow_up_to_the_edges() {
    /// hard as registered but for the framework's own-surface share.
    static HARD_ALONE: ssm_core::TechniqueInfo =
        ssm_core::TechniqueInfo { light_sampling: ssm_core::LightSampling::PerSample, ..ssm_hard::INFO };
    /// Covered pixels allowed to differ from the exact hard shadow with no edge next to them.
    const STRAY_SHARE: f32 = 0.002;
    let (width, height) = (128u32, 96u32);
    let gpu = gpu();
    let mut failures = Vec::new();
    for entry in ssm_scene::BUILTIN_SCENES {
        let mut scene = entry.build();
        for light in &mut scene.lights {
            light.half_size = glam::Vec2::ZERO;
        }
        let exact = ssm_testing::reference(&gpu, &scene, 1, (width, height));
        let rendered = render(&gpu, &entry.build(), &HARD_ALONE, &[], width, height).unwrap();
        let covered = exact.coverage();
        // A neighbour past the image's border is unknown: an edge may run along the border.
        let truth = |x: i32, y: i32| {
            let inside = (0..width as i32).contains(&x) && (0..height as i32).contains(&y);
            inside.then(|| exact.visibility[(y as u32 * width + x as u32) as usize])
        };
        let (mut differing, mut stray, mut count) = (0usize, 0usize, 0usize);
        for y in 0..height as i32 {
            for x in 0..width as i32 {
                let index = (y as u32 * width + x as u32) as usize;
                if !covered[index] {
                    continue;
                }
                count += 1;
                if rendered.visibility[index] == exact.visibility[index] {
                    continue;
                }
                differing += 1;
                let on_edge = (-2..=2).any(|dy| (-2..=2).any(|dx| truth(x + dx, y + dy) != Some(exact.visibility[index])));
                stray += usize::from(!on_edge);
            }
        }
        let stray_share = stray as f32 / count.max(1) as f32;
        println!("{}: {differing} of {count} pixels differ from the exact hard shadow, {stray} away from its edges", entry.name);
        if stray_share > STRAY_SHARE {
            failures.push(format!("{}: {stray} of {count} pixels differ from the exact hard shadow away from its edges", entry.name));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The lookup's texel reads in a counting frame (`--count-work`) against the count by hand
/// (shaders/hard/hard.wgsl's convention: a textureLoad is one texel): every pixel loads its two
/// G-buffer texels, and every covered pixel one shadow-map texel, as none is left to the shared
/// rules on `parallel-square` (no closed mesh, every surface in front of the light); the normal
/// offset reads none. One invocation per pixel: the full-screen triangle shades each once, and a
/// helper invocation's atomics do nothing. The shadow-map pass reads no texel. In bytes, each
/// texel costs its format's size (ssm-core's formats, not the shader's constants): with G the
/// G-buffer's position and normal texels together (`Rgba32Float` each, 32 bytes) and D a depth
/// texel of the map (`R32Float`, 4), G·P + D·C bytes, exactly.
#[test]
fn the_lookup_reads_two_gbuffer_texels_per_pixel_and_one_map_texel_per_covered_pixel() {
    let (width, height) = (96u32, 72u32);
    let settings = [("shadow_map_size", "256")];
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let mut rendered = render(&gpu, &scene, &ssm_hard::INFO, &settings, width, height).unwrap();
    let pixels = u64::from(width * height);
    let covered = rendered.coverage().iter().filter(|covered| **covered).count() as u64;
    assert!(covered > 0 && covered < pixels, "{covered} of {pixels} pixels covered: the case must have both");
    let params = ssm_hard::INFO.params_from(settings).unwrap();
    let work = rendered.renderer.count_work(&ssm_hard::INFO, &params).unwrap();
    println!("{}", work.passes_column());
    assert!(work.shader_counts, "hard counts its reads");
    let pass = |name: &str| work.passes.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no {name} in {}", work.passes_column()));
    let lookup = pass("hard_lookup");
    assert_eq!((lookup.counted_invocations, lookup.texel_reads), (pixels, 2 * pixels + covered));
    let size = |format: Option<u32>| u64::from(format.expect("a format with a texel size"));
    let gbuffer =
        size(ssm_core::GBuffer::POSITION_FORMAT.block_copy_size(None)) + size(ssm_core::GBuffer::NORMAL_FORMAT.block_copy_size(None));
    let depth = size(ssm_core::LightDepthMap::FORMAT.block_copy_size(None));
    assert_eq!(lookup.read_bytes, gbuffer * pixels + depth * covered, "bytes read");
    // Every pass that reads counts its bytes, the framework's after hard's included.
    for pass in work.passes.iter().filter(|pass| pass.texel_reads > 0) {
        assert!(pass.read_bytes > 0, "{} reads {} texels and counts no bytes", pass.name, pass.texel_reads);
    }
    assert_eq!((lookup.atomics, lookup.storage_bytes), (0, 0), "the lookup writes its render target only");
    assert_eq!(pass("hard_shadow_map").texel_reads, 0);
}
