//! `plugin-hard` counts its work like a built-in technique (`--count-work`).

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_plugin_technique::{INFO, LOOKUP_PASS};

/// The lookup's texel reads in a counting frame against the count by hand (a textureLoad is one
/// texel): every pixel loads its two G-buffer texels, and every covered pixel one depth-map texel,
/// as none is left to the shared rules on `parallel-square` (no closed mesh, every surface in front
/// of the light). One invocation per pixel.
#[test]
fn the_lookup_reads_two_gbuffer_texels_per_pixel_and_one_map_texel_per_covered_pixel() {
    let (width, height) = (96u32, 72u32);
    let settings = [("map_size", "256")];
    let scene = ssm_scene::builtin("parallel-square").unwrap().build();
    let mut rendered = ssm_testing::render(&ssm_testing::gpu(), &scene, &INFO, &settings, width, height).unwrap();
    let pixels = u64::from(width * height);
    let covered = rendered.coverage().iter().filter(|covered| **covered).count() as u64;
    assert!(covered > 0 && covered < pixels, "{covered} of {pixels} pixels covered: the case must have both");
    let work = rendered.renderer.count_work(&INFO, &INFO.params_from(settings).unwrap()).unwrap();
    let lookup = work.passes.iter().find(|pass| pass.name == LOOKUP_PASS).unwrap();
    assert_eq!((lookup.counted_invocations, lookup.texel_reads), (pixels, 2 * pixels + covered), "{}", work.passes_column());
}
