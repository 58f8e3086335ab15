//! `index.html`: the interactive viewer (`viewer.js` over `viewer-data.js`: [`viewer_data`]), the
//! table, the per-pass charts, the counted work and every technique's images ([`html_report`]);
//! readable offline.

use std::fmt::Write as _;

use ssm_core::FrameWork;

use super::work::{FRAME_HEADER, HOW_COUNTED, PASS_HEADER, frame_table, notes, pass_table, short};
use super::{ReportContext, TABLE_HEADER, beyond_frame_note, counted, light_suffix, pixels_of, table_cells};
use crate::data::json::finite;
use crate::data::work::{GROUND_TRUTH_NOT_COUNTED, Totals};
use crate::data::{Row, visibility_stem};

/// The interactive viewer's script (`ssm-bench/assets/viewer.js`), written beside `index.html` as `viewer.js`.
pub const VIEWER_SCRIPT: &str = include_str!("../../assets/viewer.js");

/// One image set the interactive viewer shows: a technique (or the ground truth) and its visibility per light.
pub struct ViewerImages<'a> {
    /// The technique's name (its folder in the report).
    pub technique: &'a str,
    /// Visibility per light, row-major, in `[0, 1]`.
    pub visibility: &'a [Vec<f32>],
    /// Whether `<technique>/flip.png` was written (every technique but the ground truth).
    pub has_flip: bool,
}

/// `viewer-data.js`: what the interactive viewer of `index.html` reads, as
/// one script that sets `window.SSM_DATA` (a page opened from disk may load
/// scripts, but not read back the pixels of its own images): the size, the
/// covered pixels, each technique's visibility per light as 16-bit values
/// (base64, little-endian), the paths of its shaded and FLIP images, and the
/// metrics table's rows. `images` starts with the ground truth.
#[must_use]
pub fn viewer_data(
    reference_name: &str,
    (width, height): (u32, u32),
    coverage: &[bool],
    images: &[ViewerImages<'_>],
    rows: &[Row],
) -> String {
    use base64::Engine as _;
    let encode = |bytes: &[u8]| base64::engine::general_purpose::STANDARD.encode(bytes);
    let quantised =
        |values: &[f32]| -> Vec<u8> { values.iter().flat_map(|v| ((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_le_bytes()).collect() };
    let covered: Vec<u8> = coverage.iter().map(|&c| u8::from(c)).collect();
    let mut image_sets = serde_json::Map::new();
    for set in images {
        image_sets.insert(
            set.technique.to_owned(),
            serde_json::json!({
                "visibility": set.visibility.iter().map(|v| encode(&quantised(v))).collect::<Vec<_>>(),
                "shaded": format!("{}/shaded.png", set.technique),
                "flip": set.has_flip.then(|| format!("{}/flip.png", set.technique)),
            }),
        );
    }
    let table: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            let m = &r.metrics;
            let mut row = serde_json::json!({
                "technique": r.technique,
                "light": r.light.map_or_else(|| "all".to_owned(), |l| l.to_string()),
                "gpu_ms": r.gpu_ms_median.map_or(serde_json::Value::Null, finite),
                "mae": finite(m.mae),
                "truth_noise": m.truth_noise.map_or(serde_json::Value::Null, finite),
                "mae_penumbra": finite(m.mae_penumbra),
                "rmse": finite(m.rmse),
                "ssim": finite(m.ssim),
                "psnr": finite(m.psnr),
                "umbra_leak": finite(m.umbra_leak),
                "frac_over_0_05": finite(m.frac_over_0_05),
                "flip": finite(r.flip),
                "passes": r.passes.iter().map(|(name, ms)| format!("{name} {ms:.2}")).collect::<Vec<_>>().join(", "),
            });
            if let Some(work) = &r.work {
                let totals = Totals::of(work);
                let counts = [
                    ("vertex_invocations", totals.vertex_invocations),
                    ("fragment_invocations", totals.fragment_invocations),
                    ("compute_invocations", totals.compute_invocations),
                    ("texel_reads", totals.texel_reads),
                    ("read_bytes", totals.read_bytes),
                    ("atomics", totals.atomics),
                    ("target_bytes", Some(totals.target_bytes)),
                    ("storage_bytes", totals.storage_bytes),
                ];
                for (key, count) in counts {
                    row[key] = count.map_or(serde_json::Value::Null, |n| serde_json::json!(n));
                }
                row["passes_work"] = serde_json::json!(pass_work_summary(work));
            }
            row
        })
        .collect();
    let lights = images.first().map_or(1, |set| set.visibility.len());
    let data = serde_json::json!({
        "width": width,
        "height": height,
        "lights": lights,
        "reference": reference_name,
        "techniques": images.iter().map(|set| set.technique).collect::<Vec<_>>(),
        "covered": encode(&covered),
        "images": image_sets,
        "rows": table,
        "columns": [
            ["technique", "technique"], ["light", "light"], ["gpu_ms", "GPU ms"], ["mae", "MAE"],
            ["truth_noise", "± truth"], ["mae_penumbra", "MAE pen."], ["rmse", "RMSE"], ["ssim", "SSIM"], ["psnr", "PSNR dB"], ["umbra_leak", "umbra leak"],
            ["frac_over_0_05", "> 0.05"], ["flip", "FLIP"], ["passes", "passes, ms"],
        ],
        // The table's columns when it shows counted work instead of milliseconds (`null`: not counted).
        "work_columns": rows.iter().any(|r| r.work.is_some()).then(|| serde_json::json!([
            ["technique", "technique"], ["light", "light"], ["vertex_invocations", "vertex inv."],
            ["fragment_invocations", "fragment inv."], ["compute_invocations", "compute inv."], ["texel_reads", "texel reads"],
            ["read_bytes", "bytes read"], ["atomics", "atomics"], ["target_bytes", "target bytes"], ["storage_bytes", "storage bytes"],
            ["mae", "MAE"], ["passes_work", "passes: reads, invocations"],
        ])),
    });
    format!("// Written by ssm compare: the data of index.html's viewer (viewer.js).\nwindow.SSM_DATA = {data};\n")
}

/// Each pass of `work` in a few words for the viewer's table: its texel reads (`?` where the
/// shaders do not count) and its invocations (vertex, fragment and compute).
fn pass_work_summary(work: &FrameWork) -> String {
    work.passes
        .iter()
        .map(|pass| {
            let totals = Totals::of_passes(work, std::slice::from_ref(pass));
            let count = |n: Option<u64>| n.map_or_else(|| "?".to_owned(), |n| short(n as f64));
            format!("{} {} reads, {} inv.", pass.name, count(totals.texel_reads), count(totals.invocations()))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The interactive viewer's part of `index.html`: controls, canvas, readout and table (filled by `viewer.js`).
fn viewer_section((width, height): (u32, u32)) -> String {
    // The readout wraps within the image's width (and its border), so that the table fits beside it.
    let frame = width + 2;
    format!(
        "<section id=\"viewer\">\n<h2>Compare</h2>\n<p class=\"legend\">Keys: <kbd>1</kbd>–<kbd>9</kbd> a technique (or click it), hold <kbd>R</kbd> (or hover its button) for the ground truth; views <kbd>S</kbd> shaded, <kbd>V</kbd> visibility, <kbd>E</kbd> signed error, <kbd>A</kbd> absolute error, <kbd>F</kbd> FLIP; wheel: zoom to the pixel, drag: pan, <kbd>0</kbd>: reset; <kbd>W</kbd>: the table and the per-pass chart in milliseconds or counted work (with <code>--count-work</code>). Click a column to sort, a row to show it.</p>\n<div id=\"viewer-techniques\" class=\"bar\"></div>\n<div id=\"viewer-modes\" class=\"bar\"></div>\n<div id=\"viewer-units\" class=\"bar\"></div>\n<div class=\"bar\"><label>light <select id=\"viewer-light\"></select></label> <label>exposure (shaded) <input id=\"viewer-exposure\" type=\"range\" min=\"-4\" max=\"4\" step=\"0.1\" value=\"0\"> <span id=\"viewer-exposure-value\">+0.0 EV</span></label></div>\n<div class=\"viewer-row\">\n<div style=\"width: {frame}px\">\n<canvas id=\"viewer-canvas\" width=\"{width}\" height=\"{height}\"></canvas>\n<div id=\"viewer-scale\" class=\"legend\"></div>\n<div id=\"readout\">move the pointer over the image for every technique's value at that pixel</div>\n</div>\n<table id=\"metrics\"></table>\n</div>\n</section>\n"
    )
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// `index.html`'s section on the counted work: [`markdown_work`]'s tables and notes, and the
/// per-pass work charts.
fn html_work(context: &ReportContext<'_>, rows: &[Row]) -> String {
    if !context.count_work {
        return String::new();
    }
    let techniques = counted(rows);
    let table = |id: &str, header: &[&str], cells: Vec<[String; 13]>| {
        let mut out = format!("<table id=\"{id}\">\n<tr>");
        for name in header {
            let _ = write!(out, "<th>{}</th>", escape(name));
        }
        out += "</tr>\n";
        for row in cells {
            out += "<tr>";
            for cell in row {
                let _ = write!(out, "<td>{}</td>", escape(&cell));
            }
            out += "</tr>\n";
        }
        out + "</table>\n"
    };
    let mut out =
        format!("<h2 id=\"counted-work\">Counted work</h2>\n<p class=\"legend\">{}</p>\n<p>Per frame:</p>\n", escape(HOW_COUNTED));
    out += &table("work-frames", &FRAME_HEADER, frame_table(&techniques, pixels_of(rows)));
    out += "<p>Per pass:</p>\n";
    out += &table("work-passes", &PASS_HEADER, pass_table(&techniques));
    for note in notes(&techniques) {
        let _ = writeln!(out, "<p>{}</p>", escape(&note));
    }
    let _ = writeln!(out, "<p>Ground truth (<code>reference</code>): {}.</p>", GROUND_TRUTH_NOT_COUNTED);
    out
}

/// `index.html`: the interactive viewer (`viewer.js` over `viewer-data.js`,
/// both beside it: every technique and the ground truth in one zoomable
/// frame, switched by keys, with several views, a per-pixel readout and a
/// sortable metrics table), then the table and, per technique, the shaded
/// image, the visibility and the error heat map side by side; readable
/// offline (images and scripts by relative path, nothing from elsewhere). A
/// small script records on `<body data-images-loaded>` how many images
/// loaded, for tests.
#[must_use]
pub fn html_report(context: &ReportContext<'_>, rows: &[Row], reference_name: &str) -> String {
    let mut out = String::from(
        "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>ssm compare</title>\n<style>\nbody { font-family: sans-serif; margin: 1.5em; color: #222; }\ntable { border-collapse: collapse; font-size: 0.9em; }\nth, td { border: 1px solid #ccc; padding: 0.3em 0.6em; text-align: right; }\nth:first-child, th:nth-child(2), td:first-child, td:nth-child(2) { text-align: left; }\nfigure { margin: 1.2em 0; }\nfigure img { width: 32%; image-rendering: pixelated; border: 1px solid #ddd; vertical-align: top; }\n.overlay { position: relative; display: inline-block; width: 32%; vertical-align: top; }\n.overlay img { width: 100%; }\n.overlay img + img { position: absolute; left: 0; top: 0; opacity: 0.5; }\n.legend { font-size: 0.9em; color: #555; }\n.bar { margin: 0.3em 0; }\n.bar button { margin-right: 0.3em; }\nbutton.selected, #metrics tr.selected { background: #1d5fa0; color: white; }\n#viewer-canvas { display: block; image-rendering: pixelated; cursor: crosshair; border: 1px solid #888; }\n#readout { font-family: monospace; margin: 0.4em 0; min-height: 2.6em; }\n#readout .selected { font-weight: bold; }\n#metrics th { cursor: pointer; }\n#metrics th[data-sorted=\"ascending\"]::after { content: \" ▲\"; }\n#metrics th[data-sorted=\"descending\"]::after { content: \" ▼\"; }\n#metrics tbody tr { cursor: pointer; }\n#metrics td:last-child { text-align: left; font-size: 0.85em; }\n.viewer-row { display: flex; gap: 1.5em; align-items: flex-start; flex-wrap: wrap; }\n.viewer-row > div { max-width: 100%; flex: none; }\n.viewer-row > table { flex: 1 1 24em; }\n</style>\n</head>\n<body data-images-loaded=\"0\">\n",
    );
    let _ = writeln!(
        out,
        "<h1>ssm compare: <code>{}</code></h1>\n<p>{}×{}, median of {} frames after one warm-up, on {}. Ground truth: <code>{}</code> [{}]: {}.</p>",
        escape(context.scene),
        context.size.0,
        context.size.1,
        context.frames,
        escape(context.adapter),
        escape(reference_name),
        escape(context.reference_params),
        escape(context.reference_cost)
    );
    if let Some(note) = beyond_frame_note(rows) {
        let _ = writeln!(out, "<p>{}</p>", escape(&note));
    }
    out += &viewer_section(context.size);
    out += "<h2>All images</h2>\n<table>\n<tr>";
    for header in TABLE_HEADER {
        let _ = write!(out, "<th>{}</th>", escape(header));
    }
    out += "</tr>\n";
    for r in rows {
        let cells = table_cells(r);
        let _ = write!(out, "<tr><td><code>{}</code>{}</td>", escape(&cells[0]), escape(&light_suffix(r)));
        for cell in &cells[1..] {
            let _ = write!(out, "<td>{}</td>", escape(cell));
        }
        out += "</tr>\n";
    }
    out += "</table>\n";
    for (name, why) in context.skipped {
        let _ = writeln!(out, "<p>Not run: <code>{}</code>: {}</p>", escape(name), escape(why));
    }
    // The viewer's milliseconds/work switch changes this image's source to a work chart's
    // (`data-reads`, `data-invocations`); without timestamps only the work charts exist.
    if let Some(chart) = context.pass_chart.or_else(|| context.work_charts.first().map(|(_, file)| *file)) {
        let sources: String = context
            .pass_chart
            .map(|ms| ("ms", ms))
            .into_iter()
            .chain(context.work_charts.iter().copied())
            .map(|(unit, file)| format!(" data-{}=\"{}\"", escape(unit), escape(file)))
            .collect();
        let _ = writeln!(
            out,
            "<h2>Where the time goes</h2>\n<p class=\"legend\" id=\"pass-chart-legend\">Each technique's frame split into its passes, as shares of the frame: of its GPU time (medians; the frame's milliseconds beside its name), or with the viewer's switch on work, of its counted texel reads or invocations.</p>\n<img src=\"{}\" id=\"pass-chart\"{sources} alt=\"per-pass chart\" style=\"max-width: 100%\">",
            escape(chart)
        );
    }
    out += &html_work(context, rows);
    out += "<p class=\"legend\">Each row: shaded image, visibility, and the error against the ground truth (red: darker than the reference, over-shadowing; blue: lighter, under-shadowing; full colour at an error of 0.5).</p>\n";
    let _ = writeln!(
        out,
        "<figure><figcaption><code>{0}</code> (ground truth)</figcaption><img src=\"{0}/shaded.png\" alt=\"{0} shaded\"><img src=\"{0}/visibility.png\" alt=\"{0} visibility\"></figure>",
        escape(reference_name)
    );
    let lights = rows.iter().filter_map(|r| r.light).max().map_or(1, |last| last + 1);
    for light in 1..lights {
        let _ = writeln!(
            out,
            "<figure><figcaption><code>{0}</code> (ground truth) · light {light}</figcaption><img src=\"{0}/{1}.png\" alt=\"{0} visibility of light {light}\"></figure>",
            escape(reference_name),
            visibility_stem(light)
        );
    }
    for r in rows {
        match r.light {
            None => {
                let extras: String = r
                    .extra_images
                    .iter()
                    .map(|name| {
                        let image = format!("<img src=\"{0}/{1}.png\" alt=\"{0} {1}\" title=\"{1}\">", escape(&r.technique), escape(name));
                        if r.overlays.contains(name) {
                            // Over the visibility, half transparent (Shen et al.'s Fig. 10 inset).
                            format!(
                                "<span class=\"overlay\" title=\"{1} over the visibility\"><img src=\"{0}/visibility.png\" alt=\"{0} visibility\">{image}</span>",
                                escape(&r.technique),
                                escape(name)
                            )
                        } else {
                            image
                        }
                    })
                    .collect();
                let _ = writeln!(
                    out,
                    "<figure><figcaption><code>{0}</code></figcaption><img src=\"{0}/shaded.png\" alt=\"{0} shaded\"><img src=\"{0}/visibility.png\" alt=\"{0} visibility\"><img src=\"{0}/heatmap.png\" alt=\"{0} error\">{extras}</figure>",
                    escape(&r.technique)
                );
            }
            // Light 0's images are in the total's figure.
            Some(0) => {}
            Some(light) => {
                let _ = writeln!(
                    out,
                    "<figure><figcaption><code>{0}</code> · light {light}</figcaption><img src=\"{0}/{1}.png\" alt=\"{0} visibility of light {light}\"><img src=\"{0}/heatmap-light{light}.png\" alt=\"{0} error for light {light}\"></figure>",
                    escape(&r.technique),
                    visibility_stem(light)
                );
            }
        }
    }
    out += "<script>\nwindow.addEventListener('load', () => {\n  const images = Array.from(document.images);\n  const loaded = images.filter((i) => i.complete && i.naturalWidth > 0).length;\n  document.body.dataset.imagesLoaded = loaded + '/' + images.length;\n});\n</script>\n<script src=\"viewer-data.js\"></script>\n<script src=\"viewer.js\"></script>\n</body>\n</html>\n";
    out
}
