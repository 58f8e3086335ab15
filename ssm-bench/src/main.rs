//! `ssm`: render scenes with any registered soft-shadow technique.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use ssm_bench::shard::Varied;
use ssm_bench::{check_debug_outputs, debug_outputs_for, registry, report, requirements_of, support_on, sweep, write_positions, write_run};
use ssm_core::{GpuContext, ParamValues, Renderer, TechniqueInfo, TechniqueKind};
use ssm_scene::{BUILTIN_SCENES, Scene, SceneSource};

#[derive(Parser)]
#[command(name = "ssm", version, about = "Soft-shadow techniques as plug-ins, compared on identical scenes")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the registered techniques with their parameters, requirements and whether this adapter runs them.
    List(FormatArgs),
    /// List the built-in scenes and their parameters (`--scene forest:triangles=800000`).
    Scenes(FormatArgs),
    /// Render a scene with one or more techniques and write images and timings.
    Render(RenderArgs),
    /// Render every technique (or those named) and the ground truth; write results.csv, report.md and index.html.
    Compare(CompareArgs),
    /// Vary techniques' parameters over a grid; write sweep.csv, sweep.md and the time-against-error plot (PNG, SVG).
    Sweep(SweepArgs),
    /// A live window: the scene shaded with one technique at a time (number keys switch), a panel of its
    /// parameters, per-pass GPU times and the error against the cached ground truth; drag to orbit.
    View(ViewArgs),
    /// Put the shards of a sweep (`ssm sweep --shard K/N` outputs) back together: sweep.csv, sweep.md and the plot.
    Merge(MergeArgs),
}

/// How a command prints what it found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Format {
    /// Lines for people.
    Text,
    /// One JSON document on stdout, for scripts (progress and notes go to stderr).
    Json,
}

#[derive(clap::Args)]
struct FormatArgs {
    /// `text` for people, `json` for scripts.
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
}

/// The rendered image's size, as every rendering command takes it.
#[derive(clap::Args, Clone, Copy)]
struct ImageSize {
    /// Image width in pixels.
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 480)]
    height: u32,
}

/// How the timed frames of several techniques (or sweep points) are ordered.
#[derive(clap::Args, Clone, Copy)]
struct FrameOrderArgs {
    /// Time each technique's frames in one block, one technique in memory at a time, instead of
    /// in turns (every technique's first frame, then every second, ..., each after an untimed
    /// frame of its own), which keeps a slow spell of the machine from landing on one technique:
    /// for sets too large to hold together.
    #[arg(long)]
    sequential: bool,
}

impl FrameOrderArgs {
    fn order(self) -> report::FrameOrder {
        if self.sequential { report::FrameOrder::Sequential } else { report::FrameOrder::Interleaved }
    }
}

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

#[derive(clap::Args)]
struct MergeArgs {
    /// The shards' output folders (each holds sweep.csv and shard.json), every shard of one sweep once.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// `text`: a line per point on stdout; `json`: the rows and their varied values as one JSON document.
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Output directory: sweep.csv, sweep.md, sweep.png and sweep.svg, as the unsharded sweep writes them.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct SweepArgs {
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
    /// The measure on the y axis (`time` for the papers' timing figures); default: the preset's, else mae-penumbra.
    #[arg(long, value_enum)]
    error: Option<sweep::ErrorAxis>,
    /// The x axis: `time`, or a varied parameter as `<technique>.<param>` (`scene.light_scale`); default: the preset's, else time.
    #[arg(long)]
    x: Option<String>,
    #[command(flatten)]
    size: SweepImageSize,
    #[command(flatten)]
    frame_order: FrameOrderArgs,
    /// Frames timed per point after one warm-up.
    #[arg(long, default_value_t = 3)]
    frames: u32,
    /// Pixels the error metrics cover: every surface, or only receivers (as Atty et al. measure, Sec. 5.2.1); default: the preset's, else all.
    #[arg(long, value_enum)]
    pixels: Option<report::PixelSet>,
    /// `text`: a line per point on stdout; `json`: the rows and their varied values as one JSON document.
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Run only shard K of N (`2/3`): the K-th of N contiguous blocks of the sweep's runs, in the
    /// unsharded order; `shard.json` beside `sweep.csv` records them for `ssm merge`.
    #[arg(long, value_name = "K/N")]
    shard: Option<ssm_bench::shard::Shard>,
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

#[derive(clap::Args)]
struct CompareArgs {
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
    pixels: report::PixelSet,
    /// Debug outputs to write beside each technique's visibility, comma-separated (`ssm list`
    /// shows what each technique offers; `all`: every one).
    #[arg(long = "debug-output", value_delimiter = ',', value_name = "NAME")]
    debug_outputs: Vec<String>,
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

#[derive(clap::Args)]
struct RenderArgs {
    /// A built-in scene name, a scene manifest (.toml) or a model file (.gltf, .glb, .obj, .ply; staged with a ground and a light).
    #[arg(long)]
    scene: String,
    /// Technique names, comma-separated (see `ssm list`).
    #[arg(long, value_delimiter = ',', required = true)]
    technique: Vec<String>,
    #[command(flatten)]
    size: ImageSize,
    #[command(flatten)]
    frame_order: FrameOrderArgs,
    /// Parameter assignment `<technique>.<param>=<value>`; repeatable.
    #[arg(long = "set", value_name = "TECHNIQUE.PARAM=VALUE")]
    settings: Vec<String>,
    /// Frames timed after one warm-up frame; timings.json holds each and the median.
    #[arg(long, default_value_t = 1)]
    frames: u32,
    /// Debug outputs to write beside each technique's visibility, comma-separated (`ssm list`
    /// shows what each technique offers; `all`: every one).
    #[arg(long = "debug-output", value_delimiter = ',', value_name = "NAME")]
    debug_outputs: Vec<String>,
    /// Output directory: <out>/<technique>/{visibility.exr,visibility.png,shaded.png,timings.json} and <out>/position.exr.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct ViewArgs {
    /// A built-in scene name, a scene manifest (.toml) or a model file.
    #[arg(long)]
    scene: String,
    /// Technique names in key order (key 1 is the first), comma-separated; default: every real-time technique, then `reference`.
    #[arg(long, value_delimiter = ',')]
    technique: Vec<String>,
    #[command(flatten)]
    size: ImageSize,
    /// Starting parameter `<technique>.<param>=<value>`; repeatable.
    #[arg(long = "set", value_name = "TECHNIQUE.PARAM=VALUE")]
    settings: Vec<String>,
}

/// Writes a line to stdout, failing (rather than panicking like `println!`) when stdout is closed.
macro_rules! say {
    ($($arg:tt)*) => {
        writeln!(std::io::stdout().lock(), $($arg)*).context("writing to stdout")?
    };
}

/// Without a Wayland session (no `XDG_RUNTIME_DIR`), Mesa's device-selection
/// Vulkan layer still tries to connect to one when wgpu enables the Wayland
/// surface extension, and libwayland prints `error: XDG_RUNTIME_DIR is invalid
/// or not set` on a perfectly good offscreen run. ssm never presents to a
/// window and picks its adapter itself, so the layer is switched off (its own
/// documented switch) for this process.
fn quiet_window_system_layers() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() && std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: called first thing in `main`, before any thread exists, so no
        // other thread can read the environment while it changes.
        #[allow(unsafe_code)]
        unsafe {
            std::env::set_var("NODEVICE_SELECT", "1");
        }
    }
}

fn main() -> ExitCode {
    quiet_window_system_layers();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::List(args) => list(args.format),
        Command::Scenes(args) => scenes(args.format),
        Command::Render(args) => render(&args),
        Command::Compare(args) => compare(&args),
        Command::Sweep(args) => sweep_command(&args),
        Command::Merge(args) => merge_command(&args),
        Command::View(args) => view(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that stopped reading (`ssm list | head`) is not a failure.
        Err(error)
            if error.chain().any(|e| e.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)) =>
        {
            ExitCode::SUCCESS
        }
        Err(error) => {
            // One line: the error and its causes.
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

fn list(format: Format) -> Result<()> {
    let registry = registry()?;
    let gpu = GpuContext::new();
    if format == Format::Json {
        let techniques = registry
            .iter()
            .map(|info| {
                let requirements = (info.requirements)(&info.default_params())?;
                Ok(serde_json::json!({
                    "name": info.name,
                    "summary": info.summary,
                    "paper": info.paper,
                    "kind": format!("{:?}", info.kind).to_lowercase(),
                    "needs": requirements.describe(),
                    "runs_here": gpu.as_ref().ok().map(|gpu| support_on(gpu, info)),
                    "params": info.params.iter().map(|spec| serde_json::json!({
                        "name": spec.name,
                        "default": spec.default_value().to_string(),
                        "range": spec.range_text(),
                        "doc": spec.doc,
                    })).collect::<Vec<_>>(),
                    "debug_outputs": info.debug_outputs.iter().map(|o| serde_json::json!({
                        "name": o.name, "doc": o.doc, "overlay": o.overlay,
                    })).collect::<Vec<_>>(),
                    "presets": info.presets.iter().map(|p| p.name).collect::<Vec<_>>(),
                }))
            })
            .collect::<Result<Vec<_>>>()?;
        let adapter = gpu.as_ref().map_or(serde_json::Value::Null, |gpu| serde_json::Value::String(gpu.describe()));
        say!("{}", serde_json::to_string_pretty(&serde_json::json!({ "adapter": adapter, "techniques": techniques }))?);
        return Ok(());
    }
    match &gpu {
        Ok(gpu) => say!("adapter: {}\n", gpu.describe()),
        Err(e) => say!("adapter: none ({e})\n"),
    }
    for info in registry.iter() {
        say!("{}: {}", info.name, info.summary);
        say!("  paper: {}", info.paper);
        let requirements = (info.requirements)(&info.default_params())?;
        say!("  needs: {}", requirements.describe());
        if let Ok(gpu) = &gpu {
            say!("  runs here: {}", support_on(gpu, info));
        }
        for spec in info.params {
            say!("  --set {}.{}={}  ({}; {})", info.name, spec.name, spec.default_value(), spec.range_text(), spec.doc);
        }
        for output in info.debug_outputs {
            say!("  --debug-output {}  ({})", output.name, output.doc);
        }
        say!("");
    }
    Ok(())
}

fn scenes(format: Format) -> Result<()> {
    if format == Format::Json {
        let scenes: Vec<serde_json::Value> = BUILTIN_SCENES
            .iter()
            .map(|scene| {
                serde_json::json!({
                    "name": scene.name,
                    "triangles": scene.build().triangle_count(),
                    "summary": scene.summary,
                    "params": scene.params.iter().map(|p| serde_json::json!({
                        "name": p.name, "default": p.default, "min": p.min, "max": p.max, "doc": p.doc,
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        say!("{}", serde_json::to_string_pretty(&scenes)?);
        return Ok(());
    }
    for scene in BUILTIN_SCENES {
        let built = scene.build();
        say!("{:<16} {:>7} triangles  {}", scene.name, built.triangle_count(), scene.summary);
        for param in scene.params {
            say!("{:<26}{}:{}={}  ({} to {}) {}", "", scene.name, param.name, param.default, param.min, param.max, param.doc);
        }
    }
    Ok(())
}

/// A progress bar on stderr with the elapsed time and an estimate of the time left.
fn progress_bar(len: u64) -> ProgressBar {
    let progress = ProgressBar::new(len);
    progress.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} ({elapsed}, about {eta} left)")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    progress
}

/// Splits `technique.param=value`.
fn parse_setting(text: &str) -> Result<(&str, &str, &str)> {
    let (key, value) = text.split_once('=').with_context(|| format!("--set `{text}`: expected <technique>.<param>=<value>"))?;
    let (technique, param) = key.split_once('.').with_context(|| format!("--set `{text}`: expected <technique>.<param>=<value>"))?;
    Ok((technique.trim(), param.trim(), value.trim()))
}

fn render(args: &RenderArgs) -> Result<()> {
    let registry = registry()?;
    let scene = load_scene(&args.scene, Format::Text)?;
    let settings: Vec<(&str, &str, &str)> = args.settings.iter().map(|s| parse_setting(s)).collect::<Result<_>>()?;
    for (technique, _, _) in &settings {
        if !args.technique.iter().any(|t| t == technique) {
            bail!("--set names technique `{technique}`, which is not among --technique {}", args.technique.join(","));
        }
    }
    // Resolve every technique and its parameters before touching the GPU: a typo fails fast.
    let mut runs = Vec::new();
    for name in &args.technique {
        let info = registry.get(name)?;
        runs.push((info, params_for(info, &settings)?));
    }
    let needs = requirements_of(runs.iter().map(|(info, params)| (*info, params)))?;
    check_debug_outputs(&args.debug_outputs, &runs.iter().map(|(info, _)| *info).collect::<Vec<_>>())?;
    let gpu = GpuContext::new()?;
    let mut renderer = Renderer::new(&gpu, &scene, args.size.width, args.size.height, &needs)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    write_positions(&renderer, &args.out.join("position.exr"))?;

    let progress = progress_bar(runs.len() as u64 * u64::from(args.frames.max(1)));
    progress.set_message(runs.iter().map(|(info, _)| info.name).collect::<Vec<_>>().join(","));
    let debug: Vec<Vec<&str>> = runs.iter().map(|(info, _)| debug_outputs_for(info, &args.debug_outputs, false)).collect();
    let jobs: Vec<report::MeasureJob<'_>> =
        runs.iter().zip(&debug).map(|((info, params), debug)| report::MeasureJob { info, params, debug }).collect();
    // Technique errors name the technique already.
    let measured = report::measure_all(&mut renderer, &jobs, args.frames, args.frame_order.order(), || progress.inc(1))?;
    progress.finish_and_clear();
    for run in &measured {
        let info = run.info;
        let dir = args.out.join(info.name);
        write_run(&renderer, run, &dir)?;
        let time = match run.gpu_ms_median() {
            Some(ms) => format!("{ms:.3} ms GPU"),
            None => format!("{:.3} ms CPU wall (no timestamps)", run.cpu_ms_median()),
        };
        say!("{:<8} {time}  [{}]  -> {}", info.name, run.params, dir.display());
        if !run.diagnostics.is_empty() {
            let text: Vec<String> = run.diagnostics.iter().map(|(k, v)| format!("{k}={v:.4}")).collect();
            say!("{:<8} {}", "", text.join("  "));
        }
    }
    say!("adapter: {}", gpu.describe());
    Ok(())
}

fn view(args: &ViewArgs) -> Result<()> {
    let registry = registry()?;
    let scene = load_scene(&args.scene, Format::Text)?;
    let settings: Vec<(&str, &str, &str)> = args.settings.iter().map(|s| parse_setting(s)).collect::<Result<_>>()?;
    let names: Vec<&str> = if args.technique.is_empty() {
        let mut names: Vec<&str> = registry.iter().filter(|i| i.kind == TechniqueKind::Realtime).map(|i| i.name).collect();
        names.extend(registry.iter().filter(|i| i.kind == TechniqueKind::GroundTruth).map(|i| i.name));
        names
    } else {
        args.technique.iter().map(String::as_str).collect()
    };
    for (technique, _, _) in &settings {
        if !names.contains(technique) {
            bail!("--set names technique `{technique}`, which is not among those shown ({})", names.join(","));
        }
    }
    let techniques = names
        .iter()
        .map(|name| {
            let info = registry.get(name)?;
            Ok((info, params_for(info, &settings)?))
        })
        .collect::<Result<Vec<_>>>()?;
    ssm_bench::view::run(ssm_bench::view::ViewOptions {
        scene_name: args.scene.clone(),
        scene,
        techniques,
        width: args.size.width,
        height: args.size.height,
    })
}

/// Loads `spec` and says what it holds: on stdout, or on stderr when stdout carries `Format::Json`.
fn load_scene(spec: &str, format: Format) -> Result<Scene> {
    let (scene, source) = Scene::load(spec).with_context(|| format!("loading scene `{spec}`"))?;
    let mut notes = String::new();
    if let SceneSource::StagedModel(manifest) = &source {
        notes += &format!("# staged scene for {spec} (save beside the model and edit):\n{}\n", manifest.to_toml());
    }
    notes += &format!(
        "scene: {spec} ({} triangles, {} instances, {} lights)",
        scene.triangle_count(),
        scene.instances.len(),
        scene.lights.len()
    );
    match format {
        Format::Text => say!("{notes}"),
        Format::Json => eprintln!("{notes}"),
    }
    Ok(scene)
}

/// The parameter values of `info` from the `--set` assignments that name it.
fn params_for(info: &'static TechniqueInfo, settings: &[(&str, &str, &str)]) -> Result<ParamValues> {
    Ok(info.params_from(settings.iter().filter(|(t, _, _)| *t == info.name).map(|(_, p, v)| (*p, *v)))?)
}

fn compare(args: &CompareArgs) -> Result<()> {
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
    let reference = report::measure(&mut renderer, reference_info, &reference_params, 1, &[])?;
    let coverage = report::pixel_mask(&renderer, report::PixelSet::All)?;
    let size = (args.size.width, args.size.height);
    report::write_images(&args.out.join(reference_info.name), &reference, size, &coverage, None)?;
    let covered = report::pixel_mask(&renderer, args.pixels)?;
    progress.inc(1);
    let mut rows = Vec::new();
    // Every technique's visibility, kept for the interactive viewer's data.
    let mut visibilities = Vec::new();
    // The overlays always: the HTML report draws them over the visibility.
    let debug: Vec<Vec<&str>> = runs.iter().map(|(info, _)| debug_outputs_for(info, &args.debug_outputs, true)).collect();
    let jobs: Vec<report::MeasureJob<'_>> =
        runs.iter().zip(&debug).map(|((info, params), debug)| report::MeasureJob { info, params, debug }).collect();
    progress.set_message(runs.iter().map(|(info, _)| info.name).collect::<Vec<_>>().join(","));
    let measured = report::measure_all(&mut renderer, &jobs, args.frames, args.frame_order.order(), || progress.inc(1))?;
    for measured in measured {
        let info = measured.info;
        report::write_images(&args.out.join(info.name), &measured, size, &coverage, Some((&reference, &covered)))?;
        rows.extend(report::rows_per_light(&args.scene, &renderer, &measured, &reference, &covered));
        visibilities.push((info.name, measured.visibility));
    }
    progress.finish_and_clear();

    let adapter = gpu.describe();
    let reference_text = reference_params.to_string();
    let reference_cost = report::reference_cost(&reference.diagnostics);
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
    let pass_chart = match sweep::pass_chart(&bars, &chart_title, &args.out.join("passes.png"), &args.out.join("passes.svg")) {
        Ok(()) => Some("passes.svg"),
        // Without timestamps there are no passes to chart: the report says nothing of them.
        Err(error) => {
            eprintln!("note: no per-pass chart: {error:#}");
            None
        }
    };
    let context = report::ReportContext {
        scene: &args.scene,
        adapter: &adapter,
        size: (args.size.width, args.size.height),
        frames: args.frames,
        reference_params: &reference_text,
        reference_cost: &reference_cost,
        skipped: &skipped,
        pass_chart,
    };
    let write = |name: &str, text: String| {
        std::fs::write(args.out.join(name), text).with_context(|| format!("writing {}", args.out.join(name).display()))
    };
    write("results.csv", report::csv(&rows))?;
    let markdown = report::markdown_report(&context, &rows);
    write("report.md", markdown.clone())?;
    let mut viewer_images =
        vec![report::ViewerImages { technique: reference_info.name, visibility: &reference.visibility, has_flip: false }];
    viewer_images.extend(visibilities.iter().map(|(name, visibility)| report::ViewerImages {
        technique: name,
        visibility,
        has_flip: true,
    }));
    write("viewer-data.js", report::viewer_data(reference_info.name, size, &coverage, &viewer_images, &rows))?;
    write("viewer.js", report::VIEWER_SCRIPT.to_owned())?;
    write("index.html", report::html_report(&context, &rows, reference_info.name))?;
    let index = args.out.join("index.html");
    match args.format {
        Format::Text => {
            say!("{markdown}");
            say!("wrote results.csv, report.md and the images under {}", args.out.display());
            say!("report: {} (open it in a browser, or run with --open)", index.display());
        }
        Format::Json => say!("{}", serde_json::to_string_pretty(&rows.iter().map(report::row_json).collect::<Vec<_>>())?),
    }
    if args.open {
        // Not a failure when there is no browser: the report is written.
        if let Err(error) = opener::open(&index) {
            eprintln!("note: could not open {} in a browser: {error}", index.display());
        }
    }
    Ok(())
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

fn list_presets(registry: &ssm_core::Registry) -> Result<()> {
    for preset in sweep::presets(registry)? {
        let owner = preset.owner.map_or_else(String::new, |o| format!(" [{o}]"));
        say!("{}{owner}: {}", preset.name, preset.summary);
        let (width, height) = sweep::image_size(None, None, Some(&preset));
        say!(
            "  --scene {}  --vary {}  (x: {}, y: {}, pixels: {}, {width}x{height})",
            preset.scenes.join("|"),
            preset.varies.join(" --vary "),
            preset.x_axis,
            sweep_axis_name(preset.y_axis),
            sweep_pixels_name(preset.pixels)
        );
    }
    Ok(())
}

fn sweep_axis_name(axis: sweep::ErrorAxis) -> String {
    clap::ValueEnum::to_possible_value(&axis).map_or_else(String::new, |v| v.get_name().to_owned())
}

fn sweep_pixels_name(pixels: report::PixelSet) -> String {
    clap::ValueEnum::to_possible_value(&pixels).map_or_else(String::new, |v| v.get_name().to_owned())
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
    let error = args.error.or_else(|| preset.as_ref().map(|p| p.y_axis)).unwrap_or(sweep::ErrorAxis::MaePenumbra);
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
        let reference = report::measure(&mut renderer, reference_info, &reference_params, 1, &[])?;
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
            .map(|(&point, debug)| report::MeasureJob { info: plan.points[point].0, params: &plan.points[point].1, debug })
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
struct SweepOutput<'a> {
    out: &'a Path,
    /// The preset's name, or `custom`.
    name: &'a str,
    /// The adapter's name for `sweep.md`'s header (several, joined, for a merge across machines).
    adapter: &'a str,
    size: (u32, u32),
    frames: u32,
    scene_spec: &'a str,
    x_axis: &'a str,
    /// Every `--vary` specification (to find the parameters that vary in step with the x axis).
    specs: &'a [String],
    error: sweep::ErrorAxis,
    format: Format,
}

/// `sweep.csv`, the plot (PNG and SVG) and the table on stdout.
fn write_sweep(output: &SweepOutput<'_>, rows: &[report::Row], varied: &[Vec<(String, String)>]) -> Result<()> {
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
            sweep::MarkdownRow {
                scene: row.scene.clone(),
                technique: row.technique.clone(),
                point: point.join(" "),
                ms: sweep::time_of(row),
                mae_penumbra: row.metrics.mae_penumbra,
                psnr: row.metrics.psnr,
            }
        })
        .collect();
    let markdown = sweep::markdown(output.name, output.adapter, output.size, output.frames, &table);
    std::fs::write(out.join("sweep.md"), markdown).with_context(|| format!("writing {}", out.join("sweep.md").display()))?;
    // One series per technique and combination of the varied values that are not on the x axis.
    let plot_points: Vec<sweep::PlotPoint> = rows
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
            sweep::PlotPoint { series, x, y: error.of(row), label }
        })
        .collect();
    // A parameter axis spanning more than a decade is logarithmic too (triangle counts, sizes).
    let log_x = x_axis == "time" || sweep::spans_decades(&plot_points.iter().map(|p| p.x).collect::<Vec<_>>());
    let axes = sweep::PlotAxes {
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
    sweep::plot(&plot_points, &axes, &title, &out.join("sweep.png"), &out.join("sweep.svg"))?;
    let front = if axes.pareto { sweep::pareto_front(&plot_points.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>()) } else { Vec::new() };
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
                value
            })
            .collect();
        say!("{}", serde_json::to_string_pretty(&json)?);
        eprintln!(
            "wrote {}, {}, {} and {}",
            out.join("sweep.csv").display(),
            out.join("sweep.md").display(),
            out.join("sweep.png").display(),
            out.join("sweep.svg").display()
        );
        return Ok(());
    }
    for (index, (row, values)) in rows.iter().zip(varied).enumerate() {
        let mark = if front.contains(&index) { "*" } else { " " };
        say!(
            "{mark} {:<10} {:<40} {:>9.3} ms  {} {:.4}",
            row.technique,
            sweep::point_label(values),
            sweep::time_of(row),
            error.label(),
            error.of(row)
        );
    }
    if axes.pareto {
        say!("(* on the Pareto front)");
    }
    say!(
        "wrote {}, {}, {} and {}",
        out.join("sweep.csv").display(),
        out.join("sweep.md").display(),
        out.join("sweep.png").display(),
        out.join("sweep.svg").display()
    );
    Ok(())
}

fn sweep_command(args: &SweepArgs) -> Result<()> {
    let registry = registry()?;
    if args.list_presets {
        return list_presets(registry);
    }
    let settings: Vec<(&str, &str, &str)> = args.settings.iter().map(|s| parse_setting(s)).collect::<Result<_>>()?;
    // Every grid point resolved before the GPU is touched: a bad value fails fast.
    let sweep = resolve_sweep(args, registry, &settings)?;
    let techniques: Vec<&TechniqueInfo> = sweep.plan.points.iter().map(|(info, _, _)| *info).collect();
    check_debug_outputs(&args.debug_outputs, &techniques)?;
    let gpu = GpuContext::new()?;
    std::fs::create_dir_all(&sweep.out).with_context(|| format!("creating {}", sweep.out.display()))?;
    let (rows, runs) = run_sweep(&gpu, args, registry, &sweep, &settings)?;
    if let Some(shard) = args.shard {
        let identity = ssm_bench::shard::SweepIdentity {
            ssm_version: env!("CARGO_PKG_VERSION").to_owned(),
            preset: args.preset.clone(),
            scene: sweep.scene_spec.clone(),
            varies: sweep.specs.clone(),
            settings: args.settings.clone(),
            size: sweep.size,
            frames: args.frames,
            pixels: sweep_pixels_name(sweep.pixels),
            x_axis: sweep.x_axis.clone(),
            error: sweep_axis_name(sweep.error),
            runs: sweep.plan.scene_points.len() * sweep.plan.points.len(),
        };
        let record = ssm_bench::shard::ShardRecord { identity, shard, adapter: gpu.info.name.clone(), rows: runs.clone() };
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
        format: args.format,
    };
    write_sweep(&output, &rows, &varied)
}

fn merge_command(args: &MergeArgs) -> Result<()> {
    let merged = ssm_bench::shard::merge(&args.shards)?;
    let identity = &merged.identity;
    let error = <sweep::ErrorAxis as clap::ValueEnum>::from_str(&identity.error, true)
        .map_err(|e| anyhow::anyhow!("the shards' error axis `{}`: {e}", identity.error))?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    if merged.adapters.len() > 1 {
        eprintln!(
            "note: the shards ran on {} adapters ({}); compare times within one shard's rows only",
            merged.adapters.len(),
            merged.adapters.join("; ")
        );
    }
    let adapter = merged.adapters.join(" + ");
    let output = SweepOutput {
        out: &args.out,
        name: identity.preset.as_deref().unwrap_or("custom"),
        adapter: &adapter,
        size: identity.size,
        frames: identity.frames,
        scene_spec: &identity.scene,
        x_axis: &identity.x_axis,
        specs: &identity.varies,
        error,
        format: args.format,
    };
    eprintln!("merged {} shards of {} runs", args.shards.len(), identity.runs);
    write_sweep(&output, &merged.rows, &merged.varied)
}
