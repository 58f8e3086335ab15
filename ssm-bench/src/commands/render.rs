//! `ssm render`: a scene rendered with one or more techniques, written as images and timings.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use ssm_core::{GpuContext, Renderer};

use super::{CountWorkArg, FrameOrderArgs, ImageSize, load_scene, params_for, parse_setting, progress_bar};
use crate::measure::files::{write_positions, write_run};
use crate::measure::needs::{check_debug_outputs, debug_outputs_for, requirements_of};
use crate::measure::{MeasureJob, measure_all};
use crate::present::work::{FRAME_HEADER, PASS_HEADER, frame_table, notes, pass_table};
use crate::present::{Format, say};
use crate::registry;

/// `ssm render`'s arguments.
#[derive(clap::Args)]
pub(super) struct RenderArgs {
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
    /// Frames timed after one warm-up frame; timings.json holds each, the median and the
    /// interquartile range.
    #[arg(long, default_value_t = 5)]
    frames: u32,
    #[command(flatten)]
    work: CountWorkArg,
    /// Debug outputs to write beside each technique's visibility, comma-separated (`ssm list`
    /// shows what each technique offers; `all`: every one).
    #[arg(long = "debug-output", value_delimiter = ',', value_name = "NAME")]
    debug_outputs: Vec<String>,
    /// Output directory: <out>/<technique>/{visibility.exr,visibility.png,shaded.png,timings.json} and <out>/position.exr.
    #[arg(long)]
    out: PathBuf,
}

/// Renders the scene with each technique (their frames in turns unless `--sequential`) and writes
/// every technique's images and timings, and the world positions.
pub(super) fn run(args: &RenderArgs) -> Result<()> {
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
    let count_work = args.work.count_work;
    let jobs: Vec<MeasureJob<'_>> =
        runs.iter().zip(&debug).map(|((info, params), debug)| MeasureJob { info, params, debug, count_work }).collect();
    // Technique errors name the technique already.
    let measured = measure_all(&mut renderer, &jobs, args.frames, args.frame_order.order(), || progress.inc(1))?;
    progress.finish_and_clear();
    for run in &measured {
        let info = run.info;
        let dir = args.out.join(info.name);
        write_run(&renderer, run, &dir)?;
        let time = match run.gpu_ms_median() {
            Some(ms) => match run.gpu_ms_quartiles() {
                Some((q1, q3)) if run.frames.len() > 1 => {
                    format!("{ms:.3} ms GPU (median; IQR {q1:.3}–{q3:.3}, {} frames)", run.frames.len())
                }
                _ => format!("{ms:.3} ms GPU"),
            },
            None => format!("{:.3} ms CPU wall (no timestamps)", run.cpu_ms_median()),
        };
        say!("{:<8} {time}  [{}]  -> {}", info.name, run.params, dir.display());
        if !run.diagnostics.is_empty() {
            let text: Vec<String> = run.diagnostics.iter().map(|(k, v)| format!("{k}={v:.4}")).collect();
            say!("{:<8} {}", "", text.join("  "));
        }
        if let Some(note) = run.work_note {
            say!("{:<8} work: {note}", "");
        }
    }
    // The counted work, per frame and per pass (as report.md's section), `-` where not counted.
    let counted: Vec<(&str, &ssm_core::FrameWork)> = measured.iter().filter_map(|m| m.work.as_ref().map(|w| (m.info.name, w))).collect();
    if !counted.is_empty() {
        let pixels = u64::from(args.size.width) * u64::from(args.size.height);
        let lines = |header: &[&str], rows: Vec<[String; 13]>| -> Vec<String> {
            std::iter::once(header.join("\t")).chain(rows.iter().map(|row| row.join("\t"))).collect()
        };
        say!("counted work per frame (every light):");
        for line in lines(&FRAME_HEADER, frame_table(&counted, pixels)) {
            say!("  {line}");
        }
        say!("counted work per pass:");
        for line in lines(&PASS_HEADER, pass_table(&counted)) {
            say!("  {line}");
        }
        for note in notes(&counted) {
            say!("note: {note}");
        }
    }
    say!("adapter: {}", gpu.describe());
    Ok(())
}
