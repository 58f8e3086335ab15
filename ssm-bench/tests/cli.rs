//! The `ssm` binary as a user runs it: outputs on success, one clear line and
//! a non-zero exit on failure.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::PathBuf;
use std::process::{Command, Output};

use common::{column, int_param, pass_prefix, split_csv, two_techniques};

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
    let (first, second) = two_techniques();
    let (param, default, min, _) = int_param(first).unwrap();
    let value = if default == min { min + 1 } else { min };
    let setting = format!("{}.{param}={value}", first.name);
    let techniques = format!("{},{}", first.name, second.name);
    let output = ssm(&[
        "render",
        "--scene",
        "floating-sphere",
        "--technique",
        &techniques,
        "--width",
        "96",
        "--height",
        "64",
        "--set",
        &setting,
        "--frames",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    assert!(out.join("position.exr").is_file());
    for technique in [first.name, second.name] {
        for file in ["visibility.exr", "visibility.png", "shaded.png", "timings.json"] {
            assert!(out.join(technique).join(file).is_file(), "{technique}/{file}");
        }
    }
    let timings = std::fs::read_to_string(out.join(first.name).join("timings.json")).unwrap();
    assert!(timings.contains(&format!("{param}={value}")), "{timings}");
    assert!(timings.contains(&format!("\"{}_", pass_prefix(first))), "every pass is timed by name: {timings}");
    let shaded = image::open(out.join(second.name).join("shaded.png")).unwrap();
    assert_eq!((shaded.width(), shaded.height()), (96, 64));
    let visibility = image::open(out.join(second.name).join("visibility.png")).unwrap().into_luma16();
    assert!(
        visibility.pixels().any(|p| p.0[0] < u16::MAX / 4) && visibility.pixels().any(|p| p.0[0] == u16::MAX),
        "the sphere's shadow and lit ground are both there"
    );
}

/// A first run on a machine without a display session prints no line starting with `error`
/// (Mesa's window-system layer would, unless ssm switches it off), and `position.exr` tells
/// background from geometry through its coverage channel, even for a surface at the origin.
#[test]
fn a_first_headless_render_prints_no_error_and_marks_background() {
    let out = out_dir("headless");
    let output = Command::new(env!("CARGO_BIN_EXE_ssm"))
        .args(["render", "--scene", "parallel-square", "--technique", two_techniques().0.name, "--width", "64", "--height", "48", "--out"])
        .arg(&out)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let all = format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert!(!all.lines().any(|l| l.trim_start().to_ascii_lowercase().starts_with("error")), "{all}");

    let positions = ssm_core::image_io::read_exr(&out.join("position.exr")).unwrap();
    let channel = |name: &str| positions.channel(name).unwrap_or_else(|| panic!("no channel {name}")).to_vec();
    let (x, y, z, coverage) = (channel("R"), channel("G"), channel("B"), channel("A"));
    // parallel-square's camera looks at the origin, a point of the receiver: the centre pixel is covered
    // and lies near (0, 0, 0); the top row sees the sky.
    let centre = (48 / 2) * 64 + 64 / 2;
    assert_eq!(coverage[centre], 1.0);
    assert!(x[centre].abs() < 0.2 && y[centre].abs() < 1e-3 && z[centre].abs() < 0.2, "({}, {}, {})", x[centre], y[centre], z[centre]);
    assert!(coverage[..64].iter().all(|a| *a == 0.0), "the top row is background");
    assert!(coverage.iter().all(|a| *a == 0.0 || *a == 1.0));
    // The visibility EXR carries the same coverage.
    let visibility = ssm_core::image_io::read_exr(&out.join(two_techniques().0.name).join("visibility.exr")).unwrap();
    assert_eq!(visibility.channel("A").unwrap(), coverage.as_slice());
    assert!(visibility.channel("Y").is_some());
}

/// `compare` on a scene with three lights reports each light and all of them together.
#[test]
fn compare_reports_every_light_and_the_total() {
    let dir = out_dir("lights");
    std::fs::create_dir_all(&dir).unwrap();
    let manifest = dir.join("three-lights.toml");
    std::fs::write(
        &manifest,
        "[camera]\nposition = [0.0, 5.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[light]]\ncentre = [0.0, 4.0, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [1.0, 1.0]\n\
         [[light]]\ncentre = [2.0, 5.0, 1.0]\nnormal = [-0.3, -1.0, -0.2]\nsize = [2.0, 0.5]\nintensity = 0.5\n\
         [[light]]\ncentre = [-2.0, 3.0, -1.0]\nnormal = [0.4, -1.0, 0.3]\nsize = [0.2, 0.2]\nintensity = 2.0\n\
         [[object]]\nprimitive = \"sphere\"\nsize = [0.6]\ntranslate = [0.0, 1.5, 0.0]\n\
         [[object]]\nprimitive = \"plane\"\nsize = [8.0, 8.0]\nrole = \"receiver\"\n",
    )
    .unwrap();
    let out = dir.join("report");
    let output = ssm(&[
        "compare",
        "--scene",
        manifest.to_str().unwrap(),
        "--technique",
        two_techniques().0.name,
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "1",
        "--set",
        "reference.samples=4",
        "--set",
        "reference.cache=false",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let light_column = column(csv.lines().next().unwrap(), "light");
    let lights: Vec<String> = csv.lines().skip(1).map(|l| split_csv(l)[light_column].clone()).collect();
    assert_eq!(lights, ["all", "0", "1", "2"], "{csv}");
    let technique = two_techniques().0.name;
    for file in
        [format!("{technique}/visibility-light2.exr"), format!("{technique}/heatmap-light1.png"), "reference/visibility-light2.png".into()]
    {
        assert!(out.join(&file).is_file(), "{file}");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains(&format!("`{technique}` · light 2")), "{report}");
    // Where the time goes: the per-pass chart, drawn into the HTML report.
    let chart = std::fs::read_to_string(out.join("passes.svg")).unwrap();
    assert!(chart.contains(&format!("{technique} (")) && out.join("passes.png").is_file(), "{chart}");
    assert!(std::fs::read_to_string(out.join("index.html")).unwrap().contains("<img src=\"passes.svg\""));
}

#[test]
fn list_and_scenes_name_everything() {
    let list = ssm(&["list"]);
    assert!(list.status.success());
    let text = String::from_utf8_lossy(&list.stdout);
    for info in ssm_bench::registry().unwrap().iter() {
        assert!(text.contains(&format!("{}:", info.name)), "`{}` missing from:\n{text}", info.name);
        for spec in info.params {
            let line = format!("--set {}.{}={}  ({}", info.name, spec.name, spec.default_value(), spec.range_text());
            assert!(text.contains(&line), "`{line}` missing from:\n{text}");
        }
    }
    for info in ssm_bench::registry().unwrap().iter() {
        for output in info.debug_outputs {
            let line = format!("--debug-output {}  ({})", output.name, output.doc);
            assert!(text.contains(&line), "`{line}` missing from:\n{text}");
        }
    }
    for needle in ["runs here: yes", "needs: G-buffer"] {
        assert!(text.contains(needle), "`{needle}` missing from:\n{text}");
    }
    let scenes = String::from_utf8_lossy(&ssm(&["scenes"]).stdout).into_owned();
    for entry in ssm_scene::BUILTIN_SCENES {
        assert!(scenes.contains(entry.name), "{scenes}");
        for param in entry.params {
            let line = format!("{}:{}={}  ({} to {})", entry.name, param.name, param.default, param.min, param.max);
            assert!(scenes.contains(&line), "`{line}` missing from:\n{scenes}");
        }
    }
}

/// A reader that stops reading (`ssm list | head`) is not a failure: no error line, exit 0. The
/// pipe's reading end is closed before `ssm` writes (it opens the adapter first), so its first
/// line meets a closed pipe every time.
#[test]
fn a_reader_that_stops_reading_is_not_a_failure() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_ssm"))
        .arg("list")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the ssm binary runs");
    drop(child.stdout.take());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{:?}: {stderr}", output.status);
    assert!(!stderr.lines().any(|l| l.starts_with("error")), "{stderr}");
}

#[test]
fn bad_arguments_fail_with_one_line() {
    let out = out_dir("bad");
    let out = out.to_str().unwrap();
    let (first, second) = two_techniques();
    let (param, _, _, max) = int_param(first).unwrap();
    let (other_param, _, _, _) = int_param(second).unwrap();
    let render = |technique: &str, setting: &str| {
        ssm(&["render", "--scene", "parallel-square", "--technique", technique, "--set", setting, "--out", out])
    };
    assert_one_line_error(&ssm(&["render", "--scene", "parallel-square", "--technique", "nope", "--out", out]), "unknown technique `nope`");
    assert_one_line_error(&render(first.name, &format!("{}.no_such_parameter=3", first.name)), "no parameter `no_such_parameter`");
    assert_one_line_error(&render(first.name, &format!("{}.{param}={}", first.name, max + 1)), "out of range");
    assert_one_line_error(&render(first.name, &format!("{}.{param}=many", first.name)), "not a valid value");
    assert_one_line_error(&render(first.name, &format!("{}.{other_param}=1", second.name)), "not among --technique");
    assert_one_line_error(&ssm(&["render", "--scene", "no-such-scene", "--technique", first.name, "--out", out]), "unknown built-in scene");
    assert_one_line_error(
        &ssm(&["render", "--scene", "sphere-cube:spheres=1000", "--technique", first.name, "--out", out]),
        "built-in scene `sphere-cube:spheres=1000`: spheres = 1000 is outside 1..=40",
    );
    assert_one_line_error(
        &ssm(&["render", "--scene", "parallel-square", "--technique", first.name, "--width", "0", "--out", out]),
        "invalid",
    );
}

/// `--debug-output all` writes every debug output each technique declares (as `.png` and `.exr`),
/// nothing is written unasked, and a name no technique offers is refused before any GPU work.
#[test]
fn debug_outputs_are_written_when_asked_and_only_then() {
    let offering: Vec<_> = common::runnable().into_iter().filter(|i| !i.debug_outputs.is_empty()).collect();
    assert!(!offering.is_empty(), "no technique declares a debug output");
    let names = offering.iter().map(|i| i.name).collect::<Vec<_>>().join(",");
    let render = |out: &PathBuf, extra: &[&str]| {
        let mut args = vec![
            "render",
            "--scene",
            "floating-sphere",
            "--technique",
            &names,
            "--width",
            "64",
            "--height",
            "48",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        ssm(&args)
    };
    let asked = out_dir("debug-asked");
    let output = render(&asked, &["--debug-output", "all"]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let unasked = out_dir("debug-unasked");
    assert!(render(&unasked, &[]).status.success());
    for info in &offering {
        for debug in info.debug_outputs {
            for extension in ["png", "exr"] {
                let file = format!("{}.{extension}", debug.name);
                assert!(asked.join(info.name).join(&file).is_file(), "{}/{file} not written", info.name);
                assert!(!unasked.join(info.name).join(&file).exists(), "{}/{file} written unasked", info.name);
            }
        }
    }
    assert_one_line_error(
        &render(&unasked, &["--debug-output", "no_such_output"]),
        "--debug-output no_such_output: no technique run offers it",
    );
    let _ = std::fs::remove_dir_all(&asked);
    let _ = std::fs::remove_dir_all(&unasked);
}

/// `ssm sweep --images --debug-output NAME` writes the debug output beside each point's images;
/// `--debug-output` without `--images` is refused.
#[test]
fn a_sweep_writes_debug_outputs_with_its_images() {
    let out = out_dir("sweep-debug");
    let path = out.to_str().unwrap();
    let sweep = |extra: &[&str]| {
        let mut args = vec![
            "sweep",
            "--scene",
            "floating-sphere",
            "--vary",
            "pvsm.antialiasing=true",
            "--width",
            "48",
            "--height",
            "36",
            "--frames",
            "1",
        ];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", path]);
        ssm(&args)
    };
    let output = sweep(&["--images", "--debug-output", "blocker_depth"]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let written: Vec<PathBuf> = walk(&out.join("images")).into_iter().filter(|p| p.ends_with("blocker_depth.png")).collect();
    assert_eq!(written.len(), 1, "{written:?}");
    let refused = sweep(&["--debug-output", "blocker_depth"]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--images"), "{}", String::from_utf8_lossy(&refused.stderr));
    let _ = std::fs::remove_dir_all(&out);
}

/// Every file under `dir`, recursively.
fn walk(dir: &std::path::Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let path = entry.path();
        if path.is_dir() { files.extend(walk(&path)) } else { files.push(path) }
    }
    files
}

/// `--format json` gives scripts one JSON document on stdout: every technique with its
/// parameters and debug outputs, every built-in scene with its parameters, and compare's and
/// sweep's rows with their metrics (notes such as the scene's summary go to stderr).
#[test]
fn json_output_for_scripts() {
    let json = |args: &[&str]| -> serde_json::Value {
        let output = ssm(args);
        assert!(output.status.success(), "{args:?}: {}", String::from_utf8_lossy(&output.stderr));
        serde_json::from_slice(&output.stdout)
            .unwrap_or_else(|e| panic!("{args:?}: not one JSON document ({e}):\n{}", String::from_utf8_lossy(&output.stdout)))
    };
    let list = json(&["list", "--format", "json"]);
    let techniques = list["techniques"].as_array().unwrap();
    for info in ssm_bench::registry().unwrap().iter() {
        let entry = techniques.iter().find(|t| t["name"] == info.name).unwrap_or_else(|| panic!("{} missing", info.name));
        let params = entry["params"].as_array().unwrap();
        assert_eq!(params.len(), info.params.len(), "{}", info.name);
        for (spec, param) in info.params.iter().zip(params) {
            assert_eq!(
                (param["name"].as_str(), param["default"].as_str()),
                (Some(spec.name), Some(spec.default_value().to_string().as_str()))
            );
        }
        assert_eq!(entry["debug_outputs"].as_array().unwrap().len(), info.debug_outputs.len(), "{}", info.name);
    }
    let scenes = json(&["scenes", "--format", "json"]);
    for entry in ssm_scene::BUILTIN_SCENES {
        let scene = scenes.as_array().unwrap().iter().find(|s| s["name"] == entry.name).unwrap();
        assert!(scene["triangles"].as_u64().unwrap() > 0);
        assert_eq!(scene["params"].as_array().unwrap().len(), entry.params.len());
    }
    let out = out_dir("json-compare");
    let (first, _) = two_techniques();
    let small = ["--width", "48", "--height", "36", "--frames", "1", "--set", "reference.samples=4", "--format", "json"];
    let mut args = vec!["compare", "--scene", "parallel-square", "--technique", first.name, "--out", out.to_str().unwrap()];
    args.extend_from_slice(&small);
    let rows = json(&args);
    let row = &rows.as_array().unwrap()[0];
    assert_eq!(row["technique"], first.name);
    assert!(row["metrics"]["mae_penumbra"].as_f64().is_some_and(|v| (0.0..=1.0).contains(&v)), "{row}");
    let (vary, _) = common::knob_vary(first, 2);
    let mut args = vec!["sweep", "--scene", "parallel-square", "--vary", &vary, "--out", out.to_str().unwrap()];
    args.extend_from_slice(&small);
    let rows = json(&args);
    assert!(rows.as_array().unwrap().len() >= 2 && rows[0]["varied"].is_object(), "{rows}");
    let _ = std::fs::remove_dir_all(&out);
}

/// `compare --open` hands index.html to the system's opener (`xdg-open` here, a stand-in
/// that records what it was given), and a missing opener is a note, not a failure.
#[test]
fn compare_opens_its_report_when_asked() {
    let out = out_dir("open");
    let bin = out_dir("open-bin");
    std::fs::create_dir_all(&bin).unwrap();
    let opened = bin.join("opened.txt");
    let script = bin.join("xdg-open");
    std::fs::write(&script, format!("#!/bin/sh\necho \"$1\" > '{}'\n", opened.display())).unwrap();
    let mut permissions = std::fs::metadata(&script).unwrap().permissions();
    std::os::unix::fs::PermissionsExt::set_mode(&mut permissions, 0o755);
    std::fs::set_permissions(&script, permissions).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let (first, _) = two_techniques();
    let output = Command::new(env!("CARGO_BIN_EXE_ssm"))
        .env("PATH", &path)
        .args(["compare", "--scene", "parallel-square", "--technique", first.name, "--width", "48", "--height", "36", "--frames", "1"])
        .args(["--set", "reference.samples=4", "--open", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains(&format!("report: {}", out.join("index.html").display())), "the summary names the report:\n{stdout}");
    // The opener is spawned, not waited for.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while !opened.is_file() && std::time::Instant::now() < deadline {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let given = std::fs::read_to_string(&opened).unwrap_or_default();
    assert!(given.trim_end().ends_with("index.html"), "xdg-open was given `{given}`");
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&bin);
}
