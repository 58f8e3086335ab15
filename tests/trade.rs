//! The speed/accuracy instruments on known cases: error against the ground
//! truth, measured with ssm-core's metrics on the same pixels.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_core::metrics::{ErrorMetrics, compare};
use ssm_integration_tests::{gpu, render};
use ssm_scene::{Scene, builtin};

const SIZE: (u32, u32) = (128, 96);

/// Metrics of `technique` with `settings` against a 16×16-sample reference on `scene`.
fn error_of(scene: &Scene, technique: &str, settings: &[(&str, &str)], reference: &[f32]) -> ErrorMetrics {
    let gpu = gpu();
    let rendered = render(&gpu, scene, technique, settings, SIZE.0, SIZE.1).unwrap();
    let covered: Vec<bool> = rendered.renderer.read_positions().unwrap().iter().map(|p| p[3] > 0.5).collect();
    compare(reference, &rendered.visibility, &covered, SIZE.0 as usize, SIZE.1 as usize)
}

fn reference_of(scene: &Scene) -> Vec<f32> {
    render(&gpu(), scene, "reference", &[("samples", "16"), ("cache", "false")], SIZE.0, SIZE.1).unwrap().visibility
}

#[test]
fn multi_sm_error_falls_as_k_grows() {
    let scene = builtin("sphere-cube").unwrap().build();
    let reference = reference_of(&scene);
    let errors: Vec<f64> = ["1", "4", "16", "64"]
        .iter()
        .map(|k| {
            let m = error_of(&scene, "multi-sm", &[("samples", k)], &reference);
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
fn pcss_has_lower_penumbra_error_than_hard_on_parallel_square() {
    let scene = builtin("parallel-square").unwrap().build();
    let reference = reference_of(&scene);
    let hard = error_of(&scene, "hard", &[], &reference);
    let pcss = error_of(&scene, "pcss", &[], &reference);
    println!("parallel-square: hard mae_penumbra {:.4}, pcss {:.4}", hard.mae_penumbra, pcss.mae_penumbra);
    assert!(pcss.mae_penumbra < hard.mae_penumbra * 0.6, "pcss {} vs hard {}", pcss.mae_penumbra, hard.mae_penumbra);
    assert!(pcss.ssim > hard.ssim);
}
