//! `ssm view` in a real window: a virtual X server (Xvfb), keys and mouse
//! from xdotool (XTEST, as a user's), screenshots of the whole screen by
//! ImageMagick's `import`. The window must show exactly what `ssm render`
//! shades for the technique selected, switch technique on a number key,
//! show the visibility on V, orbit the camera when the image is dragged, and
//! on W count the selected technique's work once per technique, not every frame.
//!
//! The tools come from `scripts/install-deps.sh --for-tests`; without them
//! the test fails, saying so, rather than skipping.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

const SSM: &str = env!("CARGO_BIN_EXE_ssm");
const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

/// Kills the child when dropped, so a failing assertion leaves no X server or window behind.
struct Reaped(Child);

impl Drop for Reaped {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn require(tool: &str, package: &str) {
    let found = Command::new("sh").args(["-c", &format!("command -v {tool}")]).output().is_ok_and(|o| o.status.success());
    assert!(found, "`{tool}` is missing: `scripts/install-deps.sh --for-tests` installs it (Debian package {package})");
}

/// The image announced on the viewer's stdout: `... image X,Y WxH`.
fn image_origin(line: &str) -> (u32, u32) {
    let place = line.split(" image ").nth(1).unwrap_or_else(|| panic!("no image place in `{line}`"));
    let (xy, _) = place.split_once(' ').unwrap_or_else(|| panic!("bad image place in `{line}`"));
    let (x, y) = xy.split_once(',').unwrap_or_else(|| panic!("bad image place in `{line}`"));
    (x.parse().unwrap_or_else(|_| panic!("bad x in `{line}`")), y.parse().unwrap_or_else(|_| panic!("bad y in `{line}`")))
}

/// Waits for a stdout line of the viewer containing `needle`; on failure shows the viewer's stderr (`log`).
fn wait_for(lines: &Receiver<String>, needle: &str, timeout: Duration, log: &Path) -> String {
    lines_until(lines, needle, timeout, log).pop().expect("the line found")
}

/// The viewer's stdout lines up to the first containing `needle`, that one last.
fn lines_until(lines: &Receiver<String>, needle: &str, timeout: Duration, log: &Path) -> Vec<String> {
    let deadline = Instant::now() + timeout;
    let mut seen = Vec::new();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match lines.recv_timeout(left) {
            Ok(line) if line.contains(needle) => {
                seen.push(line);
                return seen;
            }
            Ok(line) => seen.push(line),
            Err(error) => {
                let stderr = std::fs::read_to_string(log).unwrap_or_default();
                panic!("ssm view did not print `{needle}` within {timeout:?} ({error}); its stderr:\n{stderr}");
            }
        }
    }
}

fn xdotool(display: &str, args: &[&str]) {
    let status = Command::new("xdotool").env("DISPLAY", display).args(args).status().expect("running xdotool");
    assert!(status.success(), "xdotool {args:?} failed");
}

/// The window's image, cut out of a screenshot of the whole screen.
fn screenshot(display: &str, file: &Path, origin: (u32, u32)) -> image::RgbImage {
    // The frame was presented before it was announced; give the X server a moment to show it.
    std::thread::sleep(Duration::from_millis(500));
    let status = Command::new("import")
        .env("DISPLAY", display)
        .args(["-window", "root"])
        .arg(format!("png:{}", file.display()))
        .status()
        .expect("running import");
    assert!(status.success(), "import failed");
    let screen = image::open(file).expect("reading the screenshot").to_rgb8();
    image::imageops::crop_imm(&screen, origin.0, origin.1, WIDTH, HEIGHT).to_image()
}

/// Screenshots until the window's image is within a level of `expected` (the X server may show a
/// presented frame late on a loaded machine), for at most ten seconds; the last one.
fn screenshot_showing(display: &str, file: &Path, origin: (u32, u32), expected: &image::RgbImage) -> image::RgbImage {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let shown = screenshot(display, file, origin);
        if mean_difference(&shown, expected) <= 1.0 || Instant::now() > deadline {
            return shown;
        }
    }
}

/// Mean absolute difference per channel, in 8-bit levels.
fn mean_difference(a: &image::RgbImage, b: &image::RgbImage) -> f64 {
    let total: u64 = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| u64::from(x.abs_diff(*y))).sum();
    total as f64 / a.as_raw().len() as f64
}

fn shaded(dir: &Path, technique: &str) -> image::RgbImage {
    image::open(dir.join(technique).join("shaded.png")).expect("reading ssm render's shaded.png").to_rgb8()
}

/// Asserts the window showed `expected`; writes `-actual` and `-diff` images beside it otherwise.
fn assert_shows(out: &Path, name: &str, actual: &image::RgbImage, expected: &image::RgbImage) {
    let difference = mean_difference(actual, expected);
    if difference > 1.0 {
        actual.save(out.join(format!("{name}-actual.png"))).expect("writing the actual image");
        expected.save(out.join(format!("{name}-expected.png"))).expect("writing the expected image");
        let diff = image::RgbImage::from_fn(WIDTH, HEIGHT, |x, y| {
            let (a, e) = (actual.get_pixel(x, y), expected.get_pixel(x, y));
            image::Rgb([0, 1, 2].map(|c| a[c].abs_diff(e[c]).saturating_mul(8)))
        });
        diff.save(out.join(format!("{name}-diff.png"))).expect("writing the difference image");
        panic!("the window's image differs from `ssm render`'s {name} by {difference:.2} levels on average (images in {})", out.display());
    }
}

#[test]
fn view_shows_the_selected_technique_switches_on_number_keys_and_orbits_on_drag() {
    require("Xvfb", "xvfb");
    require("xdotool", "xdotool");
    require("import", "imagemagick");
    let out: PathBuf = std::env::temp_dir().join(format!("ssm-view-test-{}", std::process::id()));
    std::fs::create_dir_all(&out).expect("creating the output folder");
    let runtime = out.join("runtime");
    std::fs::create_dir_all(&runtime).expect("creating XDG_RUNTIME_DIR");

    // What the window must show: the same scene, techniques and size through `ssm render`.
    let rendered = out.join("render");
    let status = Command::new(SSM)
        .args(["render", "--scene", "parallel-square", "--technique", "hard,pcss", "--width", &WIDTH.to_string()])
        .args(["--height", &HEIGHT.to_string(), "--out"])
        .arg(&rendered)
        .env("XDG_RUNTIME_DIR", &runtime)
        .stdout(Stdio::null())
        .status()
        .expect("running ssm render");
    assert!(status.success(), "ssm render failed");

    // A display no other X server holds (its socket and lock file absent).
    let number = (40 + std::process::id() % 400..)
        .find(|n| !Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() && !Path::new(&format!("/tmp/.X{n}-lock")).exists())
        .expect("a free display number");
    let display = format!(":{number}");
    let _server = Reaped(
        Command::new("Xvfb")
            .args([display.as_str(), "-screen", "0", "800x600x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("starting Xvfb"),
    );
    let socket = PathBuf::from(format!("/tmp/.X11-unix/X{number}"));
    let started = Instant::now();
    while !socket.exists() {
        assert!(started.elapsed() < Duration::from_secs(20), "Xvfb did not open {display}");
        std::thread::sleep(Duration::from_millis(100));
    }

    let mut viewer = Command::new(SSM);
    viewer
        .args(["view", "--scene", "parallel-square", "--technique", "hard,pcss", "--width", &WIDTH.to_string()])
        .args(["--height", &HEIGHT.to_string()])
        .env("DISPLAY", &display)
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", &runtime)
        .stdout(Stdio::piped())
        .stderr(std::fs::File::create(out.join("viewer-stderr.txt")).expect("creating the viewer's log"));
    let mut viewer = Reaped(viewer.spawn().expect("starting ssm view"));
    let stdout = viewer.0.stdout.take().expect("the viewer's stdout");
    let (send, lines) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if send.send(line).is_err() {
                break;
            }
        }
    });

    let log = out.join("viewer-stderr.txt");
    let line = wait_for(&lines, "showing hard", Duration::from_secs(120), &log);
    let origin = image_origin(&line);
    let expected_hard = shaded(&rendered, "hard");
    let shown_hard = screenshot_showing(&display, &out.join("screen-hard.png"), origin, &expected_hard);
    assert_shows(&out, "hard", &shown_hard, &expected_hard);

    xdotool(&display, &["search", "--sync", "--name", "ssm view", "windowfocus", "--sync", "key", "2"]);
    let line = wait_for(&lines, "showing pcss", Duration::from_secs(120), &log);
    let expected_pcss = shaded(&rendered, "pcss");
    let shown_pcss = screenshot_showing(&display, &out.join("screen-pcss.png"), image_origin(&line), &expected_pcss);
    assert_shows(&out, "pcss", &shown_pcss, &expected_pcss);
    // Not one picture twice: hard and soft shadows differ visibly.
    let between = mean_difference(&shown_hard, &shown_pcss);
    assert!(between > 0.5, "hard and pcss look alike in the window ({between:.2} levels)");

    // V shows the visibility: `ssm render`'s 16-bit visibility.png, in 8 bits.
    xdotool(&display, &["key", "v"]);
    let line = wait_for(&lines, "view visibility", Duration::from_secs(120), &log);
    let written = image::open(rendered.join("pcss").join("visibility.png")).expect("reading visibility.png").to_luma16();
    let expected = image::RgbImage::from_fn(WIDTH, HEIGHT, |x, y| {
        let level = (f64::from(written.get_pixel(x, y)[0]) / 65535.0 * 255.0).round() as u8;
        image::Rgb([level; 3])
    });
    let shown_visibility = screenshot_showing(&display, &out.join("screen-pcss-visibility.png"), image_origin(&line), &expected);
    assert_shows(&out, "pcss-visibility", &shown_visibility, &expected);
    let shown_pcss = shown_visibility;

    // Drag across the image, a step per frame, as a hand would: the camera orbits.
    let (x, y) = (origin.0 + WIDTH / 2, origin.1 + HEIGHT / 2);
    let mut drag = vec!["mousemove".to_string(), x.to_string(), y.to_string(), "mousedown".into(), "1".into()];
    for step in 1..=4 {
        drag.extend(["sleep".into(), "0.3".into(), "mousemove".into(), (x + 12 * step).to_string(), y.to_string()]);
    }
    drag.extend(["sleep".into(), "0.3".into(), "mouseup".into(), "1".into()]);
    xdotool(&display, &drag.iter().map(String::as_str).collect::<Vec<_>>());
    let line = wait_for(&lines, "view visibility", Duration::from_secs(120), &log);
    // Let the frames of the rest of the drag arrive.
    std::thread::sleep(Duration::from_secs(3));
    while lines.try_recv().is_ok() {}
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut moved = 0.0;
    while moved <= 2.0 && Instant::now() < deadline {
        let orbited = screenshot(&display, &out.join("screen-orbited.png"), image_origin(&line));
        moved = mean_difference(&orbited, &shown_pcss);
    }
    assert!(moved > 2.0, "dragging the image did not move the camera ({moved:.2} levels)");

    // W: the selected technique's work per pass, counted in one extra frame (announced), with
    // invocations from pipeline statistics (lavapipe has them); a later frame of the same
    // technique and settings counts nothing; another technique is counted when shown.
    xdotool(&display, &["key", "w"]);
    let counted = wait_for(&lines, "ssm view: counted pcss [", Duration::from_secs(120), &log);
    let invocations = counted.split(" invocations ").nth(1).and_then(|rest| rest.split(' ').next()).unwrap_or_default();
    assert!(invocations.parse::<u64>().is_ok_and(|n| n > 0), "no invocations counted: `{counted}`");
    xdotool(&display, &["key", "s"]);
    let frames = lines_until(&lines, "view shaded", Duration::from_secs(120), &log);
    assert!(!frames.iter().any(|l| l.contains("ssm view: counted")), "counted again at the same settings: {frames:#?}");
    xdotool(&display, &["key", "1"]);
    let frames = lines_until(&lines, "showing hard", Duration::from_secs(120), &log);
    assert!(frames.iter().any(|l| l.starts_with("ssm view: counted hard [")), "hard not counted when shown: {frames:#?}");
    assert!(viewer.0.try_wait().expect("polling the viewer").is_none(), "ssm view exited");
    let _ = std::fs::remove_dir_all(&out);
}
