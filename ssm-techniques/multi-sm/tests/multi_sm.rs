//! `multi-sm` converges to the ground truth as K grows.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_scene::builtin;
use ssm_testing::error_against_reference;

#[test]
fn the_error_falls_as_k_grows() {
    let scene = builtin("sphere-cube").unwrap().build();
    let errors: Vec<f64> = ["1", "4", "16", "64"]
        .iter()
        .map(|k| {
            let m = error_against_reference(&scene, &ssm_multi_sm::INFO, &[("samples", k)], 16, (128, 96));
            println!("multi-sm K = {k}: mae_penumbra {:.4}, rmse {:.4}, ssim {:.4}", m.mae_penumbra, m.rmse, m.ssim);
            m.mae_penumbra
        })
        .collect();
    for pair in errors.windows(2) {
        assert!(pair[1] < pair[0], "the error must fall with K: {errors:?}");
    }
    // From one map (a hard shadow) to 64 the penumbra error falls several-fold.
    assert!(errors[3] < errors[0] / 3.0, "{errors:?}");
}

#[test]
fn samples_must_be_a_perfect_square() {
    let scene = builtin("parallel-square").unwrap().build();
    let error = ssm_testing::render(&ssm_testing::gpu(), &scene, &ssm_multi_sm::INFO, &[("samples", "5")], 32, 24).err().unwrap();
    assert!(error.to_string().contains("perfect square"), "{error}");
}
