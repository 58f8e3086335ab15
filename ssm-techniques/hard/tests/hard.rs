//! `hard` on the analytic case, on every built-in scene, and against its
//! blessed reference images.

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

/// Every built-in scene at 128×96 against the blessed 16-bit PNGs in `tests/reference/`.
/// Re-bless after an intended change with `SSM_BLESS=1 cargo test -p ssm-hard`, then look at
/// the images before committing them. Lavapipe is deterministic on one machine; across Mesa
/// versions, edge pixels may move by one: a real regression moves far more.
#[test]
fn every_builtin_scene_matches_its_reference_image() {
    let directory = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference");
    if let Err(failures) = ssm_testing::every_builtin_scene_matches_its_reference_image(&gpu(), &ssm_hard::INFO, &directory) {
        panic!("{failures}");
    }
}
