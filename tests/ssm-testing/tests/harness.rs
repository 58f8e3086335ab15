//! The image comparison of ssm-testing: a missing reference fails unless
//! blessed, and a mismatch writes `-actual` and `-diff` images.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_testing::{ImageTolerance, compare_with_reference};

const TOLERANCE: ImageTolerance = ImageTolerance { mean: 0.002, pixel: 0.1, wrong_share: 0.005 };

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
