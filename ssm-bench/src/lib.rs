//! The `ssm` command-line tool as a library, and support for it and the criterion benches: [`run`]
//! (the whole command line, for any binary that links techniques and calls it), the registry
//! (every technique crate linked through the `ssm-techniques` facade), the bench image size, the
//! rendering of one technique to files, and the charts.
//!
//! # Example
//!
//! The `ssm` binary of a crate of one's own (what `ssm new --standalone` writes): link the
//! techniques, then hand over the command line.
//!
//! ```no_run
//! fn main() -> std::process::ExitCode {
//!     ssm_techniques::link_all(); // or one crate's `ssm_mine::link()`
//!     ssm_bench::run()
//! }
//! ```

pub mod charts;
mod commands;
pub mod docs;
pub mod report;
pub mod shard;
pub mod sweep;
pub mod view;
pub mod work;

use std::path::Path;
use std::process::ExitCode;

use serde_json::json;
use ssm_core::image_io::write_exr_positions;
use ssm_core::{GpuContext, ParamValues, Registry, Renderer, Requirements, TechniqueInfo};

/// Runs the `ssm` command line: parses the arguments (clap), runs the command and returns its exit
/// status. A failure prints one line, `error:` and its causes, on stderr and exits 1; a bad
/// command line prints clap's message and exits 2; a reader that stopped reading (`ssm list |
/// head`) is not a failure.
///
/// The techniques are those of [`registry`]: every technique crate of the workspace, and any
/// other crate linked into the binary that registers one (`ssm_core::register_technique!`). A
/// binary with a technique of its own calls that crate's `link()`, then this:
///
/// ```no_run
/// fn main() -> std::process::ExitCode {
///     // my_technique::link(); (keeps the crate, and with it its registration, in the binary)
///     ssm_bench::run()
/// }
/// ```
///
/// Call it first thing in `main`, before spawning any thread (a `link()` before it is fine: it
/// starts none): without `XDG_RUNTIME_DIR` it sets `NODEVICE_SELECT=1` for the process (which keeps
/// Mesa's device-selection layer from looking for a Wayland session), and changing the
/// environment is sound only while no other thread exists.
#[must_use]
pub fn run() -> ExitCode {
    quiet_window_system_layers();
    match commands::parse_and_run() {
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

/// Without a Wayland session (no `XDG_RUNTIME_DIR`), Mesa's device-selection
/// Vulkan layer still tries to connect to one when wgpu enables the Wayland
/// surface extension, and libwayland prints `error: XDG_RUNTIME_DIR is invalid
/// or not set` on a perfectly good offscreen run. ssm never presents to a
/// window and picks its adapter itself, so the layer is switched off (its own
/// documented switch) for this process.
fn quiet_window_system_layers() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() && std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: called only by `run`, whose contract is to be called first thing in `main`,
        // before any thread exists, so no other thread can read the environment while it changes.
        #[allow(unsafe_code)]
        unsafe {
            std::env::set_var("NODEVICE_SELECT", "1");
        }
    }
}

/// The registry, with every technique crate linked (through the
/// `ssm-techniques` facade: a new technique crate is one line in its manifest).
///
/// # Errors
/// A duplicate technique name.
pub fn registry() -> ssm_core::Result<&'static Registry> {
    ssm_techniques::registry()
}

/// The image size of the criterion benches: `SSM_BENCH_SIZE=WxH`, or `full`
/// for 1280×720; 256×192 by default, small enough for lavapipe.
///
/// # Errors
/// A value that is neither `full` nor `WxH` with positive sides.
pub fn bench_size() -> Result<(u32, u32), String> {
    match std::env::var("SSM_BENCH_SIZE").as_deref() {
        Ok("full") => Ok((1280, 720)),
        Ok(text) => text
            .split_once('x')
            .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
            .filter(|&(w, h): &(u32, u32)| w > 0 && h > 0)
            .ok_or_else(|| format!("SSM_BENCH_SIZE={text}: expected WxH or full")),
        Err(_) => Ok((256, 192)),
    }
}

/// Median of `values` (the mean of the middle two for an even count); `None` when empty.
#[must_use]
pub fn median(values: &[f64]) -> Option<f64> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return None;
    }
    sorted.sort_by(f64::total_cmp);
    let mid = sorted.len() / 2;
    Some(if sorted.len().is_multiple_of(2) { (sorted[mid - 1] + sorted[mid]) * 0.5 } else { sorted[mid] })
}

/// The first and third quartiles of `values` (linear interpolation between order statistics, as
/// numpy's default): the interquartile range a timed point's spread is reported as. `None` when
/// empty; one value is its own range.
#[must_use]
pub fn quartiles(values: &[f64]) -> Option<(f64, f64)> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return None;
    }
    sorted.sort_by(f64::total_cmp);
    let at = |p: f64| {
        let position = p * (sorted.len() - 1) as f64;
        let (below, above) = (position.floor() as usize, position.ceil() as usize);
        sorted[below] + (sorted[above] - sorted[below]) * (position - below as f64)
    };
    Some((at(0.25), at(0.75)))
}

/// The shared inputs every output of `ssm render` needs: the G-buffer, for
/// the shaded image and the world positions.
#[must_use]
pub fn output_requirements() -> Requirements {
    Requirements { gbuffer: true, ..Requirements::NONE }
}

/// What the renderer must build for `techniques` (the union of what each needs, the framework's
/// own-surface share included: `TechniqueInfo::needs`) and for the
/// outputs every command reads ([`output_requirements`]).
///
/// # Errors
/// A technique whose parameters its requirements reject.
pub fn requirements_of<'a>(techniques: impl IntoIterator<Item = (&'a TechniqueInfo, &'a ParamValues)>) -> ssm_core::Result<Requirements> {
    let mut needs = output_requirements();
    for (info, params) in techniques {
        needs = needs.union(info.needs(params)?);
    }
    Ok(needs)
}

/// The debug outputs to ask of `info`: those named in `asked` (`all`: every one it declares),
/// plus its overlays when `overlays` (the HTML report draws them).
#[must_use]
pub fn debug_outputs_for(info: &TechniqueInfo, asked: &[String], overlays: bool) -> Vec<&'static str> {
    let all = asked.iter().any(|a| a == DEBUG_OUTPUT_ALL);
    info.debug_outputs.iter().filter(|o| all || asked.iter().any(|a| a == o.name) || (overlays && o.overlay)).map(|o| o.name).collect()
}

/// `--debug-output all`: every debug output of every technique run.
pub const DEBUG_OUTPUT_ALL: &str = "all";

/// Checks that every name in `asked` is a debug output of at least one of `infos` (or `all`).
///
/// # Errors
/// A name none of them offers; the message lists what each offers.
pub fn check_debug_outputs(asked: &[String], infos: &[&TechniqueInfo]) -> anyhow::Result<()> {
    for name in asked.iter().filter(|a| *a != DEBUG_OUTPUT_ALL) {
        if !infos.iter().any(|info| info.debug_outputs.iter().any(|o| o.name == name)) {
            let offered: Vec<String> = infos
                .iter()
                .map(|info| {
                    let names: Vec<&str> = info.debug_outputs.iter().map(|o| o.name).collect();
                    format!("{}: {}", info.name, if names.is_empty() { "none".to_owned() } else { names.join(", ") })
                })
                .collect();
            anyhow::bail!("--debug-output {name}: no technique run offers it ({}; `ssm list` describes them)", offered.join("; "));
        }
    }
    Ok(())
}

/// Renders `info` with `params` for one warm-up and `frames` timed frames
/// and writes, under `dir`, `visibility.exr`/`.png` (light 0;
/// `visibility-light<k>.*` for the others), `shaded.png`, `timings.json` and
/// `<name>.exr`/`.png` for each of the debug outputs named in `debug` that it offers.
///
/// # Errors
/// Technique, GPU or file errors.
pub fn render_technique(
    renderer: &mut Renderer,
    info: &'static TechniqueInfo,
    params: &ParamValues,
    frames: u32,
    debug: &[&str],
    dir: &Path,
) -> ssm_core::Result<report::Measured> {
    let measured = report::measure(renderer, info, params, frames, debug)?;
    write_run(renderer, &measured, dir)?;
    Ok(measured)
}

/// Writes what [`render_technique`] writes for a technique measured with `renderer` (by
/// [`report::measure`] or [`report::measure_all`]), under `dir`.
///
/// # Errors
/// GPU or file errors.
pub fn write_run(renderer: &Renderer, measured: &report::Measured, dir: &Path) -> ssm_core::Result<()> {
    let info = measured.info;
    let params = &measured.params;
    let coverage = report::pixel_mask(renderer, report::PixelSet::All)?;
    report::write_images(dir, measured, (renderer.width(), renderer.height()), &coverage, None)?;
    let report = json!({
        "technique": info.name,
        "params": params.to_string(),
        "adapter": renderer.gpu.describe(),
        "width": renderer.width(),
        "height": renderer.height(),
        "frames": measured.frames.len(),
        "gpu_ms_median": measured.gpu_ms_median(),
        "gpu_ms_min": measured.gpu_ms_min(),
        "gpu_ms_iqr": measured.gpu_ms_quartiles().map(|(q1, q3)| [q1, q3]),
        "cpu_wall_ms_median": measured.cpu_ms_median(),
        "pass_ms_medians": measured.pass_medians().into_iter().map(|(k, v)| (k, json!(v))).collect::<serde_json::Map<_, _>>(),
        "shared_passes": renderer.shared_timings,
        "frame_timings": measured.frames,
        "diagnostics": measured.diagnostics.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
        // `--count-work`: each pass's counts (null when not counted, with the reason when asked).
        "work": measured.work,
        "work_note": measured.work_note,
    });
    let file = dir.join("timings.json");
    let text = serde_json::to_string_pretty(&report).map_err(|e| ssm_core::Error::write(&file, e))?;
    std::fs::write(&file, text).map_err(|e| ssm_core::Error::write(&file, e))
}

/// Writes the G-buffer's world positions to `position.exr`: `R`, `G`, `B` the
/// position (0 for background), `A` the coverage (1 where geometry covers the
/// pixel, 0 for background; a surface at the origin is not background).
///
/// # Errors
/// GPU or file errors.
pub fn write_positions(renderer: &Renderer, file: &Path) -> ssm_core::Result<()> {
    let positions = renderer.read_positions()?;
    let xyz: Vec<[f32; 3]> = positions.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let covered: Vec<bool> = positions.iter().map(|p| p[3] > 0.5).collect();
    write_exr_positions(file, renderer.width(), renderer.height(), &xyz, &covered)
}

/// Whether `gpu` can run `info` at its default parameters, as a short phrase.
#[must_use]
pub fn support_on(gpu: &GpuContext, info: &TechniqueInfo) -> String {
    match (info.requirements)(&info.default_params()).and_then(|r| r.check_device(info.name, gpu)) {
        Ok(()) => "yes".into(),
        Err(e) => format!("no: {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::{median, quartiles};

    #[test]
    fn quartiles_interpolate_between_order_statistics() {
        assert_eq!(quartiles(&[5.0, 1.0, 4.0, 2.0, 3.0]), Some((2.0, 4.0)));
        assert_eq!(quartiles(&[4.0, 1.0, 3.0, 2.0]), Some((1.75, 3.25)));
        assert_eq!(quartiles(&[7.0, f64::NAN]), Some((7.0, 7.0)));
        assert_eq!(quartiles(&[]), None);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
    }
}
