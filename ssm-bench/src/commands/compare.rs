//! `ssm compare`: every technique (or those named) against the ground truth, written as
//! results.csv, report.md, index.html (with its interactive viewer) and the per-pass chart.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use ssm_core::{GpuContext, Renderer, TechniqueKind};

use super::{CountWorkArg, FrameOrderArgs, ImageSize, load_scene, params_for, parse_setting, progress_bar};
use crate::data::Row;
use crate::data::csv::csv;
use crate::data::json::row_json;
use crate::data::work::Totals;
use crate::measure::files::{write_images, write_positions};
use crate::measure::needs::{check_debug_outputs, debug_outputs_for, requirements_of};
use crate::measure::pixels::{PixelSet, pixel_mask};
use crate::measure::truth::rows_per_light;
use crate::measure::{MeasureJob, measure, measure_all};
use crate::present::markdown::markdown_report;
use crate::present::page::{VIEWER_SCRIPT, ViewerImages, html_report, viewer_data};
use crate::present::{Format, ReportContext, charts, reference_cost, say};
use crate::registry;

/// `ssm compare`'s arguments.
#[derive(clap::Args)]
pub(super) struct CompareArgs {
    /// A built-in scene name, a scene manifest (.toml) or a model file.
    #[arg(long)]
    scene: String,
    /// Technique names, comma-separated; default: every registered real-time technique this adapter can run.
    #[arg(long, value_delimiter = ',')]
    technique: Vec<String>,
    #[command(flatten)]
    size: ImageSize,
    #[command(flatten)]
    frame_order: FrameOrderArgs,
    /// Parameter assignment `<technique>.<param>=<value>` (also `reference.samples=N`); repeatable.
    #[arg(long = "set", value_name = "TECHNIQUE.PARAM=VALUE")]
    settings: Vec<String>,
    /// Frames timed per technique after one warm-up; GPU time is their median.
    #[arg(long, default_value_t = 5)]
    frames: u32,
    /// Pixels the error metrics cover: every surface, or only receivers (as Atty et al. measure, Sec. 5.2.1).
    #[arg(long, value_enum, default_value = "all")]
    pixels: PixelSet,
    /// Debug outputs to write beside each technique's visibility, comma-separated (`ssm list`
    /// shows what each technique offers; `all`: every one).
    #[arg(long = "debug-output", value_delimiter = ',', value_name = "NAME")]
    debug_outputs: Vec<String>,
    #[command(flatten)]
    work: CountWorkArg,
    /// `text`: the report's table on stdout; `json`: the rows as one JSON document (for scripts).
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Open index.html in the default browser when done.
    #[arg(long)]
    open: bool,
    /// Output directory: results.csv, report.md, index.html and one folder of images per technique.
    #[arg(long)]
    out: PathBuf,
}

/// Renders the ground truth and every technique asked for (or every real-time one this adapter
/// runs), and writes the error table, the per-pass chart, the Markdown and HTML reports and the images.
pub(super) fn run(args: &CompareArgs) -> Result<()> {
    let registry = registry()?;
    let scene = load_scene(&args.scene, args.format)?;
    let settings: Vec<(&str, &str, &str)> = args.settings.iter().map(|s| parse_setting(s)).collect::<Result<_>>()?;
    let reference_info =
        registry.iter().find(|i| i.kind == TechniqueKind::GroundTruth).context("no ground-truth technique is registered")?;
    let gpu = GpuContext::new()?;
    let mut skipped: Vec<(String, String)> = Vec::new();
    let mut runs = Vec::new();
    if args.technique.is_empty() {
        for info in registry.iter().filter(|i| i.kind == TechniqueKind::Realtime) {
            let params = params_for(info, &settings)?;
            // Unasked-for techniques this adapter cannot run are reported, not fatal.
            match (info.requirements)(&params).and_then(|r| r.check_device(info.name, &gpu)) {
                Ok(()) => runs.push((info, params)),
                Err(e) => skipped.push((info.name.to_owned(), e.to_string())),
            }
        }
    } else {
        for name in &args.technique {
            let info = registry.get(name)?;
            runs.push((info, params_for(info, &settings)?));
        }
    }
    for (technique, _, _) in &settings {
        if *technique != reference_info.name
            && !runs.iter().any(|(i, _)| i.name == *technique)
            && !skipped.iter().any(|(n, _)| n == technique)
        {
            bail!("--set names technique `{technique}`, which is not compared");
        }
    }
    check_debug_outputs(&args.debug_outputs, &runs.iter().map(|(info, _)| *info).collect::<Vec<_>>())?;
    let reference_params = params_for(reference_info, &settings)?;
    let needs = requirements_of(runs.iter().map(|(info, params)| (*info, params)).chain([(reference_info, &reference_params)]))?;
    let mut renderer = Renderer::new(&gpu, &scene, args.size.width, args.size.height, &needs)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    write_positions(&renderer, &args.out.join("position.exr"))?;

    let progress = progress_bar(runs.len() as u64 * u64::from(args.frames.max(1)) + 1);
    progress.set_message(format!("{} (ground truth)", reference_info.name));
    let reference = measure(&mut renderer, reference_info, &reference_params, 1, &[ssm_core::reference::NOISE_OUTPUT])?;
    let coverage = pixel_mask(&renderer, PixelSet::All)?;
    let size = (args.size.width, args.size.height);
    write_images(&args.out.join(reference_info.name), &reference, size, &coverage, None)?;
    let covered = pixel_mask(&renderer, args.pixels)?;
    progress.inc(1);
    let mut rows = Vec::new();
    // Every technique's visibility, kept for the interactive viewer's data.
    let mut visibilities = Vec::new();
    // The overlays always: the HTML report draws them over the visibility.
    let debug: Vec<Vec<&str>> = runs.iter().map(|(info, _)| debug_outputs_for(info, &args.debug_outputs, true)).collect();
    let count_work = args.work.count_work;
    let jobs: Vec<MeasureJob<'_>> =
        runs.iter().zip(&debug).map(|((info, params), debug)| MeasureJob { info, params, debug, count_work }).collect();
    progress.set_message(runs.iter().map(|(info, _)| info.name).collect::<Vec<_>>().join(","));
    let measured = measure_all(&mut renderer, &jobs, args.frames, args.frame_order.order(), || progress.inc(1))?;
    for measured in measured {
        let info = measured.info;
        write_images(&args.out.join(info.name), &measured, size, &coverage, Some((&reference, &covered)))?;
        rows.extend(rows_per_light(&args.scene, &renderer, &measured, &reference, &covered));
        visibilities.push((info.name, measured.visibility));
    }
    progress.finish_and_clear();

    let adapter = gpu.describe();
    let reference_text = reference_params.to_string();
    let reference_cost = reference_cost(&reference.diagnostics);
    // Where each technique's time goes, passes named without the technique's prefix.
    let bars: Vec<(String, Vec<(String, f64)>)> = rows
        .iter()
        .filter(|r| r.light.is_none())
        .map(|r| {
            let prefix = format!("{}_", r.technique.replace('-', "_"));
            let passes = r.passes.iter().map(|(name, ms)| (name.strip_prefix(&prefix).unwrap_or(name).to_owned(), *ms)).collect();
            (r.technique.clone(), passes)
        })
        .collect();
    let chart_title = format!("{} at {}x{}: GPU time per pass", args.scene, args.size.width, args.size.height);
    let pass_chart = match charts::pass_chart(
        &bars,
        &chart_title,
        charts::PassMeasure::MILLISECONDS,
        &args.out.join("passes.png"),
        &args.out.join("passes.svg"),
    ) {
        Ok(()) => Some("passes.svg"),
        // Without timestamps there are no passes to chart: the report says nothing of them.
        Err(error) => {
            eprintln!("note: no per-pass chart: {error:#}");
            None
        }
    };
    let work_charts = if count_work { work_charts(args, &rows) } else { Vec::new() };
    let context = ReportContext {
        scene: &args.scene,
        adapter: &adapter,
        size: (args.size.width, args.size.height),
        frames: args.frames,
        reference_params: &reference_text,
        reference_cost: &reference_cost,
        skipped: &skipped,
        pass_chart,
        count_work,
        work_charts: &work_charts,
    };
    let write = |name: &str, text: String| {
        std::fs::write(args.out.join(name), text).with_context(|| format!("writing {}", args.out.join(name).display()))
    };
    write("results.csv", csv(&rows))?;
    let markdown = markdown_report(&context, &rows);
    write("report.md", markdown.clone())?;
    let mut viewer_images = vec![ViewerImages { technique: reference_info.name, visibility: &reference.visibility, has_flip: false }];
    viewer_images.extend(visibilities.iter().map(|(name, visibility)| ViewerImages { technique: name, visibility, has_flip: true }));
    write("viewer-data.js", viewer_data(reference_info.name, size, &coverage, &viewer_images, &rows))?;
    write("viewer.js", VIEWER_SCRIPT.to_owned())?;
    write("index.html", html_report(&context, &rows, reference_info.name))?;
    let index = args.out.join("index.html");
    match args.format {
        Format::Text => {
            say!("{markdown}");
            say!("wrote results.csv, report.md and the images under {}", args.out.display());
            say!("report: {} (open it in a browser, or run with --open)", index.display());
        }
        Format::Json => say!("{}", serde_json::to_string_pretty(&rows.iter().map(row_json).collect::<Vec<_>>())?),
    }
    if args.open {
        // Not a failure when there is no browser: the report is written.
        if let Err(error) = opener::open(&index) {
            eprintln!("note: could not open {} in a browser: {error}", index.display());
        }
    }
    Ok(())
}

/// The per-pass work charts (`passes-reads.*`: texel reads, `passes-invocations.*`: vertex,
/// fragment and compute invocations), each of the techniques that counted it, as
/// (the viewer's name for it, the SVG's file name).
fn work_charts(args: &CompareArgs, rows: &[Row]) -> Vec<(&'static str, &'static str)> {
    type Count = fn(&Totals) -> Option<u64>;
    let kinds: [(&str, &str, &str, charts::PassMeasure, Count); 2] = [
        ("reads", "passes-reads.png", "passes-reads.svg", charts::PassMeasure::TEXEL_READS, |t| t.texel_reads),
        ("invocations", "passes-invocations.png", "passes-invocations.svg", charts::PassMeasure::INVOCATIONS, Totals::invocations),
    ];
    let mut drawn = Vec::new();
    for (unit, png, svg, measure, count) in kinds {
        let bars: Vec<(String, Vec<(String, f64)>)> = rows
            .iter()
            .filter(|r| r.light.is_none())
            .filter_map(|r| {
                let work = r.work.as_ref()?;
                let prefix = format!("{}_", r.technique.replace('-', "_"));
                let passes = work
                    .passes
                    .iter()
                    .map(|pass| {
                        let amount = count(&Totals::of_passes(work, std::slice::from_ref(pass)))?;
                        Some((pass.name.strip_prefix(&prefix).unwrap_or(&pass.name).to_owned(), amount as f64))
                    })
                    .collect::<Option<Vec<_>>>()?;
                Some((r.technique.clone(), passes))
            })
            .collect();
        let what = measure.share_of.trim_start_matches("share of the frame's ").trim_end_matches(", %");
        let title = format!("{} at {}x{}: {what} per pass", args.scene, args.size.width, args.size.height);
        match charts::pass_chart(&bars, &title, measure, &args.out.join(png), &args.out.join(svg)) {
            Ok(()) => drawn.push((unit, svg)),
            // No technique counted it (no statistics on this adapter, no shader counts yet).
            Err(error) => eprintln!("note: no per-pass chart of {what}: {error:#}"),
        }
    }
    drawn
}
