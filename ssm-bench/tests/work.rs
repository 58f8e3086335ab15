//! Counted work (`--count-work`, issue 40) through the tool: `compare` counts every real-time
//! technique's passes and writes the work columns, the report's section and the per-pass work
//! charts; without the flag the columns are empty and no counting frame is rendered; `render`
//! writes the work into timings.json; `sweep --cost work` counts every point and plots error
//! against work.
//!
//! lavapipe exposes pipeline statistics, so every technique's invocations are counted here;
//! texel reads are counted only by techniques whose shaders count them, and are otherwise
//! unknown (an empty field), never 0.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{column, knob_vary, pass_prefix, split_csv, two_techniques};
use ssm_bench::data::csv::parse_csv;
use ssm_bench::measure::{FrameOrder, MeasureJob, measure_all};
use ssm_core::{GpuContext, Renderer, TechniqueKind};

fn ssm(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ssm")).env("SSM_CACHE_DIR", cache).args(args).output().expect("the ssm binary runs")
}

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssm-work-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

const WORK_COLUMNS: [&str; 5] = ["vertex_invocations", "fragment_invocations", "compute_invocations", "texel_reads", "passes_work"];

/// The `all` rows of a results.csv or sweep.csv: (technique, the work columns).
fn work_of(csv: &str) -> Vec<(String, Vec<String>)> {
    let header = csv.lines().next().unwrap();
    let (technique, light) = (column(header, "technique"), column(header, "light"));
    let work: Vec<usize> = WORK_COLUMNS.iter().map(|c| column(header, c)).collect();
    csv.lines()
        .skip(1)
        .map(split_csv)
        .filter(|fields| fields[light] == "all")
        .map(|fields| (fields[technique].clone(), work.iter().map(|&i| fields[i].clone()).collect()))
        .collect()
}

/// `compare --count-work` on a built-in scene: every real-time technique this adapter runs has a
/// row whose invocations are counted (pipeline statistics) and positive, and whose texel reads
/// are a count or unknown; the CSV reads back; the report has its section and the page its work
/// columns. Without the flag every work column is empty and the report has no such section.
#[test]
fn compare_counts_every_techniques_work_only_when_asked() {
    let cache = scratch("compare-cache");
    let out = scratch("compare");
    let small = ["--scene", "parallel-square", "--width", "64", "--height", "48", "--frames", "1", "--set", "reference.samples=4"];
    let mut args = vec!["compare", "--count-work", "--out", out.to_str().unwrap()];
    args.extend_from_slice(&small);
    let output = ssm(&args, &cache);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let rows = work_of(&csv);
    let runnable: Vec<&str> = common::runnable().iter().map(|i| i.name).collect();
    let counted: Vec<&str> = rows.iter().map(|(t, _)| t.as_str()).collect();
    assert_eq!(counted, runnable, "a row for every runnable real-time technique");
    for (technique, work) in &rows {
        let count = |i: usize| -> u64 { work[i].parse().unwrap_or_else(|_| panic!("{technique}: {} `{}`", WORK_COLUMNS[i], work[i])) };
        // Every pass runs a vertex or compute shader: a frame without invocations counted nothing.
        assert!(count(0) + count(1) + count(2) > 0, "{technique}: no invocation counted: {work:?}");
        assert!(work[3].is_empty() || work[3].parse::<u64>().is_ok(), "{technique}: texel reads a count or unknown: {work:?}");
        assert!(work[4].split(';').all(|pass| pass.contains(":runs=")), "{technique}: every pass ran: {}", work[4]);
    }
    let back = parse_csv(&csv).unwrap();
    assert!(back.iter().filter(|r| r.light.is_none()).all(|r| r.work.as_ref().is_some_and(|w| w.pipeline_statistics)));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## Counted work") && report.contains("not counted (CPU ray tracing)"), "{report}");
    for info in common::runnable().iter().filter(|i| runnable.contains(&i.name)) {
        let passes = format!("| {} | {}_", info.name, pass_prefix(info));
        assert!(report.contains(&passes), "{}'s passes in report.md:\n{report}", info.name);
    }
    assert!(std::fs::read_to_string(out.join("viewer-data.js")).unwrap().contains("\"work_columns\":[["));
    assert!(out.join("passes-invocations.svg").is_file(), "the per-pass chart of invocations");
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(page.contains("data-invocations=\"passes-invocations.svg\"") && page.contains("id=\"work-passes\""));

    let plain = scratch("compare-plain");
    let mut args = vec!["compare", "--technique", two_techniques().0.name, "--out", plain.to_str().unwrap()];
    args.extend_from_slice(&small);
    let output = ssm(&args, &cache);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let csv = std::fs::read_to_string(plain.join("results.csv")).unwrap();
    let rows = work_of(&csv);
    assert_eq!(rows.len(), 1);
    assert!(rows[0].1.iter().all(String::is_empty), "not counted: {:?}", rows[0].1);
    assert!(parse_csv(&csv).unwrap()[0].work.is_none());
    assert!(!std::fs::read_to_string(plain.join("report.md")).unwrap().contains("Counted work"));
    assert!(!plain.join("passes-invocations.svg").exists());
    assert!(std::fs::read_to_string(plain.join("viewer-data.js")).unwrap().contains("\"work_columns\":null"));
    for dir in [&out, &plain, &cache] {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// In the library: a measurement without counting renders no counting frame (the process's
/// count of them stays put) and has no work; with counting, one frame per technique, after its
/// timed frames, and the ground truth none (it traces on the CPU). Alone in this binary: the
/// count is the process's.
#[test]
fn only_a_measurement_that_counts_renders_a_counting_frame() {
    let registry = ssm_bench::registry().unwrap();
    let gpu = GpuContext::new().unwrap();
    let scene = ssm_scene::builtin("parallel-square").unwrap().build();
    let info = two_techniques().0;
    let reference = registry.iter().find(|i| i.kind == TechniqueKind::GroundTruth).unwrap();
    let params = info.default_params();
    let reference_params = reference.params_from([("samples", "4"), ("cache", "false")]).unwrap();
    let needs = ssm_bench::measure::needs::requirements_of([(info, &params), (reference, &reference_params)]).unwrap();
    let mut renderer = Renderer::new(&gpu, &scene, 48, 36, &needs).unwrap();
    let job = |count_work| MeasureJob { info, params: &params, debug: &[], count_work };
    let before = ssm_bench::measure::work::counting_frames();
    let plain = measure_all(&mut renderer, &[job(false), job(false)], 1, FrameOrder::Interleaved, || {}).unwrap();
    assert_eq!(ssm_bench::measure::work::counting_frames(), before, "no counting frame without --count-work");
    assert!(plain.iter().all(|m| m.work.is_none() && m.work_note.is_none()));
    let counted = measure_all(&mut renderer, &[job(true), job(false)], 1, FrameOrder::Interleaved, || {}).unwrap();
    assert_eq!(ssm_bench::measure::work::counting_frames(), before + 1, "one counting frame, for the job that asked");
    assert!(counted[0].work.as_ref().is_some_and(|w| !w.passes.is_empty()) && counted[1].work.is_none());
    // Counting changes no result, up to the f32 rounding of additive blends whose order atomics
    // decide (atty, wedges): tests/multi_light.rs's re-render tolerance.
    let largest =
        counted[0].visibility.iter().flatten().zip(plain[0].visibility.iter().flatten()).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
    assert!(largest <= 1e-5, "counting after the timed frames changed a pixel by {largest}");
    let truth = MeasureJob { info: reference, params: &reference_params, debug: &[], count_work: true };
    let traced = measure_all(&mut renderer, &[truth], 1, FrameOrder::Sequential, || {}).unwrap();
    assert_eq!(ssm_bench::measure::work::counting_frames(), before + 1, "the ground truth has no GPU frame to count");
    assert_eq!((traced[0].work.as_ref(), traced[0].work_note), (None, Some(ssm_bench::data::work::GROUND_TRUTH_NOT_COUNTED)));
}

/// `render --count-work` writes each technique's passes into timings.json, and says why the
/// ground truth's are not counted.
#[test]
fn render_writes_the_counted_work_beside_the_times() {
    let cache = scratch("render-cache");
    let out = scratch("render");
    let technique = two_techniques().0.name;
    let techniques = format!("{technique},reference");
    let args = ["render", "--scene", "parallel-square", "--technique", &techniques, "--width", "48", "--height", "36"];
    let mut args = args.to_vec();
    args.extend_from_slice(&["--set", "reference.samples=4", "--count-work", "--out", out.to_str().unwrap()]);
    let output = ssm(&args, &cache);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("counted work per pass:") && stdout.contains("work: not counted (CPU ray tracing)"), "{stdout}");
    let timings = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join(name).join("timings.json")).unwrap()).unwrap()
    };
    let own = timings(technique);
    let passes = own["work"]["passes"].as_array().unwrap();
    assert!(!passes.is_empty() && passes.iter().all(|p| p["runs"].as_u64() > Some(0)), "{own}");
    assert_eq!(own["work"]["pipeline_statistics"], true);
    let truth = timings("reference");
    assert!(truth["work"].is_null() && truth["work_note"] == "not counted (CPU ray tracing)", "{truth}");
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&cache);
}

/// `sweep --cost work` counts every point: sweep.csv's work columns are filled, sweep.md has the
/// invocations, and sweep-work.svg plots error against work in the unit named on its axis; a
/// sweep without it counts nothing and draws no work plot.
#[test]
fn a_sweep_with_cost_work_counts_every_point_and_plots_error_against_work() {
    let cache = scratch("sweep-cache");
    let (first, second) = two_techniques();
    let (first_vary, first_points) = knob_vary(first, 2);
    let (second_vary, second_points) = knob_vary(second, 2);
    let sweep = |out: &Path, extra: &[&str]| {
        let mut args = vec!["sweep", "--scene", "parallel-square", "--vary", &first_vary, "--vary", &second_vary];
        args.extend_from_slice(&["--set", "reference.samples=4", "--width", "48", "--height", "36", "--frames", "1"]);
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let output = ssm(&args, &cache);
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        String::from_utf8_lossy(&output.stdout).into_owned()
    };
    let out = scratch("sweep-work");
    let stdout = sweep(&out, &["--cost", "work", "--work-unit", "invocations"]);
    let rows = work_of(&std::fs::read_to_string(out.join("sweep.csv")).unwrap());
    assert_eq!(rows.len(), first_points + second_points);
    for (technique, work) in &rows {
        assert!(work[..3].iter().all(|c| c.parse::<u64>().is_ok()) && !work[4].is_empty(), "{technique}: {work:?}");
    }
    let markdown = std::fs::read_to_string(out.join("sweep.md")).unwrap();
    for line in markdown.lines().skip(4) {
        let invocations: u64 = line.split('|').nth(10).unwrap().trim().parse().unwrap_or_else(|_| panic!("invocations in `{line}`"));
        assert!(invocations > 0, "{line}");
    }
    let plot = std::fs::read_to_string(out.join("sweep-work.svg")).unwrap();
    assert!(plot.contains("counted vertex, fragment and compute invocations per frame (log)"), "the axis names the unit");
    assert!(out.join("sweep-work.png").is_file() && stdout.contains("(* on the Pareto front of work)"), "{stdout}");

    let plain = scratch("sweep-plain");
    sweep(&plain, &[]);
    let rows = work_of(&std::fs::read_to_string(plain.join("sweep.csv")).unwrap());
    assert!(rows.iter().all(|(_, work)| work.iter().all(String::is_empty)), "{rows:?}");
    assert!(!plain.join("sweep-work.svg").exists());
    for dir in [&out, &plain, &cache] {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// The CPU work a paper puts inside the frame has its own column: PVSM's kd-tree and read-back
/// (its `cpu_step_ms`, part of its frame time), and nothing for a technique without any. Seen red
/// with the column filled from the frame's GPU passes instead of its CPU scopes.
#[test]
fn the_papers_cpu_step_has_its_own_column() {
    let out = scratch("cpu-step");
    let cache = out.join("cache");
    let dir = out.display().to_string();
    let output = ssm(
        &[
            "sweep",
            "--scene",
            "parallel-square",
            "--vary",
            "pvsm",
            "--vary",
            "hard",
            "--width",
            "48",
            "--height",
            "36",
            "--frames",
            "3",
            "--out",
            &dir,
        ],
        &cache,
    );
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let rows = parse_csv(&std::fs::read_to_string(out.join("sweep.csv")).unwrap()).unwrap();
    for row in rows.iter().filter(|row| row.light.is_none()) {
        match row.technique.as_str() {
            "pvsm" => {
                let cpu = row.cpu_step_ms.unwrap_or_else(|| panic!("pvsm has a CPU step: {row:?}"));
                let frame = row.gpu_ms_median.unwrap();
                assert!(cpu > 0.0 && cpu < frame, "pvsm's CPU step {cpu} ms, inside its frame's {frame} ms");
            }
            "hard" => assert_eq!(row.cpu_step_ms, None, "hard has no CPU step"),
            other => panic!("unexpected technique {other}"),
        }
    }
    let table = std::fs::read_to_string(out.join("sweep.md")).unwrap();
    assert!(table.lines().nth(2).is_some_and(|header| header.contains("| CPU step ms |")), "{table}");
}
