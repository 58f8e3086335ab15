//! What a measured run writes to disk: its images (visibility, shaded, the heat maps against the
//! ground truth, the debug outputs: [`write_images`]), its `timings.json` ([`write_run`]), the
//! world positions ([`write_positions`]), and one technique measured and written at once
//! ([`render_technique`]).

use std::path::Path;

use serde_json::json;
use ssm_core::image_io::{write_exr_gray, write_exr_positions, write_png_gray16, write_png_rgba8};
use ssm_core::metrics::{flip_map, heat_map};
use ssm_core::{Error, ParamValues, Renderer, Result, TechniqueInfo};

use super::pixels::{PixelSet, pixel_mask};
use super::{Measured, measure};
use crate::data::visibility_stem;

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
) -> Result<Measured> {
    let measured = measure(renderer, info, params, frames, debug)?;
    write_run(renderer, &measured, dir)?;
    Ok(measured)
}

/// Writes what [`render_technique`] writes for a technique measured with `renderer` (by
/// [`measure`] or [`measure_all`](super::measure_all)), under `dir`.
///
/// # Errors
/// GPU or file errors.
pub fn write_run(renderer: &Renderer, measured: &Measured, dir: &Path) -> Result<()> {
    let info = measured.info;
    let params = &measured.params;
    let coverage = pixel_mask(renderer, PixelSet::All)?;
    write_images(dir, measured, (renderer.width(), renderer.height()), &coverage, None)?;
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
pub fn write_positions(renderer: &Renderer, file: &Path) -> Result<()> {
    let positions = renderer.read_positions()?;
    let xyz: Vec<[f32; 3]> = positions.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let covered: Vec<bool> = positions.iter().map(|p| p[3] > 0.5).collect();
    write_exr_positions(file, renderer.width(), renderer.height(), &xyz, &covered)
}

/// Writes a measured technique's images under `dir`: `visibility.exr`/`.png`
/// (light 0; `visibility-light<k>.*` for the others; the EXR's `A` channel is
/// `coverage`) and `shaded.png`; with a reference, also `heatmap.png` (light
/// 0; `heatmap-light<k>.png` for the others) over the pixels it marks.
///
/// # Errors
/// File errors.
pub fn write_images(
    dir: &Path,
    measured: &Measured,
    (width, height): (u32, u32),
    coverage: &[bool],
    reference: Option<(&Measured, &[bool])>,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::write(dir, e))?;
    for (light, visibility) in measured.visibility.iter().enumerate() {
        let stem = visibility_stem(light);
        write_exr_gray(&dir.join(format!("{stem}.exr")), width, height, visibility, coverage)?;
        write_png_gray16(&dir.join(format!("{stem}.png")), width, height, visibility)?;
    }
    write_png_rgba8(&dir.join("shaded.png"), width, height, &measured.shaded)?;
    for extra in &measured.extra_images {
        let extra_coverage: &[bool] =
            if (extra.width, extra.height) == (width, height) { coverage } else { &vec![true; extra.values.len()] };
        write_exr_gray(&dir.join(format!("{}.exr", extra.name)), extra.width, extra.height, &extra.values, extra_coverage)?;
        write_png_gray16(&dir.join(format!("{}.png", extra.name)), extra.width, extra.height, &extra.values)?;
    }
    if let Some((reference, covered)) = reference {
        for (light, (truth, image)) in reference.visibility.iter().zip(&measured.visibility).enumerate() {
            let file = dir.join(if light == 0 { "heatmap.png".to_owned() } else { format!("heatmap-light{light}.png") });
            let rgb = heat_map(truth, image, covered, 0.5);
            let picture =
                image::RgbImage::from_raw(width, height, rgb).ok_or_else(|| Error::write(&file, ssm_core::Reason("buffer size".into())))?;
            picture.save(&file).map_err(|e| Error::write(&file, e))?;
        }
        let file = dir.join("flip.png");
        let rgb = flip_map(&reference.shaded, &measured.shaded, width, height);
        let picture =
            image::RgbImage::from_raw(width, height, rgb).ok_or_else(|| Error::write(&file, ssm_core::Reason("buffer size".into())))?;
        picture.save(&file).map_err(|e| Error::write(&file, e))?;
    }
    Ok(())
}
