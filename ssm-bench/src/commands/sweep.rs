//! `ssm sweep`: techniques' parameters (and the scene's) varied over a grid, each point measured
//! against the ground truth; sweep.csv, sweep.md and the time-against-error plot. The writing of
//! those outputs ([`crate::present::sweep`]) is shared with `ssm merge`, which rebuilds them from a
//! sharded sweep.
//!
//! `sweep::` here is the library's [`crate::sweep`] (the plan, presets and axes); this module is
//! the command around it.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use ssm_core::{GpuContext, Renderer, TechniqueInfo, TechniqueKind};

use super::{CountWorkArg, FrameOrderArgs, load_scene, params_for, parse_setting, progress_bar};
use crate::data::Row;
use crate::measure::files::write_images;
use crate::measure::needs::{check_debug_outputs, debug_outputs_for, requirements_of};
use crate::measure::pixels::{PixelSet, pixel_mask};
use crate::measure::truth::row;
use crate::measure::{MeasureJob, measure, measure_all};
use crate::present::sweep::{Cost, ErrorAxis, SweepOutput, WorkUnit, write_sweep};
use crate::present::{Format, say};
use crate::shard::{Shard, ShardRecord, SweepIdentity, Varied};
use crate::{registry, sweep};

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
    error: Option<ErrorAxis>,
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
    cost: Cost,
    /// The unit of counted work in the work plot and the `--cost work` front.
    #[arg(long, value_enum, default_value = "reads-and-invocations")]
    work_unit: WorkUnit,
    /// Pixels the error metrics cover: every surface, or only receivers (as Atty et al. measure, Sec. 5.2.1); default: the preset's, else all.
    #[arg(long, value_enum)]
    pixels: Option<PixelSet>,
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
        self.work.count_work || self.cost == Cost::Work
    }
}

/// What a sweep measured: its rows and, per row, its run's number and varied values.
type SweepRows = (Vec<Row>, Vec<(usize, Varied)>);

/// A sweep with every default resolved: the scene, the axes, the pixels and the plan.
struct ResolvedSweep {
    scene_spec: String,
    /// Every `--vary` specification, the preset's after the command line's.
    specs: Vec<String>,
    out: PathBuf,
    plan: sweep::SweepPlan,
    x_axis: String,
    error: ErrorAxis,
    pixels: PixelSet,
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
fn sweep_axis_name(axis: ErrorAxis) -> String {
    clap::ValueEnum::to_possible_value(&axis).map_or_else(String::new, |v| v.get_name().to_owned())
}

/// A value as its option spells it.
pub(super) fn sweep_name(value: impl clap::ValueEnum) -> String {
    value.to_possible_value().map_or_else(String::new, |v| v.get_name().to_owned())
}

/// The pixel set as `--pixels` spells it.
fn sweep_pixels_name(pixels: PixelSet) -> String {
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
    let error = args.error.or_else(|| preset.as_ref().map(|p| p.y_axis)).unwrap_or(ErrorAxis::Mae);
    let pixels = args.pixels.or_else(|| preset.as_ref().map(|p| p.pixels)).unwrap_or(PixelSet::All);
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
        let reference = measure(&mut renderer, reference_info, &reference_params, 1, &[ssm_core::reference::NOISE_OUTPUT])?;
        let covered = pixel_mask(&renderer, sweep.pixels)?;
        let size = sweep.size;
        // Under <out>/images/<scene point>/ when asked: the ground truth, then each technique's points.
        let images = args.images.then(|| sweep.out.join("images").join(sweep::path_component(&sweep::assignment_label(scene_point))));
        let coverage = if images.is_some() { pixel_mask(&renderer, PixelSet::All)? } else { Vec::new() };
        if let Some(dir) = &images {
            write_images(&dir.join(reference_info.name), &reference, size, &coverage, None)?;
        }
        progress.inc(1);
        // This shard's points of the scene point, measured together (their frames in turns, unless --sequential).
        let points: Vec<usize> = (0..plan.points.len()).filter(|point| runs.contains(&(first_run + point))).collect();
        let debug: Vec<Vec<&str>> =
            points.iter().map(|&point| debug_outputs_for(plan.points[point].0, &args.debug_outputs, false)).collect();
        let jobs: Vec<MeasureJob<'_>> = points
            .iter()
            .zip(&debug)
            .map(|(&point, debug)| MeasureJob {
                info: plan.points[point].0,
                params: &plan.points[point].1,
                debug,
                count_work: args.counts_work(),
            })
            .collect();
        progress.set_message(format!("{} points of {scene_name}", jobs.len()));
        let measured = measure_all(&mut renderer, &jobs, args.frames, args.frame_order.order(), || progress.inc(1))?;
        for (measured, &point_index) in measured.into_iter().zip(&points) {
            let (info, _, technique_point) = &plan.points[point_index];
            let run = first_run + point_index;
            if let Some(dir) = &images {
                let point_dir = dir.join(info.name).join(sweep::path_component(&sweep::assignment_label(technique_point)));
                write_images(&point_dir, &measured, size, &coverage, Some((&reference, &covered)))?;
            }
            rows.push(row(&scene_name, &renderer, &measured, &reference, &covered));
            let mut all: Vec<(String, String)> = scene_point.iter().map(|(k, v)| (format!("scene.{k}"), v.clone())).collect();
            all.extend(technique_point.iter().cloned());
            varied.push((run, all));
        }
    }
    progress.finish_and_clear();
    Ok((rows, varied))
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
    let along_x = sweep::in_step_with(&sweep.specs, &sweep.x_axis);
    let output = SweepOutput {
        out: &sweep.out,
        name: args.preset.as_deref().unwrap_or("custom"),
        adapter: &gpu.info.name,
        size: sweep.size,
        frames: args.frames,
        scene_spec: &sweep.scene_spec,
        x_axis: &sweep.x_axis,
        along_x: &along_x,
        error: sweep.error,
        cost: args.cost,
        work_unit: args.work_unit,
        format: args.format,
    };
    write_sweep(&output, &rows, &varied)
}
