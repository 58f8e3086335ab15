//! `hard` on the analytic case, on every built-in scene, and against its
//! blessed reference images.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::Vec3;
use ssm_scene::{BUILTIN_SCENES, builtin};
use ssm_testing::{ImageTolerance, at, bless_requested, compare_with_reference, gpu, parallel_square_exact, pixel_of, render};

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
    let gpu = gpu();
    for entry in BUILTIN_SCENES {
        let rendered = render(&gpu, &entry.build(), &ssm_hard::INFO, &[], WIDTH, HEIGHT).unwrap_or_else(|e| panic!("{}: {e}", entry.name));
        let shadowed = rendered.visibility.iter().filter(|v| **v < 0.5).count();
        let lit = rendered.visibility.iter().filter(|v| **v > 0.5).count();
        assert!(shadowed > 50, "{}: only {shadowed} shadowed pixels", entry.name);
        assert!(lit > shadowed, "{}: {lit} lit vs {shadowed} shadowed", entry.name);
    }
}

/// Every built-in scene at 128×96 against the blessed 16-bit PNGs in `tests/reference/`.
/// Re-bless after an intended change with `SSM_BLESS=1 cargo test -p ssm-hard`, then look at
/// the images before committing them. Lavapipe is deterministic on one machine; across Mesa
/// versions, edge pixels may move by one: a real regression moves far more.
#[test]
fn every_builtin_scene_matches_its_reference_image() {
    let gpu = gpu();
    let directory = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference");
    let tolerance = ImageTolerance { mean: 0.002, pixel: 0.1, wrong_share: 0.005 };
    let failures: Vec<String> = BUILTIN_SCENES
        .iter()
        .filter_map(|entry| {
            let rendered = render(&gpu, &entry.build(), &ssm_hard::INFO, &[], 128, 96).unwrap();
            let name = format!("{}-hard", entry.name);
            compare_with_reference(&directory, &name, &rendered.visibility, (128, 96), tolerance, bless_requested()).err()
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
