//! `index.html`'s interactive viewer, driven in headless Chromium through
//! the DevTools protocol as a user would drive it: number keys switch the
//! technique, a held R flips to the ground truth, the pixel readout under
//! the pointer gives each technique's value (checked against the 16-bit
//! `visibility.png` files `ssm compare` wrote), the wheel zooms (the
//! screenshot changes), the view keys switch to the error maps, and a click
//! on a column sorts the metrics table. Chromium must be installed
//! (`scripts/install-deps.sh --for-tests`); without it the test fails.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use base64::Engine as _;
use serde_json::{Value, json};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

/// Kills the browser when dropped.
struct Reaped(Child);

impl Drop for Reaped {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A DevTools session on one page (flattened target sessions over the browser's socket).
struct Page {
    socket: WebSocket<MaybeTlsStream<TcpStream>>,
    session: String,
    next_id: u64,
}

impl Page {
    fn call_on(socket: &mut WebSocket<MaybeTlsStream<TcpStream>>, id: u64, session: Option<&str>, method: &str, params: Value) -> Value {
        let mut message = json!({ "id": id, "method": method, "params": params });
        if let Some(session) = session {
            message["sessionId"] = json!(session);
        }
        socket.send(Message::text(message.to_string())).expect("sending to Chromium");
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            assert!(Instant::now() < deadline, "no answer from Chromium to {method}");
            let Message::Text(text) = socket.read().expect("reading from Chromium") else { continue };
            let reply: Value = serde_json::from_str(&text).expect("Chromium sent JSON");
            if reply["id"] == json!(id) {
                assert!(reply.get("error").is_none(), "{method} failed: {}", reply["error"]);
                return reply["result"].clone();
            }
        }
    }

    fn call(&mut self, method: &str, params: Value) -> Value {
        self.next_id += 1;
        Self::call_on(&mut self.socket, self.next_id, Some(&self.session), method, params)
    }

    /// Evaluates `expression` in the page and returns its value.
    fn eval(&mut self, expression: &str) -> Value {
        let result = self.call("Runtime.evaluate", json!({ "expression": expression, "returnByValue": true }));
        assert!(result.get("exceptionDetails").is_none(), "`{expression}` threw: {}", result["exceptionDetails"]);
        result["result"]["value"].clone()
    }

    fn wait_for(&mut self, expression: &str) {
        let deadline = Instant::now() + Duration::from_secs(60);
        while self.eval(expression) != json!(true) {
            assert!(Instant::now() < deadline, "`{expression}` never became true");
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    fn key(&mut self, kind: &str, key: &str) {
        let code = if key.chars().all(|c| c.is_ascii_digit()) { format!("Digit{key}") } else { format!("Key{}", key.to_uppercase()) };
        let virtual_key = i64::from(key.to_uppercase().as_bytes()[0]);
        let mut params = json!({ "type": kind, "key": key, "code": code, "windowsVirtualKeyCode": virtual_key });
        if kind == "keyDown" {
            params["text"] = json!(key);
        }
        self.call("Input.dispatchKeyEvent", params);
    }

    fn press(&mut self, key: &str) {
        self.key("keyDown", key);
        self.key("keyUp", key);
    }

    fn mouse(&mut self, params: Value) {
        self.call("Input.dispatchMouseEvent", params);
    }

    fn body(&mut self, attribute: &str) -> String {
        self.eval(&format!("document.body.dataset.{attribute}")).as_str().unwrap_or_default().to_owned()
    }

    /// A screenshot of the page's `rect` (CSS pixels), decoded.
    fn screenshot(&mut self, rect: (f64, f64, f64, f64)) -> image::RgbImage {
        let clip = json!({ "x": rect.0, "y": rect.1, "width": rect.2, "height": rect.3, "scale": 1 });
        let result = self.call("Page.captureScreenshot", json!({ "format": "png", "clip": clip }));
        let bytes = base64::engine::general_purpose::STANDARD.decode(result["data"].as_str().unwrap()).unwrap();
        image::load_from_memory(&bytes).unwrap().to_rgb8()
    }
}

/// Starts headless Chromium with DevTools on a free port and opens `page` in a new target.
fn open(url: &str, profile: &Path) -> (Reaped, Page) {
    let mut browser = Command::new(common::chromium_binary())
        .args(common::OFFLINE_FLAGS)
        .args(["--remote-debugging-port=0", "--window-size=1400,1000"])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg("about:blank")
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .expect("starting Chromium");
    let stderr = browser.stderr.take().unwrap();
    let browser = Reaped(browser);
    // Chromium prints its DevTools address on stderr: "DevTools listening on ws://...".
    let address = BufReader::new(stderr)
        .lines()
        .map_while(Result::ok)
        .find_map(|line| line.split_once("DevTools listening on ").map(|(_, url)| url.trim().to_owned()))
        .expect("Chromium did not print its DevTools address");
    let (mut socket, _) = tungstenite::connect(address.as_str()).expect("connecting to Chromium's DevTools");
    let target = Page::call_on(&mut socket, 1, None, "Target.createTarget", json!({ "url": "about:blank" }));
    let attached = Page::call_on(&mut socket, 2, None, "Target.attachToTarget", json!({ "targetId": target["targetId"], "flatten": true }));
    let session = attached["sessionId"].as_str().expect("a session id").to_owned();
    let mut page = Page { socket, session, next_id: 10 };
    page.call("Page.enable", json!({}));
    page.call("Emulation.setDeviceMetricsOverride", json!({ "width": 1400, "height": 1000, "deviceScaleFactor": 1, "mobile": false }));
    page.call("Page.navigate", json!({ "url": url }));
    (browser, page)
}

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssm-viewer-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The 16-bit visibility `ssm compare` wrote for `technique`, at pixel (`x`, `y`).
fn written_visibility(out: &Path, technique: &str, x: u32, y: u32) -> f64 {
    let picture = image::open(out.join(technique).join("visibility.png")).unwrap().to_luma16();
    f64::from(picture.get_pixel(x, y)[0]) / 65535.0
}

#[test]
fn the_comparison_page_switches_flips_reads_out_zooms_and_sorts_in_a_browser() {
    let out = scratch("compare");
    let cache = scratch("cache");
    let status = Command::new(env!("CARGO_BIN_EXE_ssm"))
        .env("SSM_CACHE_DIR", &cache)
        .args(["compare", "--scene", "parallel-square", "--technique", "hard,pcss", "--width", "96", "--height", "72"])
        .args(["--frames", "1", "--set", "reference.samples=8", "--count-work", "--out"])
        .arg(&out)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success(), "ssm compare failed");
    assert!(out.join("pcss/flip.png").is_file() && out.join("viewer-data.js").is_file() && out.join("viewer.js").is_file());

    let url = format!("file://{}", out.join("index.html").display());
    let (_browser, mut page) = open(&url, &scratch("profile"));
    page.wait_for("document.readyState === 'complete' && document.body !== null && document.body.dataset.viewerReady === '1'");
    assert_eq!(page.body("technique"), "hard", "the first technique is shown first");

    // Number keys switch technique.
    page.press("2");
    assert_eq!(page.body("technique"), "pcss");
    // Holding R flips to the ground truth; letting go flips back.
    page.key("keyDown", "r");
    assert_eq!(page.body("technique"), "reference");
    page.key("keyUp", "r");
    assert_eq!(page.body("technique"), "pcss");

    // The readout under the pointer: every technique's value at that pixel, as written to disk.
    let rect = page.eval("(() => { const c = document.getElementById('viewer-canvas'); const r = c.getBoundingClientRect(); return [r.left + c.clientLeft, r.top + c.clientTop, c.clientWidth, c.clientHeight]; })()");
    let rect: Vec<f64> = rect.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert_eq!((rect[2], rect[3]), (96.0, 72.0), "the canvas is the image, pixel for pixel");
    // Inside the shadow's penumbra of parallel-square, where the techniques disagree.
    let (px, py) = (rect[0] + 30.5, rect[1] + 40.5);
    page.mouse(json!({ "type": "mouseMoved", "x": px, "y": py }));
    // Browsers round event coordinates to whole CSS pixels, and the canvas may sit at a fraction: within one pixel.
    let pixel = page.eval("document.getElementById('readout').dataset.pixel");
    let (x, y) =
        pixel.as_str().and_then(|p| p.split_once(',')).map(|(x, y)| (x.parse::<u32>().unwrap(), y.parse::<u32>().unwrap())).unwrap();
    assert!(x.abs_diff(30) <= 1 && y.abs_diff(40) <= 1, "the readout is at ({x}, {y}), not under the pointer at (30.5, 40.5)");
    for technique in ["reference", "hard", "pcss"] {
        let shown = page.eval(&format!("document.querySelector('#readout span[data-technique=\"{technique}\"]').textContent"));
        let shown = shown.as_str().unwrap();
        let value: f64 = shown.split_whitespace().nth(1).unwrap().parse().unwrap();
        let written = written_visibility(&out, technique, x, y);
        assert!((value - written).abs() < 2e-4, "{technique}: readout {value}, visibility.png {written}");
    }

    // The wheel zooms about the pointer, without smoothing: the picture changes.
    let region = (rect[0], rect[1], rect[2], rect[3]);
    let before = page.screenshot(region);
    page.mouse(json!({ "type": "mouseWheel", "x": px, "y": py, "deltaX": 0, "deltaY": -400 }));
    page.wait_for("Number(document.body.dataset.zoom) > 2");
    let after = page.screenshot(region);
    let changed = before.pixels().zip(after.pixels()).filter(|(a, b)| a != b).count();
    assert!(changed > 500, "zooming changed only {changed} pixels");
    // The pixel under the pointer stays under it.
    assert_eq!(page.eval("document.getElementById('readout').dataset.pixel"), pixel);
    // Zoomed in, a screen pixel repeats its image pixel: neighbours are equal (no smoothing).
    let (cx, cy) = (30, 40);
    assert_eq!(after.get_pixel(cx, cy), after.get_pixel(cx + 1, cy), "zoomed pixels are blocks, not interpolated");

    // The view keys: hard shadows' signed error map has the diverging colours (red or blue in the penumbra).
    page.press("0");
    page.press("1");
    page.press("e");
    assert_eq!(page.body("mode"), "signed");
    let error_map = page.screenshot(region);
    let coloured = error_map.pixels().filter(|p| p[0].abs_diff(p[2]) > 60).count();
    assert!(coloured > 20, "the signed error map has no coloured pixels ({coloured})");
    page.press("f");
    assert_eq!(page.body("mode"), "flip");

    // The table sorts by a column (both ways), and a click on a row shows that technique.
    page.eval("document.querySelector('#metrics th[data-key=\"mae_penumbra\"]').click()");
    let order = page.eval("Array.from(document.querySelectorAll('#metrics tbody tr')).map((r) => Number(r.cells[3].textContent))");
    let order: Vec<f64> = order.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert!(order.len() == 2 && order[0] <= order[1], "ascending: {order:?}");
    page.eval("document.querySelector('#metrics th[data-key=\"mae_penumbra\"]').click()");
    let first = page.eval("Number(document.querySelector('#metrics tbody tr').cells[3].textContent)");
    assert_eq!(first.as_f64().unwrap(), order[1], "a second click sorts descending");
    page.eval("document.querySelector('#metrics tbody tr[data-technique=\"hard\"]').click()");
    assert_eq!(page.body("technique"), "hard");

    // W switches the table and the per-pass chart from milliseconds to the counted work (the
    // chart's texel reads or, as chosen, invocations per pass), and back.
    assert_eq!(page.body("units"), "ms");
    let chart = "document.getElementById('pass-chart').getAttribute('src')";
    assert_eq!(page.eval(chart), "passes.svg");
    page.press("w");
    assert_eq!(page.body("units"), "work");
    let keys = page.eval("Array.from(document.querySelectorAll('#metrics th')).map((h) => h.dataset.key).join(',')");
    let keys = keys.as_str().unwrap();
    assert!(keys.contains("fragment_invocations") && keys.contains("texel_reads") && !keys.contains("gpu_ms"), "{keys}");
    // lavapipe has pipeline statistics: hard's fragments are counted (the fourth column).
    let fragments = page.eval("document.querySelector('#metrics tbody tr[data-technique=\"hard\"]').cells[3].textContent");
    assert!(fragments.as_str().and_then(|f| f.parse::<u64>().ok()).is_some_and(|f| f > 0), "hard's fragments: {fragments}");
    assert!(page.eval(chart).as_str().is_some_and(|src| src.starts_with("passes-") && src != "passes.svg"), "{}", page.eval(chart));
    page.eval("document.querySelector('#viewer-units button[data-chart=\"invocations\"]').click()");
    assert_eq!(page.eval(chart), "passes-invocations.svg");
    page.press("w");
    assert_eq!((page.body("units"), page.eval(chart)), ("ms".into(), json!("passes.svg")));

    // The view lives in the address's fragment: a link opens the page on it.
    let fragment = page.eval("window.location.hash");
    assert!(fragment.as_str().is_some_and(|f| f.contains("technique=hard") && f.contains("mode=flip")), "fragment {fragment}");
    // Away and back, so that the link is a fresh load (a fragment alone would not reload the page).
    page.call("Page.navigate", json!({ "url": "about:blank" }));
    page.wait_for("window.location.href === 'about:blank'");
    page.call("Page.navigate", json!({ "url": format!("{url}#technique=pcss&mode=signed&zoom=4&x=10&y=20&units=work&chart=invocations") }));
    page.wait_for(
        "window.location.protocol === 'file:' && document.readyState === 'complete' && document.body !== null && document.body.dataset.viewerReady === '1'",
    );
    assert_eq!((page.body("technique"), page.body("mode"), page.body("zoom")), ("pcss".into(), "signed".into(), "4".into()));
    assert_eq!((page.body("units"), page.eval(chart)), ("work".into(), json!("passes-invocations.svg")));
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&cache);
}
