//! Support for the `ssm` command-line tool and the criterion benches: the
//! list of linked technique crates and the rendering of one technique to files.

use std::path::Path;

use serde_json::json;
use ssm_core::image_io::{write_exr_gray, write_exr_rgb, write_png_gray16, write_png_rgba8};
use ssm_core::{
    FrameTimings, GpuContext, ParamValues, Registry, Renderer, Requirements, TechniqueInfo,
};

/// Keeps every technique crate linked into the binary, so that their
/// registrations reach the registry. A new technique crate adds one line here
/// and one dependency in this crate's manifest.
pub fn link_techniques() -> [&'static str; 4] {
    [
        ssm_core::reference::link(),
        ssm_hard::link(),
        ssm_multi_sm::link(),
        ssm_pcss::link(),
    ]
}

/// The registry, with every technique crate linked.
///
/// # Errors
/// A duplicate technique name.
pub fn registry() -> ssm_core::Result<&'static Registry> {
    link_techniques();
    Registry::global()
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
    Some(if sorted.len().is_multiple_of(2) {
        (sorted[mid - 1] + sorted[mid]) * 0.5
    } else {
        sorted[mid]
    })
}

/// The shared inputs every output of `ssm render` needs: the G-buffer, for
/// the shaded image and the world positions.
#[must_use]
pub fn output_requirements() -> Requirements {
    Requirements {
        gbuffer: true,
        ..Requirements::NONE
    }
}

/// What rendering one technique produced.
#[derive(Debug)]
pub struct TechniqueRun {
    /// Timings of every measured frame.
    pub frames: Vec<FrameTimings>,
    /// Technique diagnostics after the last frame.
    pub diagnostics: Vec<(String, f64)>,
}

/// Renders `info` with `params` for `warmup + frames` frames and writes, under
/// `dir`, `visibility.exr`/`.png` (light 0; `visibility-light<k>.*` for the
/// others), `shaded.png` and `timings.json`.
///
/// # Errors
/// Technique, GPU or file errors.
pub fn render_technique(
    renderer: &mut Renderer,
    info: &TechniqueInfo,
    params: &ParamValues,
    frames: u32,
    dir: &Path,
) -> ssm_core::Result<TechniqueRun> {
    let write_error = |e: std::io::Error| ssm_core::Error::Write {
        file: dir.into(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(dir).map_err(write_error)?;
    let mut technique = renderer.create_technique(info, params)?;
    // One warm-up frame: pipeline compilation and first-use allocation are not the technique's cost.
    renderer.render(technique.as_mut(), info.name)?;
    let mut timings = Vec::new();
    for _ in 0..frames.max(1) {
        timings.push(renderer.render(technique.as_mut(), info.name)?);
    }
    let (width, height) = (renderer.width(), renderer.height());
    for light in 0..renderer.scene.light_count() {
        let visibility = renderer.read_visibility(light, info.name)?;
        let stem = if light == 0 {
            "visibility".to_owned()
        } else {
            format!("visibility-light{light}")
        };
        write_exr_gray(&dir.join(format!("{stem}.exr")), width, height, &visibility)?;
        write_png_gray16(&dir.join(format!("{stem}.png")), width, height, &visibility)?;
    }
    let shaded = renderer.shade()?;
    write_png_rgba8(&dir.join("shaded.png"), width, height, &shaded)?;
    let diagnostics = technique.diagnostics();
    let gpu_ms: Vec<f64> = timings.iter().filter_map(|t| t.gpu_ms).collect();
    let cpu_ms: Vec<f64> = timings.iter().map(|t| t.cpu_wall_ms).collect();
    let report = json!({
        "technique": info.name,
        "params": params.to_string(),
        "adapter": renderer.gpu.describe(),
        "width": width,
        "height": height,
        "frames": timings.len(),
        "gpu_ms_median": median(&gpu_ms),
        "cpu_wall_ms_median": median(&cpu_ms),
        "shared_passes": renderer.shared_timings,
        "frame_timings": timings,
        "diagnostics": diagnostics.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
    });
    let text = serde_json::to_string_pretty(&report).map_err(|e| ssm_core::Error::Write {
        file: dir.join("timings.json"),
        message: e.to_string(),
    })?;
    std::fs::write(dir.join("timings.json"), text).map_err(|e| ssm_core::Error::Write {
        file: dir.join("timings.json"),
        message: e.to_string(),
    })?;
    Ok(TechniqueRun {
        frames: timings,
        diagnostics,
    })
}

/// Writes the G-buffer's world positions (`position.exr`, RGB; background pixels are 0).
///
/// # Errors
/// GPU or file errors.
pub fn write_positions(renderer: &Renderer, file: &Path) -> ssm_core::Result<()> {
    let positions = renderer.read_positions()?;
    let rgb: Vec<[f32; 3]> = positions
        .iter()
        .map(|p| {
            if p[3] > 0.5 {
                [p[0], p[1], p[2]]
            } else {
                [0.0; 3]
            }
        })
        .collect();
    write_exr_rgb(file, renderer.width(), renderer.height(), &rgb)
}

/// Whether `gpu` can run `info` at its default parameters, as a short phrase.
#[must_use]
pub fn support_on(gpu: &GpuContext, info: &TechniqueInfo) -> String {
    match (info.requirements)(&info.default_params()).and_then(|r| r.check_device(info.name, gpu)) {
        Ok(()) => "yes".into(),
        Err(e) => format!("no: {e}"),
    }
}
