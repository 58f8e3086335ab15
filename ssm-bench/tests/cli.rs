//! The `ssm` binary as a user runs it: outputs on success, one clear line and
//! a non-zero exit on failure.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::{Command, Output};

fn ssm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ssm")).args(args).output().expect("the ssm binary runs")
}

fn out_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssm-cli-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A failure prints exactly one line, starting `error:`, and exits non-zero.
fn assert_one_line_error(output: &Output, needle: &str) {
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    let lines: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].contains(needle), "expected `{needle}` in: {stderr}");
}

#[test]
fn render_writes_every_file() {
    let out = out_dir("render");
    let output = ssm(&[
        "render",
        "--scene",
        "floating-sphere",
        "--technique",
        "hard,pcss",
        "--width",
        "96",
        "--height",
        "64",
        "--set",
        "pcss.pcf_kernel=9",
        "--frames",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    assert!(out.join("position.exr").is_file());
    for technique in ["hard", "pcss"] {
        for file in ["visibility.exr", "visibility.png", "shaded.png", "timings.json"] {
            assert!(out.join(technique).join(file).is_file(), "{technique}/{file}");
        }
    }
    let timings = std::fs::read_to_string(out.join("pcss/timings.json")).unwrap();
    assert!(timings.contains("pcf_kernel=9"), "{timings}");
    assert!(timings.contains("pcss_blocker_search_and_filter"), "every pass is timed by name: {timings}");
    let shaded = image::open(out.join("hard/shaded.png")).unwrap();
    assert_eq!((shaded.width(), shaded.height()), (96, 64));
    let visibility = image::open(out.join("hard/visibility.png")).unwrap().into_luma16();
    assert!(
        visibility.pixels().any(|p| p.0[0] == 0) && visibility.pixels().any(|p| p.0[0] == u16::MAX),
        "hard visibility is binary and has both values"
    );
}

#[test]
fn list_and_scenes_name_everything() {
    let list = ssm(&["list"]);
    assert!(list.status.success());
    let text = String::from_utf8_lossy(&list.stdout);
    for needle in ["hard:", "pcss:", "--set pcss.pcf_kernel=15", "int in [1, 128]", "runs here: yes", "needs: G-buffer"] {
        assert!(text.contains(needle), "`{needle}` missing from:\n{text}");
    }
    let scenes = String::from_utf8_lossy(&ssm(&["scenes"]).stdout).into_owned();
    for name in ["parallel-square", "floating-sphere", "contact", "sphere-cube", "leaves"] {
        assert!(scenes.contains(name), "{scenes}");
    }
}

#[test]
fn bad_arguments_fail_with_one_line() {
    let out = out_dir("bad");
    let out = out.to_str().unwrap();
    assert_one_line_error(&ssm(&["render", "--scene", "parallel-square", "--technique", "nope", "--out", out]), "unknown technique `nope`");
    assert_one_line_error(
        &ssm(&["render", "--scene", "parallel-square", "--technique", "pcss", "--set", "pcss.kernel=3", "--out", out]),
        "no parameter `kernel`",
    );
    assert_one_line_error(
        &ssm(&["render", "--scene", "parallel-square", "--technique", "pcss", "--set", "pcss.pcf_kernel=1000", "--out", out]),
        "out of range",
    );
    assert_one_line_error(
        &ssm(&["render", "--scene", "parallel-square", "--technique", "pcss", "--set", "pcss.pcf_kernel=many", "--out", out]),
        "not a valid value",
    );
    assert_one_line_error(
        &ssm(&["render", "--scene", "parallel-square", "--technique", "pcss", "--set", "hard.slope_bias=1", "--out", out]),
        "not among --technique",
    );
    assert_one_line_error(&ssm(&["render", "--scene", "no-such-scene", "--technique", "hard", "--out", out]), "unknown built-in scene");
    assert_one_line_error(&ssm(&["render", "--scene", "parallel-square", "--technique", "hard", "--width", "0", "--out", out]), "invalid");
}
