//! Reference images: every built-in scene with both baselines at 128×96,
//! compared with the blessed 16-bit PNGs in `tests/reference/` within a
//! tolerance. Re-bless after an intended change with
//! `SSM_BLESS=1 cargo test --test images`, then look at the images before
//! committing them.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_integration_tests::{ImageTolerance, bless_requested, compare_with_reference, gpu, reference_directory, render};
use ssm_scene::BUILTIN_SCENES;

const SIZE: (u32, u32) = (128, 96);

/// Lavapipe is deterministic on one machine; across Mesa versions, edge
/// pixels may move by one. A real regression moves far more.
const TOLERANCE: ImageTolerance = ImageTolerance { mean: 0.002, pixel: 0.1, wrong_share: 0.005 };

#[test]
fn baselines_match_their_reference_images() {
    let gpu = gpu();
    let mut failures = Vec::new();
    for entry in BUILTIN_SCENES {
        let scene = entry.build();
        for technique in ["hard", "pcss"] {
            let rendered = render(&gpu, &scene, technique, &[], SIZE.0, SIZE.1).unwrap();
            let name = format!("{}-{technique}", entry.name);
            if let Err(message) =
                compare_with_reference(&reference_directory(), &name, &rendered.visibility, SIZE, TOLERANCE, bless_requested())
            {
                failures.push(message);
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_missing_reference_fails_and_a_mismatch_writes_actual_and_diff() {
    let directory = std::env::temp_dir().join(format!("ssm-image-harness-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&directory);
    let ramp: Vec<f32> = (0..16).map(|i| i as f32 / 15.0).collect();
    let missing = compare_with_reference(&directory, "ramp", &ramp, (4, 4), TOLERANCE, false).unwrap_err();
    assert!(missing.contains("SSM_BLESS=1"), "{missing}");
    compare_with_reference(&directory, "ramp", &ramp, (4, 4), TOLERANCE, true).unwrap();
    compare_with_reference(&directory, "ramp", &ramp, (4, 4), TOLERANCE, false).unwrap();
    assert!(!directory.join("ramp-actual.png").exists());
    let flat = vec![0.5; 16];
    let error = compare_with_reference(&directory, "ramp", &flat, (4, 4), TOLERANCE, false).unwrap_err();
    assert!(error.contains("ramp-actual.png") && error.contains("ramp-diff.png"), "{error}");
    assert!(directory.join("ramp-actual.png").is_file() && directory.join("ramp-diff.png").is_file());
    let diff = image::open(directory.join("ramp-diff.png")).unwrap().into_rgb8();
    // Pixel 0 of the ramp is 0 and now reads 0.5: lighter than the reference, so blue.
    assert!(diff.get_pixel(0, 0).0[2] > 0 && diff.get_pixel(0, 0).0[0] == 0);
    std::fs::remove_dir_all(&directory).unwrap();
}
