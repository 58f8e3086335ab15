//! `ssm compare` end to end: the CSV has the documented columns and sane
//! numbers, and `index.html` opens in headless Chromium with every image
//! loaded. Chromium must be installed (scripts/install-deps.sh --for-tests):
//! a missing browser fails the test, it does not skip it.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{column, int_param, knob_vary, split_csv, two_techniques};

fn ssm(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_ssm")).args(args).output().expect("the ssm binary runs")
}

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssm-report-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Headless Chromium with the flags that keep it off the network.
fn chromium(profile: &Path, args: &[&str]) -> std::process::Output {
    let profile_flag = format!("--user-data-dir={}", profile.display());
    let mut command = Command::new(common::chromium_binary());
    command.args(common::OFFLINE_FLAGS).args(["--allow-file-access-from-files", "--virtual-time-budget=5000", &profile_flag]);
    command.args(args).output().expect("chromium runs")
}

#[test]
fn compare_writes_a_csv_and_a_report_that_renders_in_a_browser() {
    let out = scratch("compare");
    let cache = scratch("cache");
    let (first, second) = two_techniques();
    let techniques = format!("{},{}", first.name, second.name);
    let output = Command::new(env!("CARGO_BIN_EXE_ssm"))
        .env("SSM_CACHE_DIR", &cache)
        .args([
            "compare",
            "--scene",
            "parallel-square",
            "--technique",
            &techniques,
            "--width",
            "96",
            "--height",
            "72",
            "--frames",
            "2",
            "--set",
            "reference.samples=8",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));

    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(lines.next().unwrap().starts_with(
        "scene,technique,params,width,height,gpu_ms_median,gpu_ms_min,cpu_ms,mae_penumbra,rmse,max_abs,psnr,ssim,frac_over_0_05,adapter"
    ));
    let rows: Vec<Vec<String>> = lines.map(split_csv).collect();
    assert_eq!(rows.len(), 2);
    let value = |row: &Vec<String>, i: usize| row[i].parse::<f64>().unwrap();
    for row in &rows {
        assert_eq!(row[0], "parallel-square");
        assert!(value(row, 5) > 0.0, "GPU time is measured: {row:?}");
        assert!((0.0..=1.0).contains(&value(row, 8)) && (0.0..=1.0).contains(&value(row, 12)), "{row:?}");
    }
    assert_eq!((rows[0][1].as_str(), rows[1][1].as_str()), (first.name, second.name));
    assert!(std::fs::read_to_string(out.join("report.md")).unwrap().contains(&format!("| `{}` |", second.name)));
    for file in ["reference/shaded.png".to_owned(), format!("{}/heatmap.png", first.name), format!("{}/visibility.exr", second.name)] {
        assert!(out.join(&file).is_file(), "{file}");
    }

    // The report, opened from disk with no network: every image loads.
    let page = format!("file://{}", out.join("index.html").display());
    let dom = chromium(&scratch("profile"), &["--dump-dom", &page]);
    let dom = String::from_utf8_lossy(&dom.stdout);
    // Ground truth (2 images) + 2 techniques × 3 images + the per-pass time chart.
    assert!(dom.contains("data-images-loaded=\"9/9\""), "not every image loaded:\n{}", &dom[..dom.len().min(2000)]);
    let screenshot = out.join("screenshot.png");
    let shot = chromium(&scratch("profile2"), &["--window-size=1200,1600", &format!("--screenshot={}", screenshot.display()), &page]);
    assert!(screenshot.is_file(), "{}", String::from_utf8_lossy(&shot.stderr));
    let image = image::open(&screenshot).unwrap().into_rgb8();
    // Table text, grey scales and the heat maps' colours: a rendered page is far from uniform.
    let colours: std::collections::HashSet<[u8; 3]> = image.pixels().map(|p| p.0).collect();
    assert!(colours.len() > 200, "the page looks empty ({} colours)", colours.len());
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&cache);
}

#[test]
fn unknown_settings_in_compare_fail_with_one_line() {
    let out = scratch("bad");
    let (first, second) = two_techniques();
    let setting = format!("{}.{}=3", second.name, int_param(second).unwrap().0);
    let output =
        ssm(&["compare", "--scene", "parallel-square", "--technique", first.name, "--set", &setting, "--out", out.to_str().unwrap()]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.lines().filter(|l| l.starts_with("error:")).count() == 1 && stderr.contains("not compared"), "{stderr}");
}

#[test]
fn sweep_writes_a_csv_row_per_point_and_the_trade_plot() {
    let out = scratch("sweep");
    let cache = scratch("sweep-cache");
    // Each technique's own quality knob, as the trade preset varies it.
    let (first, second) = two_techniques();
    let ((first_vary, first_count), (second_vary, second_count)) = (knob_vary(first, 2), knob_vary(second, 3));
    let output = Command::new(env!("CARGO_BIN_EXE_ssm"))
        .env("SSM_CACHE_DIR", &cache)
        .args([
            "sweep",
            "--scene",
            "parallel-square",
            "--vary",
            &first_vary,
            "--vary",
            &second_vary,
            "--set",
            "reference.samples=8",
            "--width",
            "96",
            "--height",
            "72",
            "--frames",
            "1",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv.lines().skip(1).map(split_csv).collect();
    assert_eq!(rows.len(), first_count + second_count, "{csv}");
    assert!(rows.iter().take(first_count).all(|r| r[1] == first.name) && rows.iter().skip(first_count).all(|r| r[1] == second.name));
    // Each row carries its own point's parameters: the second point differs from the first.
    assert_ne!(rows[0][2], rows[1][2]);
    assert!(rows.iter().all(|r| (0.0..=1.0).contains(&r[8].parse::<f64>().unwrap())), "{csv}");
    let png = image::open(out.join("sweep.png")).unwrap();
    assert_eq!((png.width(), png.height()), (1000, 700));
    let svg = std::fs::read_to_string(out.join("sweep.svg")).unwrap();
    assert!(svg.contains("Pareto front") && svg.contains(second.name) && svg.contains("<circle"), "the plot has its legend and points");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.lines().any(|l| l.starts_with('*')), "the Pareto front is marked:\n{stdout}");
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&cache);
}

#[test]
fn sweep_varies_the_scene_and_plots_against_a_parameter() {
    let out = scratch("sweep-scene");
    let cache = scratch("sweep-scene-cache");
    let (first, _) = two_techniques();
    let (param, default, _, _) = int_param(first).unwrap();
    let fixed_point = format!("{}.{param}={default}", first.name);
    let output = Command::new(env!("CARGO_BIN_EXE_ssm"))
        .env("SSM_CACHE_DIR", &cache)
        .args([
            "sweep",
            "--scene",
            "parallel-square",
            "--vary",
            "scene.light_scale=0.5,2",
            "--vary",
            &fixed_point,
            "--x",
            "scene.light_scale",
            "--pixels",
            "receivers",
            "--images",
            "--set",
            "reference.samples=6",
            "--width",
            "96",
            "--height",
            "72",
            "--frames",
            "1",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv.lines().skip(1).map(split_csv).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    assert_eq!(rows[0][0], "parallel-square[light_scale=0.5]");
    assert_eq!(rows[1][0], "parallel-square[light_scale=2]");
    // A larger light, a wider penumbra: more penumbra pixels.
    let penumbra_column = column(csv.lines().next().unwrap(), "penumbra_pixels");
    let penumbra: Vec<u64> = rows.iter().map(|r| r[penumbra_column].parse().unwrap()).collect();
    assert!(penumbra[1] > penumbra[0], "{penumbra:?}");
    let svg = std::fs::read_to_string(out.join("sweep.svg")).unwrap();
    assert!(svg.contains("scene.light_scale") && !svg.contains("Pareto front"), "parameter axis, no Pareto front");
    // --images: each scene point's ground truth and each technique point's images.
    for scale in ["0.5", "2"] {
        let scene_point = out.join("images").join(format!("light_scale={scale}"));
        assert!(scene_point.join("reference").join("visibility.png").is_file(), "{}", scene_point.display());
        let point = scene_point.join(first.name).join(format!("{param}={default}"));
        for file in ["visibility.png", "visibility.exr", "shaded.png", "heatmap.png"] {
            assert!(point.join(file).is_file(), "{}/{file}", point.display());
        }
    }
    let bad =
        ssm(&["sweep", "--scene", "parallel-square", "--vary", "scene.colour=1", "--vary", &fixed_point, "--out", out.to_str().unwrap()]);
    let message = String::from_utf8_lossy(&bad.stderr);
    assert!(message.contains("scene.colour") && message.contains("unknown parameter `colour`"), "{message}");
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&cache);
}

/// Every measured technique reports the GPU memory it holds, and it follows what it allocates:
/// `hard` at 1024² holds four times what it holds at 512² (its maps are all there is).
#[test]
fn the_memory_a_technique_holds_is_reported() {
    let gpu = ssm_core::GpuContext::new().unwrap();
    let registry = ssm_bench::registry().unwrap();
    let hard = registry.get("hard").unwrap();
    let scene = ssm_scene::builtin("parallel-square").unwrap().build();
    let defaults = ssm_core::ParamValues::defaults(hard.name, hard.params);
    let mut renderer = ssm_core::Renderer::new(&gpu, &scene, 64, 48, &(hard.requirements)(&defaults).unwrap()).unwrap();
    let mut memory = |size: &str| {
        let mut params = defaults.clone();
        params.set("shadow_map_size", size).unwrap();
        let measured = ssm_bench::measure::measure(&mut renderer, hard, &params, 1, &[]).unwrap();
        measured.diagnostics.iter().find(|(k, _)| k == ssm_bench::measure::MEMORY_DIAGNOSTIC).map(|(_, v)| *v).unwrap()
    };
    let (small, large) = (memory("512"), memory("1024"));
    println!("hard: {small} MiB at 512², {large} MiB at 1024²");
    assert!(small > 0.0 && (large / small - 4.0).abs() < 0.1, "{small} MiB, {large} MiB");
}

/// Techniques measured together with their frames in turns (`FrameOrder::Interleaved`, what
/// `compare`, `render` and `sweep` do without `--sequential`) each keep their own frames, images
/// and memory: the same visibility as measured one after the other, every frame, and `hard` at
/// 1024² holding four times what it holds at 512² though both exist at once.
#[test]
fn techniques_measured_in_turns_keep_their_own_images_and_memory() {
    use ssm_bench::measure::{FrameOrder, MeasureJob, measure_all};
    let gpu = ssm_core::GpuContext::new().unwrap();
    let registry = ssm_bench::registry().unwrap();
    let (hard, pcss) = (registry.get("hard").unwrap(), registry.get("pcss").unwrap());
    let scene = ssm_scene::builtin("sphere-cube").unwrap().build();
    let hard_params = |size: &str| {
        let mut params = ssm_core::ParamValues::defaults(hard.name, hard.params);
        params.set("shadow_map_size", size).unwrap();
        params
    };
    let (small, large, soft) = (hard_params("512"), hard_params("1024"), ssm_core::ParamValues::defaults(pcss.name, pcss.params));
    let needs = ssm_bench::measure::needs::requirements_of([(hard, &small), (pcss, &soft)]).unwrap();
    let mut renderer = ssm_core::Renderer::new(&gpu, &scene, 64, 48, &needs).unwrap();
    let jobs = [
        MeasureJob { info: hard, params: &small, debug: &[], count_work: false },
        MeasureJob { info: pcss, params: &soft, debug: &[], count_work: false },
        MeasureJob { info: hard, params: &large, debug: &[], count_work: false },
    ];
    let mut timed = 0;
    let in_turns = measure_all(&mut renderer, &jobs, 3, FrameOrder::Interleaved, || timed += 1).unwrap();
    let one_by_one = measure_all(&mut renderer, &jobs, 3, FrameOrder::Sequential, || {}).unwrap();
    assert_eq!(timed, 9, "one call per timed frame");
    let memory =
        |m: &ssm_bench::measure::Measured| m.diagnostics.iter().find(|(k, _)| k == ssm_bench::measure::MEMORY_DIAGNOSTIC).unwrap().1;
    for (index, (turns, alone)) in in_turns.iter().zip(&one_by_one).enumerate() {
        assert_eq!(turns.frames.len(), 3, "job {index}");
        assert!(turns.visibility == alone.visibility, "job {index}: its visibility measured in turns differs from measured alone");
        println!("job {index}: {} MiB in turns, {} MiB alone", memory(turns), memory(alone));
        assert!((memory(turns) - memory(alone)).abs() < 1e-3, "job {index}");
    }
    assert!(in_turns[0].visibility != in_turns[1].visibility, "hard and PCSS must differ for the test to tell them apart");
    let (small_mib, large_mib) = (memory(&in_turns[0]), memory(&in_turns[2]));
    assert!(small_mib > 0.0 && (large_mib / small_mib - 4.0).abs() < 0.1, "{small_mib} MiB, {large_mib} MiB");
}

/// A sweep split into 3 shards (`--shard K/3`) and merged (`ssm merge`) equals the unsharded
/// sweep row for row, times aside; the second shard straddles the two scene points. A missing
/// shard and a shard of another sweep are refused.
#[test]
fn three_shards_merged_equal_the_unsharded_sweep() {
    let cache = scratch("shard-cache");
    let run = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_ssm")).env("SSM_CACHE_DIR", &cache).args(args).output().unwrap();
    let sweep = |out: &Path, frames: &str, extra: &[&str]| {
        let mut args = vec![
            "sweep",
            "--scene",
            "parallel-square",
            "--vary",
            "scene.light_scale=0.5,2",
            "--vary",
            "hard.shadow_map_size=256,512,1024",
            "--set",
            "reference.samples=4",
            "--width",
            "64",
            "--height",
            "48",
            "--frames",
            frames,
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let output = run(&args);
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    };
    let whole = scratch("shard-whole");
    sweep(&whole, "1", &[]);
    let shards: Vec<PathBuf> = (1..=3).map(|k| scratch(&format!("shard-{k}"))).collect();
    for (k, dir) in shards.iter().enumerate() {
        sweep(dir, "1", &["--shard", &format!("{}/3", k + 1)]);
        let rows = std::fs::read_to_string(dir.join("sweep.csv")).unwrap().lines().count() - 1;
        assert_eq!(rows, 2, "6 runs in 3 shards: 2 each");
    }
    let merged = scratch("shard-merged");
    let mut args = vec!["merge", "--out", merged.to_str().unwrap()];
    // Given in another order: the merge puts the rows back in the unsharded order.
    args.extend(shards.iter().rev().map(|d| d.to_str().unwrap()));
    let output = run(&args);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    // Every column but the times.
    let untimed = |dir: &Path| -> Vec<Vec<String>> {
        let text = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
        let header = text.lines().next().unwrap().to_owned();
        let timed: Vec<usize> =
            ["gpu_ms_median", "gpu_ms_min", "cpu_ms", "passes_ms", "gpu_ms_q1", "gpu_ms_q3"].iter().map(|c| column(&header, c)).collect();
        text.lines()
            .map(|line| split_csv(line).into_iter().enumerate().map(|(i, f)| if timed.contains(&i) { String::new() } else { f }).collect())
            .collect()
    };
    let (expected, got) = (untimed(&whole), untimed(&merged));
    assert_eq!(expected.len(), 7, "a header and 6 rows");
    assert_eq!(got, expected);
    for file in ["sweep.md", "sweep.png", "sweep.svg"] {
        assert!(merged.join(file).is_file(), "{file}");
    }
    // Two of three shards, and a shard of another sweep, are refused.
    let missing = run(&["merge", "--out", merged.to_str().unwrap(), shards[0].to_str().unwrap(), shards[2].to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&missing.stderr).contains("shard 2/3 is missing"), "{}", String::from_utf8_lossy(&missing.stderr));
    let other = scratch("shard-other");
    sweep(&other, "2", &["--shard", "2/3"]);
    let mixed = run(&[
        "merge",
        "--out",
        merged.to_str().unwrap(),
        shards[0].to_str().unwrap(),
        other.to_str().unwrap(),
        shards[2].to_str().unwrap(),
    ]);
    let message = String::from_utf8_lossy(&mixed.stderr);
    assert!(message.contains("shards of different sweeps (frames: 1 against 2)"), "{message}");
    for dir in shards.iter().chain([&whole, &merged, &other, &cache]) {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// FLIP's noise floor: the ground truth's shaded image against the same shading of its visibility
/// moved by its own noise, the same for every row of a scene, above 0 where the truth samples
/// (leaves' ground under 2×2 rays a set), below every technique's FLIP there, and printed beside
/// each FLIP in report.md. Seen red with the truth's visibility left unmoved (a floor of 0).
#[test]
fn the_flip_noise_floor_is_what_the_truths_own_noise_shows() {
    let out = scratch("flip-noise");
    let dir = out.display().to_string();
    let cache = out.join("cache");
    let output = Command::new(env!("CARGO_BIN_EXE_ssm"))
        .env("SSM_CACHE_DIR", &cache)
        .args(["compare", "--scene", "leaves", "--technique", "hard,pcss", "--width", "64", "--height", "48"])
        .args(["--frames", "1", "--set", "reference.samples=2", "--out", &dir])
        .output()
        .expect("the ssm binary runs");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    let (technique, flip, floor) = (column(header, "technique"), column(header, "flip_mean"), column(header, "flip_noise"));
    let rows: Vec<Vec<String>> = csv.lines().skip(1).map(split_csv).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    let floors: Vec<f64> = rows.iter().map(|row| row[floor].parse().unwrap_or_else(|_| panic!("a floor in {row:?}"))).collect();
    assert!(floors[0] > 0.0 && floors[0] == floors[1], "one floor per scene, above 0: {floors:?}");
    for row in &rows {
        let value: f64 = row[flip].parse().unwrap();
        assert!(floors[0] < value, "{}: FLIP {value} above the floor {}", row[technique], floors[0]);
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains(&format!(" ± {:.4} |", floors[0])), "report.md prints the floor beside each FLIP:\n{report}");
}
