//! The `ssm` command line: the clap definitions of every command, what several commands share
//! (output format, image size, frame order, `--set`, scene loading, the progress bar), and one
//! module per command, each readable on its own: its arguments parsed (and a sweep planned:
//! [`crate::sweep`]), then measured ([`crate::measure`]), then reported ([`crate::data`],
//! [`crate::present`]).

use std::io::Write;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use ssm_core::{ParamValues, TechniqueInfo};
use ssm_scene::{Scene, SceneSource};

use crate::measure::FrameOrder;
use crate::present::{Format, say};

mod compare;
mod list;
mod merge;
mod new;
mod render;
mod sweep;
mod view;

/// Parses the command line and runs the command it names. A bad command line prints clap's
/// message and exits the process (status 2), as clap does.
pub(crate) fn parse_and_run() -> Result<()> {
    match Cli::parse().command {
        Command::List(args) => match &args.parameters_of {
            Some(name) => list::parameters_markdown(name),
            None => list::techniques(args.format.format),
        },
        Command::Scenes(args) => list::scenes(args.format),
        Command::Render(args) => render::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::View(args) => view::run(&args),
        Command::New(args) => new::run(&args),
    }
}

#[derive(Parser)]
#[command(name = "ssm", version, about = "Soft-shadow techniques as plug-ins, compared on identical scenes")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the registered techniques with their parameters, requirements and whether this adapter runs them.
    List(ListArgs),
    /// List the built-in scenes and their parameters (`--scene forest:triangles=800000`).
    Scenes(FormatArgs),
    /// Render a scene with one or more techniques and write images and timings.
    Render(render::RenderArgs),
    /// Render every technique (or those named) and the ground truth; write results.csv, report.md and index.html.
    Compare(compare::CompareArgs),
    /// Vary techniques' parameters over a grid; write sweep.csv, sweep.md and the time-against-error plot (PNG, SVG).
    Sweep(sweep::SweepArgs),
    /// A live window: the scene shaded with one technique at a time (number keys switch), a panel of its
    /// parameters, per-pass GPU times and the error against the cached ground truth; drag to orbit.
    View(view::ViewArgs),
    /// Put the shards of a sweep (`ssm sweep --shard K/N` outputs) back together: sweep.csv, sweep.md and the plot.
    Merge(merge::MergeArgs),
    /// Start a new technique: its crate, WGSL, README and test, a percentage-closer filter to replace with a paper's method; in
    /// this checkout (and the facade's one line), or with --standalone DIR as a crate of its own whose binary is `ssm` with it linked.
    New(new::NewArgs),
}

#[derive(clap::Args)]
struct ListArgs {
    #[command(flatten)]
    format: FormatArgs,
    /// Print only this technique's parameter table, in Markdown, as its README carries it
    /// between `<!-- parameters -->` and `<!-- /parameters -->`.
    #[arg(long, value_name = "TECHNIQUE")]
    parameters_of: Option<String>,
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

/// `--count-work`, as every rendering command takes it.
#[derive(clap::Args, Clone, Copy)]
struct CountWorkArg {
    /// After each technique's timed frames, render one extra, untimed frame that counts its work,
    /// per pass and per frame: vertex, fragment and compute invocations and primitives (pipeline
    /// statistics), texel reads, atomics and storage bytes (as its shaders count them) and bytes
    /// stored to render targets. Times are unaffected; the ground truth (CPU) is not counted.
    #[arg(long)]
    count_work: bool,
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
    /// The order `--sequential` asks for.
    fn order(self) -> FrameOrder {
        if self.sequential { FrameOrder::Sequential } else { FrameOrder::Interleaved }
    }
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
