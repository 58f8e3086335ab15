//! `scripts/gpu-bench-device.sh`, what a session lent a GPU machine runs there (issue 13, item 7),
//! run here with this build's `ssm` in a packed folder as `scripts/gpu-bench-pack.sh` lays it out:
//! it refuses to time a software adapter unless told to, and otherwise hands back through `$OUT`
//! the adapter's name, one Markdown table with every point of the preset (its time and its counted
//! work), and an archive of the preset's sweep.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssm-gpu-bench-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A packed folder holding this build's `ssm` (no loader packages: this machine has its own), one
/// per test: the tests run in parallel in one process, and a shared folder would be emptied under
/// the other's feet.
fn pack(test: &str) -> PathBuf {
    let pack = scratch(&format!("{test}-pack"));
    std::fs::copy(env!("CARGO_BIN_EXE_ssm"), pack.join("ssm")).unwrap();
    pack
}

fn device_script(test: &str, pack: &Path, out: &Path, allow_cpu: bool) -> Output {
    device_script_with(test, pack, out, allow_cpu, &[])
}

fn device_script_with(test: &str, pack: &Path, out: &Path, allow_cpu: bool, env: &[(&str, &str)]) -> Output {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/gpu-bench-device.sh");
    let mut command = Command::new("bash");
    command
        .arg(script)
        .env("OUT", out)
        .env("SSM_BENCH_PACK", pack)
        .env("SSM_BENCH_PRESETS", "atty-map-size-time")
        .env("SSM_BENCH_WIDTH", "48")
        .env("SSM_BENCH_HEIGHT", "36")
        .env("SSM_BENCH_FRAMES", "1")
        .env("SSM_BENCH_SET", "reference.samples=4")
        .env("SSM_CACHE_DIR", scratch(&format!("{test}-cache")))
        .env_remove("SSM_BENCH_ALLOW_CPU");
    if allow_cpu {
        command.env("SSM_BENCH_ALLOW_CPU", "1");
    }
    command.envs(env.iter().copied());
    command.output().expect("bash runs the script")
}

fn is_software(adapter: &str) -> bool {
    adapter.contains("llvmpipe") || adapter.contains("Vulkan Cpu") || adapter.contains("SwiftShader")
}

#[test]
fn the_device_script_refuses_a_software_adapter_unless_told() {
    let (pack, out) = (pack("refuse"), scratch("refuse-out"));
    let output = device_script("refuse", &pack, &out, false);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let adapter = std::fs::read_to_string(out.join("adapter.txt")).expect("the script writes adapter.txt first");
    assert!(adapter.starts_with("adapter: "), "adapter.txt: {adapter}");
    if is_software(&adapter) {
        assert!(!output.status.success(), "a software adapter was timed: {stderr}");
        assert!(stderr.contains("software adapter"), "the refusal says why: {stderr}");
        assert!(!out.join("gpu-bench.md").exists(), "nothing was to be timed");
    } else {
        assert!(output.status.success(), "on a hardware adapter the bench runs: {stderr}");
        assert!(out.join("gpu-bench.md").exists());
    }
}

#[test]
fn the_device_script_hands_back_the_table_and_the_sweeps() {
    let (pack, out) = (pack("run"), scratch("run-out"));
    let output = device_script("run", &pack, &out, true);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "the script failed: {stderr}");

    let adapter = std::fs::read_to_string(out.join("adapter.txt")).unwrap();
    let name = adapter.trim().trim_start_matches("adapter: ");
    // The adapter's own name, before wgpu's backend details in brackets.
    let name = name.split(" [").next().unwrap();
    let table = std::fs::read_to_string(out.join("gpu-bench.md")).expect("gpu-bench.md comes back");
    assert!(table.starts_with("# ssm speed presets"), "{table}");
    assert!(table.contains(name), "the table names the adapter `{name}`:\n{table}");
    // atty-map-size-time: three occluder-map sizes, one- and two-sided.
    let rows: Vec<&str> = table.lines().filter(|line| line.starts_with("| atty-map-size-time |")).collect();
    assert_eq!(rows.len(), 6, "one row per point of the preset:\n{table}");
    for row in rows {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let ms: f64 = cells[5].parse().unwrap_or_else(|_| panic!("a time in `{row}`"));
        assert!(ms.is_finite() && ms > 0.0, "{row}");
        // The work beside the time: lavapipe has pipeline statistics, so invocations are counted.
        let invocations: u64 = cells[11].parse().unwrap_or_else(|_| panic!("counted invocations in `{row}`"));
        assert!(invocations > 0, "{row}");
    }

    let listing = Command::new("tar").arg("-tzf").arg(out.join("sweeps.tar.gz")).output().expect("tar runs");
    let listing = String::from_utf8_lossy(&listing.stdout);
    assert!(listing.contains("atty-map-size-time/sweep.csv"), "the archive holds the sweep: {listing}");
    assert!(listing.contains("atty-map-size-time/sweep.md"), "{listing}");
    let archive = Command::new("tar").arg("-xzOf").arg(out.join("sweeps.tar.gz")).arg("./atty-map-size-time/sweep.csv").output().unwrap();
    let csv = String::from_utf8_lossy(&archive.stdout);
    assert!(csv.lines().next().is_some_and(|h| h.contains(",texel_reads,passes_work,")), "the sweep's work columns: {csv}");
}

/// With SSM_BENCH_RESULTS the device script runs scripts/results.sh on the packed `ssm` (no build)
/// and hands back the results file, headed by its command, adapter, date and commit, leaving the
/// workspace's own generated files alone.
#[test]
fn the_device_script_hands_back_the_results_file() {
    let (pack, out) = (pack("results"), scratch("results-out"));
    let readme = Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
    let readme_before = std::fs::read_to_string(&readme).unwrap();
    let arguments = "--only summary --width 48 --height 36 --frames 1";
    let output = device_script_with("results", &pack, &out, true, &[("SSM_BENCH_RESULTS", arguments)]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "the script failed: {stderr}");
    let adapter = std::fs::read_to_string(out.join("adapter.txt")).unwrap();
    let name = adapter.trim().trim_start_matches("adapter: ").split(" [").next().unwrap().to_owned();
    // lavapipe's run is docs/results.md; any other adapter's docs/results-<adapter>.md.
    let file = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .find(|path| path.file_name().is_some_and(|n| n.to_string_lossy().starts_with("results") && n.to_string_lossy().ends_with(".md")))
        .unwrap_or_else(|| panic!("a results file comes back: {stderr}"));
    let results = std::fs::read_to_string(&file).unwrap();
    let head: Vec<&str> = results.lines().take(8).collect();
    assert!(head[0].contains("scripts/results.sh --output-root") && head[0].contains(arguments), "the command first: {head:?}");
    assert!(head.iter().any(|line| line.starts_with("- Adapter: ") && line.contains(&name)), "the adapter: {head:?}");
    assert!(head.iter().any(|line| line.starts_with("- Date: 20")), "the date: {head:?}");
    assert!(head.iter().any(|line| line.starts_with("- Commit: ") && line.len() > 20), "the commit: {head:?}");
    // One summary row per technique the framework compares, each with a number on the first scene.
    for technique in ["hard", "pcss", "multi-sm", "vssm", "sssm", "atty", "pvsm", "wedges"] {
        let row = results
            .lines()
            .find(|line| line.starts_with(&format!("| [`{technique}`]")))
            .unwrap_or_else(|| panic!("no summary row for {technique}:\n{results}"));
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        // The error, then the ground truth's own beside it: `0.0123 ± 0.0011`.
        let (error, noise) = cells[5].split_once(" ± ").unwrap_or_else(|| panic!("an error and its noise in `{row}`"));
        let (error, noise): (f64, f64) = (error.parse().unwrap(), noise.parse().unwrap());
        assert!((0.0..=1.0).contains(&error) && (0.0..=1.0).contains(&noise), "{row}");
    }
    assert_eq!(std::fs::read_to_string(&readme).unwrap(), readme_before, "README.md is left alone");
}
