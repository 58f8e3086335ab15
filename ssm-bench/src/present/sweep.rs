//! `ssm sweep`'s outputs, and `ssm merge`'s, which rebuilds them from a sharded sweep: what a
//! sweep plots (the measure on the y axis: [`ErrorAxis`]; the unit of counted work: [`WorkUnit`];
//! what the Pareto front weighs error against: [`Cost`]), `sweep.md` ([`markdown`]), and
//! `sweep.csv`, the plots (PNG, SVG) and the lines or JSON on stdout, written together.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use ssm_core::FrameWork;

use super::charts;
use super::work::{cell, short};
use super::{Format, with_noise};
use crate::data::Row;
use crate::data::csv::csv;
use crate::data::json::row_json;
use crate::data::work::Totals;
use crate::stats::pareto_front;

/// Which measure is plotted against time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ErrorAxis {
    /// The headline error: mean absolute error over the pixels the reference or the technique
    /// shadows (`ErrorMetrics::mae`).
    Mae,
    /// Mean absolute error over the reference's umbra and penumbra.
    MaePenumbra,
    /// Root-mean-square error.
    Rmse,
    /// 1 − SSIM.
    OneMinusSsim,
    /// Mean FLIP of the shaded images.
    Flip,
    /// GPU time per frame (or CPU wall time without timestamps), for the paper's timing figures.
    Time,
}

impl ErrorAxis {
    /// The value of this measure in `row`.
    #[must_use]
    pub fn of(self, row: &Row) -> f64 {
        match self {
            Self::Mae => row.metrics.mae,
            Self::MaePenumbra => row.metrics.mae_penumbra,
            Self::Rmse => row.metrics.rmse,
            Self::OneMinusSsim => 1.0 - row.metrics.ssim,
            Self::Flip => row.flip,
            Self::Time => time_of(row),
        }
    }

    /// Axis label.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Mae => "mean absolute error where either image is shadowed",
            Self::MaePenumbra => "mean absolute error over umbra and penumbra",
            Self::Rmse => "RMSE",
            Self::OneMinusSsim => "1 - SSIM",
            Self::Flip => "mean FLIP (shaded)",
            Self::Time => "time per frame, ms",
        }
    }
}

/// The time a row is plotted at: GPU median, else CPU wall median.
#[must_use]
pub fn time_of(row: &Row) -> f64 {
    row.gpu_ms_median.unwrap_or(row.cpu_ms)
}

/// The unit a sweep plots counted work in (`--work-unit`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum WorkUnit {
    /// Texel reads plus vertex, fragment and compute invocations: what a frame fetches and shades.
    #[default]
    ReadsAndInvocations,
    /// Texel reads only (as the technique's shaders count them).
    TexelReads,
    /// Vertex, fragment and compute invocations only (pipeline statistics).
    Invocations,
}

impl WorkUnit {
    /// The frame's work in this unit; `None` when a count it needs was not made.
    #[must_use]
    pub fn of(self, work: &FrameWork) -> Option<f64> {
        let totals = Totals::of(work);
        let value = match self {
            Self::ReadsAndInvocations => totals.texel_reads? + totals.invocations()?,
            Self::TexelReads => totals.texel_reads?,
            Self::Invocations => totals.invocations()?,
        };
        Some(value as f64)
    }

    /// The axis label: what is counted, per frame.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::ReadsAndInvocations => "counted work per frame: texel reads + vertex, fragment and compute invocations",
            Self::TexelReads => "counted texel reads per frame",
            Self::Invocations => "counted vertex, fragment and compute invocations per frame",
        }
    }

    /// The unit as `--work-unit` spells it.
    #[must_use]
    pub fn name(self) -> String {
        clap::ValueEnum::to_possible_value(&self).map_or_else(String::new, |v| v.get_name().to_owned())
    }
}

/// What a sweep's Pareto front (the `*` of its lines, `pareto` in JSON) weighs error against (`--cost`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Cost {
    /// Milliseconds per frame.
    #[default]
    Time,
    /// Counted work per frame, in `--work-unit`: every point is counted (as with `--count-work`).
    Work,
}

/// One line of `sweep.md`.
#[derive(Clone, Debug, PartialEq)]
pub struct MarkdownRow {
    /// The scene, with its varied values (`sphere-cube[lights=2]`).
    pub scene: String,
    /// The technique.
    pub technique: String,
    /// Its own varied values as `param=value`, space-separated; empty at its defaults.
    pub point: String,
    /// Median time per frame, ms.
    pub ms: f64,
    /// First and third quartiles of the time per frame, ms (GPU timestamps only).
    pub ms_quartiles: Option<(f64, f64)>,
    /// Median ms per frame of the CPU work inside the frame (a paper's CPU step), part of `ms`.
    pub cpu_step_ms: Option<f64>,
    /// The headline error against the ground truth ([`ErrorAxis::Mae`]).
    pub mae: f64,
    /// The ground truth's own error over the same pixels, when known.
    pub truth_noise: Option<f64>,
    /// Penumbra MAE against the ground truth.
    pub mae_penumbra: f64,
    /// PSNR against the ground truth, dB.
    pub psnr: f64,
    /// Counted texel reads per frame (`--count-work`); `None` when not counted.
    pub texel_reads: Option<u64>,
    /// The bytes those reads fetched; `None` when not counted.
    pub read_bytes: Option<u64>,
    /// Counted vertex, fragment and compute invocations per frame; `None` when not counted.
    pub invocations: Option<u64>,
}

/// `sweep.md`: the sweep's rows as one Markdown table whose first column names the sweep (a
/// preset's name), under a line naming the adapter, the image size and the frames timed; the
/// last two columns are the counted work (`--count-work`), `-` where not counted. The
/// table's lines from the fifth on are rows only, so that tables of several sweeps on one machine
/// concatenate into one (`scripts/gpu-bench.sh`).
#[must_use]
pub fn markdown(sweep: &str, adapter: &str, size: (u32, u32), frames: u32, rows: &[MarkdownRow]) -> String {
    let mut text = format!("Adapter: {adapter}; {}×{} pixels; median of {frames} frames.\n\n", size.0, size.1);
    text.push_str(
        "| sweep | scene | technique | point | ms | ms IQR | MAE (± truth) | penumbra MAE | PSNR dB | texel reads | invocations | CPU step ms | bytes read |\n|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for row in rows {
        let point = if row.point.is_empty() { "defaults" } else { &row.point };
        text.push_str(&format!(
            "| {sweep} | {} | {} | {point} | {:.2} | {} | {} | {:.4} | {:.1} | {} | {} | {} | {} |\n",
            row.scene,
            row.technique,
            row.ms,
            row.ms_quartiles.map_or_else(|| "-".to_owned(), |(q1, q3)| format!("{q1:.2}–{q3:.2}")),
            with_noise(row.mae, row.truth_noise),
            row.mae_penumbra,
            row.psnr,
            cell(row.texel_reads),
            cell(row.invocations),
            row.cpu_step_ms.map_or_else(|| "-".to_owned(), |ms| format!("{ms:.2}")),
            cell(row.read_bytes)
        ));
    }
    text
}

/// The short label of a point: its varied values.
#[must_use]
pub fn point_label(varied: &[(String, String)]) -> String {
    varied.iter().map(|(_, v)| v.as_str()).collect::<Vec<_>>().join("/")
}

/// Whether positive values span more than a decade (so that a logarithmic axis reads better).
#[must_use]
pub fn spans_decades(values: &[f64]) -> bool {
    let positive: Vec<f64> = values.iter().copied().filter(|v| v.is_finite() && *v > 0.0).collect();
    let (low, high) = positive.iter().fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(*v), h.max(*v)));
    positive.len() == values.len() && !positive.is_empty() && high > 10.0 * low
}

/// What a sweep's outputs are written from, whether measured here or merged from shards.
pub(crate) struct SweepOutput<'a> {
    pub(crate) out: &'a Path,
    /// The preset's name, or `custom`.
    pub(crate) name: &'a str,
    /// The adapter's name for `sweep.md`'s header (several, joined, for a merge across machines).
    pub(crate) adapter: &'a str,
    pub(crate) size: (u32, u32),
    pub(crate) frames: u32,
    pub(crate) scene_spec: &'a str,
    pub(crate) x_axis: &'a str,
    /// The parameters varied in step with the x axis (`scene.rings` for `scene.segments` in
    /// `scene.segments:rings=...`), found in every `--vary` specification.
    pub(crate) along_x: &'a [String],
    pub(crate) error: ErrorAxis,
    /// What the printed Pareto front weighs error against.
    pub(crate) cost: Cost,
    /// The unit of the work plot.
    pub(crate) work_unit: WorkUnit,
    pub(crate) format: Format,
}

/// `sweep.csv`, the plot (PNG and SVG) and the table on stdout.
pub(crate) fn write_sweep(output: &SweepOutput<'_>, rows: &[Row], varied: &[Vec<(String, String)>]) -> Result<()> {
    let (out, x_axis, error) = (output.out, output.x_axis, output.error);
    // Parameters varied in step with the x axis (`scene.segments:rings`) move along it: they are
    // not what tells one series from another.
    let along_x = output.along_x;
    std::fs::write(out.join("sweep.csv"), csv(rows)).with_context(|| format!("writing {}", out.join("sweep.csv").display()))?;
    let table: Vec<MarkdownRow> = rows
        .iter()
        .zip(varied)
        .map(|(row, values)| {
            let own = format!("{}.", row.technique);
            let point: Vec<String> = values.iter().filter_map(|(k, v)| k.strip_prefix(&own).map(|k| format!("{k}={v}"))).collect();
            let totals = row.work.as_ref().map(Totals::of);
            MarkdownRow {
                scene: row.scene.clone(),
                technique: row.technique.clone(),
                point: point.join(" "),
                ms: time_of(row),
                ms_quartiles: row.gpu_ms_quartiles,
                cpu_step_ms: row.cpu_step_ms,
                mae: row.metrics.mae,
                truth_noise: row.metrics.truth_noise,
                mae_penumbra: row.metrics.mae_penumbra,
                psnr: row.metrics.psnr,
                texel_reads: totals.and_then(|t| t.texel_reads),
                read_bytes: totals.and_then(|t| t.read_bytes),
                invocations: totals.and_then(|t| t.invocations()),
            }
        })
        .collect();
    let markdown = markdown(output.name, output.adapter, output.size, output.frames, &table);
    std::fs::write(out.join("sweep.md"), markdown).with_context(|| format!("writing {}", out.join("sweep.md").display()))?;
    // One series per technique and combination of the varied values that are not on the x axis.
    let plot_points: Vec<charts::PlotPoint> = rows
        .iter()
        .zip(varied)
        .map(|(row, values)| {
            let prefix = format!("{}.", row.technique);
            let others: Vec<String> = values
                .iter()
                .filter(|(k, _)| k != x_axis && !along_x.contains(k))
                .map(|(k, v)| format!("{}={v}", k.strip_prefix(&prefix).unwrap_or(k)))
                .collect();
            let x = if x_axis == "time" {
                time_of(row)
            } else {
                values.iter().find(|(k, _)| k == x_axis).and_then(|(_, v)| v.parse().ok()).unwrap_or(f64::NAN)
            };
            let series = if x_axis == "time" {
                row.technique.clone()
            } else {
                std::iter::once(row.technique.clone()).chain(others.iter().cloned()).collect::<Vec<_>>().join(" ")
            };
            let label = if x_axis == "time" { point_label(values) } else { String::new() };
            charts::PlotPoint { series, x, y: error.of(row), label }
        })
        .collect();
    // A parameter axis spanning more than a decade is logarithmic too (triangle counts, sizes).
    let log_x = x_axis == "time" || spans_decades(&plot_points.iter().map(|p| p.x).collect::<Vec<_>>());
    let axes = charts::PlotAxes {
        x_label: match (x_axis == "time", log_x) {
            (true, _) => "time per frame, ms (log)".to_owned(),
            (false, true) => format!("{x_axis} (log)"),
            (false, false) => x_axis.to_owned(),
        },
        y_label: format!("{} (log)", error.label()),
        log_x,
        pareto: x_axis == "time" && error != ErrorAxis::Time,
    };
    let title = format!("{} at {}x{} on {}", output.scene_spec, output.size.0, output.size.1, output.adapter);
    charts::plot(&plot_points, &axes, &title, &out.join("sweep.png"), &out.join("sweep.svg"))?;
    let work_plot = if rows.iter().any(|r| r.work.is_some()) { write_work_plot(output, rows, &plot_points, &axes)? } else { None };
    let front_of = |points: &[charts::PlotPoint]| pareto_front(&points.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>());
    let front = match (&work_plot, output.cost) {
        (Some((points, work_axes)), Cost::Work) if work_axes.pareto => front_of(points),
        (_, Cost::Time) if axes.pareto => front_of(&plot_points),
        _ => Vec::new(),
    };
    let pareto = !front.is_empty();
    let work_of = |row: &Row| row.work.as_ref().and_then(|w| output.work_unit.of(w));
    if output.format == Format::Json {
        let json: Vec<serde_json::Value> = rows
            .iter()
            .zip(varied)
            .enumerate()
            .map(|(index, (row, values))| {
                let mut value = row_json(row);
                value["varied"] =
                    values.iter().map(|(k, v)| (k.clone(), serde_json::Value::String(v.clone()))).collect::<serde_json::Map<_, _>>().into();
                value["pareto"] = front.contains(&index).into();
                value["work"] = work_of(row).map_or(serde_json::Value::Null, serde_json::Value::from);
                value
            })
            .collect();
        say!("{}", serde_json::to_string_pretty(&json)?);
        eprintln!("wrote {}", written(out, work_plot.is_some()));
        return Ok(());
    }
    for (index, (row, values)) in rows.iter().zip(varied).enumerate() {
        let mark = if front.contains(&index) { "*" } else { " " };
        // The work in the plot's unit, `-` where a count it needs was not made.
        let counted = match (&row.work, work_of(row)) {
            (None, _) => String::new(),
            (Some(_), Some(amount)) => format!("  {} work", short(amount)),
            (Some(_), None) => "  - work".to_owned(),
        };
        say!(
            "{mark} {:<10} {:<40} {:>9.3} ms{counted}  {} {:.4}",
            row.technique,
            point_label(values),
            time_of(row),
            error.label(),
            error.of(row)
        );
    }
    if pareto {
        say!("(* on the Pareto front of {})", if output.cost == Cost::Work { "work" } else { "time" });
    }
    if work_plot.is_some() {
        say!("work: {}", output.work_unit.label());
    }
    say!("wrote {}", written(out, work_plot.is_some()));
    Ok(())
}

/// The files a sweep wrote, for its last line.
fn written(out: &Path, work_plot: bool) -> String {
    let mut files = vec!["sweep.csv", "sweep.md", "sweep.png", "sweep.svg"];
    if work_plot {
        files.extend(["sweep-work.png", "sweep-work.svg"]);
    }
    let paths: Vec<String> = files.iter().map(|f| out.join(f).display().to_string()).collect();
    format!("{} and {}", paths[..paths.len() - 1].join(", "), paths[paths.len() - 1])
}

/// `sweep-work.png` and `.svg`: the sweep's plot with counted work (in `--work-unit`) in place of
/// time: error against work where the time plot is error against time (its Pareto front marked),
/// else work on the y axis against the same x axis (the papers' timing figures in work).
/// Returns the points and axes drawn, or `None` (with a note) when no point has the work counted
/// in that unit (a technique that does not count texel reads in its shaders has no
/// reads-and-invocations).
fn write_work_plot(
    output: &SweepOutput<'_>,
    rows: &[Row],
    time_points: &[charts::PlotPoint],
    time_axes: &charts::PlotAxes,
) -> Result<Option<(Vec<charts::PlotPoint>, charts::PlotAxes)>> {
    let unit = output.work_unit;
    let amounts: Vec<f64> = rows.iter().map(|r| r.work.as_ref().and_then(|w| unit.of(w)).unwrap_or(f64::NAN)).collect();
    let missing: Vec<&str> = rows.iter().zip(&amounts).filter(|(_, a)| a.is_nan()).map(|(r, _)| r.technique.as_str()).collect();
    if !missing.is_empty() {
        let mut names = missing.clone();
        names.dedup();
        eprintln!(
            "note: the work plot leaves out {} points whose {} was not counted ({}): see --work-unit",
            missing.len(),
            unit.name(),
            names.join(", ")
        );
    }
    if amounts.iter().all(|a| a.is_nan()) {
        return Ok(None);
    }
    let against_time = output.x_axis == "time";
    let points: Vec<charts::PlotPoint> = time_points
        .iter()
        .zip(&amounts)
        .map(|(point, amount)| {
            if against_time { charts::PlotPoint { x: *amount, ..point.clone() } } else { charts::PlotPoint { y: *amount, ..point.clone() } }
        })
        .collect();
    let axes = if against_time {
        charts::PlotAxes { x_label: format!("{} (log)", unit.label()), ..time_axes.clone() }
    } else {
        charts::PlotAxes { y_label: format!("{} (log)", unit.label()), pareto: false, ..time_axes.clone() }
    };
    let title = format!("{} at {}x{}: counted work", output.scene_spec, output.size.0, output.size.1);
    charts::plot(&points, &axes, &title, &output.out.join("sweep-work.png"), &output.out.join("sweep-work.svg"))?;
    Ok(Some((points, axes)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_tables_of_several_sweeps_concatenate() {
        let row = |technique: &str| MarkdownRow {
            scene: "sphere-cube[lights=2]".into(),
            technique: technique.into(),
            point: String::new(),
            ms: 12.345,
            ms_quartiles: Some((12.0, 12.5)),
            cpu_step_ms: None,
            mae: 0.02345,
            truth_noise: Some(0.00123),
            mae_penumbra: 0.01234,
            psnr: 31.25,
            texel_reads: None,
            read_bytes: None,
            invocations: Some(3456),
        };
        let first = markdown("lights", "llvmpipe", (320, 240), 3, &[row("hard"), row("pcss")]);
        let lines: Vec<&str> = first.lines().collect();
        assert_eq!(lines[0], "Adapter: llvmpipe; 320×240 pixels; median of 3 frames.");
        assert_eq!(
            lines[4],
            "| lights | sphere-cube[lights=2] | hard | defaults | 12.35 | 12.00–12.50 | 0.0234 ± 0.0012 | 0.0123 | 31.2 | - | 3456 | - | - |"
        );
        assert_eq!(lines.len(), 6, "a title, a blank line, the header, its rule, then one line per row");
    }
}
