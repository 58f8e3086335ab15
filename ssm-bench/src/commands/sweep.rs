//! `ssm sweep`: techniques' parameters (and the scene's) varied over a grid, each point measured
//! against the ground truth; sweep.csv, sweep.md and the time-against-error plot. The writing of
//! those outputs is shared with `ssm merge`, which rebuilds them from a sharded sweep.
//!
//! `sweep::` here is the library's [`crate::sweep`] (the plan, presets and axes); this module is
//! the command around it.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use ssm_core::{GpuContext, Renderer, TechniqueInfo, TechniqueKind};

use super::{CountWorkArg, Format, FrameOrderArgs, load_scene, params_for, parse_setting, progress_bar};
use crate::shard::{Shard, ShardRecord, SweepIdentity, Varied};
use crate::{charts, check_debug_outputs, debug_outputs_for, registry, report, requirements_of, sweep, work};

/// A sweep's image size: a preset may carry its paper's.
#[derive(clap::Args, Clone, Copy)]
struct SweepImageSize {
    /// Image width in pixels; default: the preset's (its paper's viewport), else 640.
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels; default: the preset's (its paper's viewport), else 480.
    #[arg(long)]
    height: Option<u32>,
}

/// `ssm sweep`'s arguments.
#[derive(clap::Args)]
pub(super) struct SweepArgs {
    /// A built-in scene name, a scene manifest (.toml) or a model file; default: the preset's first scene.
    #[arg(long, required_unless_present_any = ["list_presets", "preset"])]
    scene: Option<String>,
    /// `<technique>.<param>[:<param>...]=<value>[:<value>...],...`: values of one axis (colon-joined parameters vary in step);
    /// `scene.light_scale`, `scene.occluder_lift`, `scene.occluder_shift`, `scene.lights` and a built-in scene's own
    /// parameters (`scene.segments`) vary the scene; a bare `<technique>` runs it at its defaults; repeatable.
    #[arg(long = "vary", value_name = "TECHNIQUE.PARAM=V1,V2,...")]
    varies: Vec<String>,
    /// A named set of --vary axes (see `ssm sweep --list-presets`).
    #[arg(long)]
    preset: Option<String>,
    /// List the presets and exit.
    #[arg(long)]
    list_presets: bool,
    /// Fixed parameter assignment `<technique>.<param>=<value>` (also `reference.samples=N`); repeatable.
    #[arg(long = "set", value_name = "TECHNIQUE.PARAM=VALUE")]
    settings: Vec<String>,
    /// The measure on the y axis (`time` for the papers' timing figures); default: the preset's, else mae (the headline error).
    #[arg(long, value_enum)]
    error: Option<sweep::ErrorAxis>,
    /// The x axis: `time`, or a varied parameter as `<technique>.<param>` (`scene.light_scale`); default: the preset's, else time.
    #[arg(long)]
    x: Option<String>,
    #[command(flatten)]
    size: SweepImageSize,
    #[command(flatten)]
    frame_order: FrameOrderArgs,
    /// Frames timed per point after one warm-up; the tables give their median and interquartile range.
    #[arg(long, default_value_t = 5)]
    frames: u32,
    #[command(flatten)]
    work: CountWorkArg,
    /// What error is weighed against for the Pareto front of the lines printed (`*`) and of the
    /// JSON (`pareto`): `time`, or `work`, which counts every point's work (as --count-work).
    /// Whenever work is counted, sweep-work.png and .svg plot it: error against work where the
    /// plot is against time, else work in place of the plot's time or error.
    #[arg(long, value_enum, default_value = "time")]
    cost: work::Cost,
    /// The unit of counted work in the work plot and the `--cost work` front.
    #[arg(long, value_enum, default_value = "reads-and-invocations")]
    work_unit: work::WorkUnit,
    /// Pixels the error metrics cover: every surface, or only receivers (as Atty et al. measure, Sec. 5.2.1); default: the preset's, else all.
    #[arg(long, value_enum)]
    pixels: Option<report::PixelSet>,
    /// `text`: a line per point on stdout; `json`: the rows and their varied values as one JSON document.
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Run only shard K of N (`2/3`): the K-th of N contiguous blocks of the sweep's runs, in the
    /// unsharded order; `shard.json` beside `sweep.csv` records them for `ssm merge`.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
    /// Also write every point's images (visibility, shaded, heat map against the ground truth, and
    /// each scene point's ground truth) under `<out>/images/<scene point>/<technique>/<point>/`.
    #[arg(long)]
    images: bool,
    /// Debug outputs to write beside each point's images, comma-separated (`ssm list` shows what
    /// each technique offers; `all`: every one); needs `--images`.
    #[arg(long = "debug-output", value_delimiter = ',', value_name = "NAME", requires = "images")]
    debug_outputs: Vec<String>,
    /// Output directory: sweep.csv, sweep.md (a Markdown table), sweep.png, sweep.svg.
    #[arg(long, required_unless_present = "list_presets")]
    out: Option<PathBuf>,
}

impl SweepArgs {
    /// Whether every point's work is counted: `--count-work`, or `--cost work`.
    fn counts_work(&self) -> bool {
        self.work.count_work || self.cost == work::Cost::Work
    }
}

/// What a sweep measured: its rows and, per row, its run's number and varied values.
type SweepRows = (Vec<report::Row>, Vec<(usize, Varied)>);

/// A sweep with every default resolved: the scene, the axes, the pixels and the plan.
struct ResolvedSweep {
    scene_spec: String,
    /// Every `--vary` specification, the preset's after the command line's.
    specs: Vec<String>,
    out: PathBuf,
    plan: sweep::SweepPlan,
    x_axis: String,
    error: sweep::ErrorAxis,
    pixels: report::PixelSet,
    /// (width, height): the command line's, else the preset's, else 640×480.
    size: (u32, u32),
}

/// `ssm sweep --list-presets`: each preset's axes, scene and image size.
fn list_presets(registry: &ssm_core::Registry) -> Result<()> {
    for preset in sweep::presets(registry)? {
        let owner = preset.owner.map_or_else(String::new, |o| format!(" [{o}]"));
        say!("{}{owner}: {}", preset.name, preset.summary);
        let (width, height) = sweep::image_size(None, None, Some(&preset));
        let settings: String = preset.settings.iter().map(|s| format!(" --set {s}")).collect();
        say!(
            "  --scene {}  --vary {}{settings}  (x: {}, y: {}, pixels: {}, {width}x{height})",
            preset.scenes.join("|"),
            preset.varies.join(" --vary "),
            preset.x_axis,
            sweep_axis_name(preset.y_axis),
            sweep_pixels_name(preset.pixels)
        );
    }
    Ok(())
}

/// The error axis as `--error` spells it.
fn sweep_axis_name(axis: sweep::ErrorAxis) -> String {
    clap::ValueEnum::to_possible_value(&axis).map_or_else(String::new, |v| v.get_name().to_owned())
}

/// A value as its option spells it.
pub(super) fn sweep_name(value: impl clap::ValueEnum) -> String {
    value.to_possible_value().map_or_else(String::new, |v| v.get_name().to_owned())
}

/// The pixel set as `--pixels` spells it.
fn sweep_pixels_name(pixels: report::PixelSet) -> String {
    clap::ValueEnum::to_possible_value(&pixels).map_or_else(String::new, |v| v.get_name().to_owned())
}

/// The fixed settings of a sweep: the preset's (its paper's configuration), except those of a
/// parameter the command line sets, then the command line's.
fn with_preset_settings(registry: &ssm_core::Registry, args: &SweepArgs) -> Result<Vec<String>> {
    let preset = args.preset.as_deref().map(|name| sweep::preset(registry, name)).transpose()?;
    let key = |setting: &str| setting.split_once('=').map(|(key, _)| key.trim().to_owned());
    let given: Vec<Option<String>> = args.settings.iter().map(|s| key(s)).collect();
    let mut settings: Vec<String> =
        preset.map(|p| p.settings).unwrap_or_default().into_iter().filter(|s| !given.contains(&key(s))).collect();
    settings.extend(args.settings.iter().cloned());
    Ok(settings)
}

/// The preset's defaults under the command line's choices, and the plan, checked before the GPU is touched.
fn resolve_sweep(args: &SweepArgs, registry: &ssm_core::Registry, settings: &[(&str, &str, &str)]) -> Result<ResolvedSweep> {
    let preset = args.preset.as_deref().map(|name| sweep::preset(registry, name)).transpose()?;
    let mut specs: Vec<String> = args.varies.clone();
    if let Some(preset) = &preset {
        specs.extend(preset.varies.iter().cloned());
    }
    if specs.is_empty() {
        bail!("nothing to sweep: give --vary or --preset (see --list-presets)");
    }
    let scene_spec = args
        .scene
        .clone()
        .or_else(|| preset.as_ref().and_then(|p| p.scenes.first().cloned()))
        .context("--scene is required (the preset names no scene)")?;
    let out = args.out.clone().context("--out is required")?;
    let plan = sweep::SweepPlan::new(registry, &specs, settings)?;
    for overrides in &plan.scene_overrides {
        overrides.check_scene(&scene_spec)?;
    }
    let x_axis = args.x.clone().or_else(|| preset.as_ref().map(|p| p.x_axis.clone())).unwrap_or_else(|| "time".to_owned());
    if x_axis != "time" && !plan.varied.contains(&x_axis) {
        bail!("--x {x_axis}: not a varied parameter (give `time` or one of the --vary parameters as <technique>.<param>)");
    }
    let error = args.error.or_else(|| preset.as_ref().map(|p| p.y_axis)).unwrap_or(sweep::ErrorAxis::Mae);
    let pixels = args.pixels.or_else(|| preset.as_ref().map(|p| p.pixels)).unwrap_or(report::PixelSet::All);
    let size = sweep::image_size(args.size.width, args.size.height, preset.as_ref());
    Ok(ResolvedSweep { scene_spec, specs, out, plan, x_axis, error, pixels, size })
}

/// Measures every point of the plan (or of `args.shard`'s runs), each scene point with its own
/// renderer and ground truth; returns the rows and, per row, its run's number in the unsharded
/// order and every varied value (scene ones first).
fn run_sweep(
    gpu: &GpuContext,
    args: &SweepArgs,
    registry: &ssm_core::Registry,
    sweep: &ResolvedSweep,
    settings: &[(&str, &str, &str)],
) -> Result<SweepRows> {
    let base_scene = load_scene(&sweep.scene_spec, args.format)?;
    let reference_info =
        registry.iter().find(|i| i.kind == TechniqueKind::GroundTruth).context("no ground-truth technique is registered")?;
    let reference_params = params_for(reference_info, settings)?;
    let needs =
        requirements_of(sweep.plan.points.iter().map(|(info, params, _)| (*info, params)).chain([(reference_info, &reference_params)]))?;
    let plan = &sweep.plan;
    // The runs this process measures: all, or its shard's block of them.
    let total = plan.scene_points.len() * plan.points.len();
    let runs = args.shard.map_or(0..total, |shard| shard.runs(total));
    let scene_points_run =
        plan.scene_points.len().min(runs.clone().map(|r| r / plan.points.len()).collect::<std::collections::BTreeSet<_>>().len());
    let progress = progress_bar(runs.len() as u64 * u64::from(args.frames.max(1)) + scene_points_run as u64);
    let (mut rows, mut varied) = (Vec::new(), Vec::new());
    for (scene_index, (scene_point, overrides)) in plan.scene_points.iter().zip(&plan.scene_overrides).enumerate() {
        let first_run = scene_index * plan.points.len();
        // A scene point none of whose runs are this shard's: no renderer, no ground truth.
        if !(first_run..first_run + plan.points.len()).any(|run| runs.contains(&run)) {
            continue;
        }
        let scene = overrides
            .base_scene(&sweep.scene_spec, &base_scene)
            .and_then(|base| overrides.apply(&base))
            .with_context(|| format!("scene {} with {scene_point:?}", sweep.scene_spec))?;
        let scene_name = if scene_point.is_empty() {
            sweep.scene_spec.clone()
        } else {
            format!("{}[{}]", sweep.scene_spec, scene_point.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(";"))
        };
        let mut renderer = Renderer::new(gpu, &scene, sweep.size.0, sweep.size.1, &needs)?;
        progress.set_message(format!("reference {scene_name}"));
        let reference = report::measure(&mut renderer, reference_info, &reference_params, 1, &[ssm_core::reference::NOISE_OUTPUT])?;
        let covered = report::pixel_mask(&renderer, sweep.pixels)?;
        let size = sweep.size;
        // Under <out>/images/<scene point>/ when asked: the ground truth, then each technique's points.
        let images = args.images.then(|| sweep.out.join("images").join(sweep::path_component(&sweep::assignment_label(scene_point))));
        let coverage = if images.is_some() { report::pixel_mask(&renderer, report::PixelSet::All)? } else { Vec::new() };
        if let Some(dir) = &images {
            report::write_images(&dir.join(reference_info.name), &reference, size, &coverage, None)?;
        }
        progress.inc(1);
        // This shard's points of the scene point, measured together (their frames in turns, unless --sequential).
        let points: Vec<usize> = (0..plan.points.len()).filter(|point| runs.contains(&(first_run + point))).collect();
        let debug: Vec<Vec<&str>> =
            points.iter().map(|&point| debug_outputs_for(plan.points[point].0, &args.debug_outputs, false)).collect();
        let jobs: Vec<report::MeasureJob<'_>> = points
            .iter()
            .zip(&debug)
            .map(|(&point, debug)| report::MeasureJob {
                info: plan.points[point].0,
                params: &plan.points[point].1,
                debug,
                count_work: args.counts_work(),
            })
            .collect();
        progress.set_message(format!("{} points of {scene_name}", jobs.len()));
        let measured = report::measure_all(&mut renderer, &jobs, args.frames, args.frame_order.order(), || progress.inc(1))?;
        for (measured, &point_index) in measured.into_iter().zip(&points) {
            let (info, _, technique_point) = &plan.points[point_index];
            let run = first_run + point_index;
            if let Some(dir) = &images {
                let point_dir = dir.join(info.name).join(sweep::path_component(&sweep::assignment_label(technique_point)));
                report::write_images(&point_dir, &measured, size, &coverage, Some((&reference, &covered)))?;
            }
            rows.push(report::row(&scene_name, &renderer, &measured, &reference, &covered));
            let mut all: Vec<(String, String)> = scene_point.iter().map(|(k, v)| (format!("scene.{k}"), v.clone())).collect();
            all.extend(technique_point.iter().cloned());
            varied.push((run, all));
        }
    }
    progress.finish_and_clear();
    Ok((rows, varied))
}

/// What a sweep's outputs are written from, whether measured here or merged from shards.
pub(super) struct SweepOutput<'a> {
    pub(super) out: &'a Path,
    /// The preset's name, or `custom`.
    pub(super) name: &'a str,
    /// The adapter's name for `sweep.md`'s header (several, joined, for a merge across machines).
    pub(super) adapter: &'a str,
    pub(super) size: (u32, u32),
    pub(super) frames: u32,
    pub(super) scene_spec: &'a str,
    pub(super) x_axis: &'a str,
    /// Every `--vary` specification (to find the parameters that vary in step with the x axis).
    pub(super) specs: &'a [String],
    pub(super) error: sweep::ErrorAxis,
    /// What the printed Pareto front weighs error against.
    pub(super) cost: work::Cost,
    /// The unit of the work plot.
    pub(super) work_unit: work::WorkUnit,
    pub(super) format: Format,
}

/// `sweep.csv`, the plot (PNG and SVG) and the table on stdout.
pub(super) fn write_sweep(output: &SweepOutput<'_>, rows: &[report::Row], varied: &[Vec<(String, String)>]) -> Result<()> {
    let (out, x_axis, error) = (output.out, output.x_axis, output.error);
    // Parameters varied in step with the x axis (`scene.segments:rings`) move along it: they are
    // not what tells one series from another.
    let along_x = sweep::in_step_with(output.specs, x_axis);
    std::fs::write(out.join("sweep.csv"), report::csv(rows)).with_context(|| format!("writing {}", out.join("sweep.csv").display()))?;
    let table: Vec<sweep::MarkdownRow> = rows
        .iter()
        .zip(varied)
        .map(|(row, values)| {
            let own = format!("{}.", row.technique);
            let point: Vec<String> = values.iter().filter_map(|(k, v)| k.strip_prefix(&own).map(|k| format!("{k}={v}"))).collect();
            let totals = row.work.as_ref().map(work::Totals::of);
            sweep::MarkdownRow {
                scene: row.scene.clone(),
                technique: row.technique.clone(),
                point: point.join(" "),
                ms: sweep::time_of(row),
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
    let markdown = sweep::markdown(output.name, output.adapter, output.size, output.frames, &table);
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
                sweep::time_of(row)
            } else {
                values.iter().find(|(k, _)| k == x_axis).and_then(|(_, v)| v.parse().ok()).unwrap_or(f64::NAN)
            };
            let series = if x_axis == "time" {
                row.technique.clone()
            } else {
                std::iter::once(row.technique.clone()).chain(others.iter().cloned()).collect::<Vec<_>>().join(" ")
            };
            let label = if x_axis == "time" { sweep::point_label(values) } else { String::new() };
            charts::PlotPoint { series, x, y: error.of(row), label }
        })
        .collect();
    // A parameter axis spanning more than a decade is logarithmic too (triangle counts, sizes).
    let log_x = x_axis == "time" || sweep::spans_decades(&plot_points.iter().map(|p| p.x).collect::<Vec<_>>());
    let axes = charts::PlotAxes {
        x_label: match (x_axis == "time", log_x) {
            (true, _) => "time per frame, ms (log)".to_owned(),
            (false, true) => format!("{x_axis} (log)"),
            (false, false) => x_axis.to_owned(),
        },
        y_label: format!("{} (log)", error.label()),
        log_x,
        pareto: x_axis == "time" && error != sweep::ErrorAxis::Time,
    };
    let title = format!("{} at {}x{} on {}", output.scene_spec, output.size.0, output.size.1, output.adapter);
    charts::plot(&plot_points, &axes, &title, &out.join("sweep.png"), &out.join("sweep.svg"))?;
    let work_plot = if rows.iter().any(|r| r.work.is_some()) { write_work_plot(output, rows, &plot_points, &axes)? } else { None };
    let front_of = |points: &[charts::PlotPoint]| sweep::pareto_front(&points.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>());
    let front = match (&work_plot, output.cost) {
        (Some((points, work_axes)), work::Cost::Work) if work_axes.pareto => front_of(points),
        (_, work::Cost::Time) if axes.pareto => front_of(&plot_points),
        _ => Vec::new(),
    };
    let pareto = !front.is_empty();
    let work_of = |row: &report::Row| row.work.as_ref().and_then(|w| output.work_unit.of(w));
    if output.format == Format::Json {
        let json: Vec<serde_json::Value> = rows
            .iter()
            .zip(varied)
            .enumerate()
            .map(|(index, (row, values))| {
                let mut value = report::row_json(row);
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
            (Some(_), Some(amount)) => format!("  {} work", work::short(amount)),
            (Some(_), None) => "  - work".to_owned(),
        };
        say!(
            "{mark} {:<10} {:<40} {:>9.3} ms{counted}  {} {:.4}",
            row.technique,
            sweep::point_label(values),
            sweep::time_of(row),
            error.label(),
            error.of(row)
        );
    }
    if pareto {
        say!("(* on the Pareto front of {})", if output.cost == work::Cost::Work { "work" } else { "time" });
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
    rows: &[report::Row],
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

/// Resolves the sweep (preset defaults under the command line's choices), measures its points
/// (or its shard's) and writes sweep.csv, sweep.md, the plot and, for a shard, shard.json.
pub(super) fn run(args: &SweepArgs) -> Result<()> {
    let registry = registry()?;
    if args.list_presets {
        return list_presets(registry);
    }
    let settings_text = with_preset_settings(registry, args)?;
    let settings: Vec<(&str, &str, &str)> = settings_text.iter().map(|s| parse_setting(s)).collect::<Result<_>>()?;
    // Every grid point resolved before the GPU is touched: a bad value fails fast.
    let sweep = resolve_sweep(args, registry, &settings)?;
    let techniques: Vec<&TechniqueInfo> = sweep.plan.points.iter().map(|(info, _, _)| *info).collect();
    check_debug_outputs(&args.debug_outputs, &techniques)?;
    let gpu = GpuContext::new()?;
    std::fs::create_dir_all(&sweep.out).with_context(|| format!("creating {}", sweep.out.display()))?;
    let (rows, runs) = run_sweep(&gpu, args, registry, &sweep, &settings)?;
    if let Some(shard) = args.shard {
        let identity = SweepIdentity {
            ssm_version: env!("CARGO_PKG_VERSION").to_owned(),
            preset: args.preset.clone(),
            scene: sweep.scene_spec.clone(),
            varies: sweep.specs.clone(),
            settings: settings_text.clone(),
            size: sweep.size,
            frames: args.frames,
            pixels: sweep_pixels_name(sweep.pixels),
            x_axis: sweep.x_axis.clone(),
            error: sweep_axis_name(sweep.error),
            count_work: args.counts_work(),
            cost: sweep_name(args.cost),
            work_unit: args.work_unit.name(),
            runs: sweep.plan.scene_points.len() * sweep.plan.points.len(),
        };
        let record = ShardRecord { identity, shard, adapter: gpu.info.name.clone(), rows: runs.clone() };
        record.write(&sweep.out)?;
    }
    let varied: Vec<Varied> = runs.into_iter().map(|(_, values)| values).collect();
    let output = SweepOutput {
        out: &sweep.out,
        name: args.preset.as_deref().unwrap_or("custom"),
        adapter: &gpu.info.name,
        size: sweep.size,
        frames: args.frames,
        scene_spec: &sweep.scene_spec,
        x_axis: &sweep.x_axis,
        specs: &sweep.specs,
        error: sweep.error,
        cost: args.cost,
        work_unit: args.work_unit,
        format: args.format,
    };
    write_sweep(&output, &rows, &varied)
}
