//! The comparison with the ground truth: a measured technique's errors against the truth's on the
//! same pixels, with the truth's own noise beside them ([`truth_noise`]), as the [`Row`] of every
//! light together ([`row`]) and one [`Row`] per light ([`rows_per_light`]).

use ssm_core::metrics::{ErrorMetrics, compare_with_noise, flip_mean};
use ssm_core::{Renderer, TimingSource};

use super::Measured;
use crate::data::Row;
use crate::stats::average;

/// Builds the row of `measured` against `reference` over all lights (same
/// pixels; `covered` marks the pixels the metrics cover): errors averaged over
/// lights, FLIP of the shaded image (all lights), GPU time of the whole frame.
#[must_use]
pub fn row(scene: &str, renderer: &Renderer, measured: &Measured, reference: &Measured, covered: &[bool]) -> Row {
    let (width, height) = (renderer.width(), renderer.height());
    let per_light: Vec<ErrorMetrics> = measured
        .visibility
        .iter()
        .zip(&reference.visibility)
        .enumerate()
        .map(|(light, (image, truth))| {
            compare_with_noise(truth, truth_noise(reference, light), image, covered, width as usize, height as usize)
        })
        .collect();
    Row {
        scene: scene.to_owned(),
        technique: measured.info.name.to_owned(),
        light: None,
        params: measured.params.to_string(),
        width,
        height,
        gpu_ms_median: measured.gpu_ms_median(),
        gpu_ms_min: measured.gpu_ms_min(),
        gpu_ms_quartiles: measured.gpu_ms_quartiles(),
        cpu_step_ms: measured.cpu_step_ms_median(),
        cpu_ms: measured.cpu_ms_median(),
        metrics: average(&per_light),
        flip: flip_mean(&reference.shaded, &measured.shaded, width, height),
        flip_noise: reference.flip_noise,
        adapter: renderer.gpu.describe(),
        timing_source: measured.frames.first().map_or(TimingSource::CpuWallOnly, |f| f.source),
        passes: measured.pass_medians(),
        diagnostics: measured.diagnostics.clone(),
        extra_images: measured.extra_images.iter().map(|e| e.name.clone()).collect(),
        overlays: measured.extra_images.iter().filter(|e| e.overlay).map(|e| e.name.clone()).collect(),
        work: measured.work.clone(),
    }
}

/// The total row (as [`row`]) followed, when the scene has more than one
/// light, by one row per light: that light's errors and the GPU time of the
/// passes recorded for it. The shaded image combines all lights, so per-light
/// rows repeat the total's FLIP.
#[must_use]
pub fn rows_per_light(scene: &str, renderer: &Renderer, measured: &Measured, reference: &Measured, covered: &[bool]) -> Vec<Row> {
    let total = row(scene, renderer, measured, reference, covered);
    let (width, height) = (renderer.width() as usize, renderer.height() as usize);
    let mut rows = Vec::new();
    if measured.visibility.len() > 1 {
        for (light, (image, truth)) in measured.visibility.iter().zip(&reference.visibility).enumerate() {
            rows.push(Row {
                light: Some(light),
                gpu_ms_median: measured.gpu_ms_median_for_light(light),
                gpu_ms_min: None,
                gpu_ms_quartiles: None,
                cpu_step_ms: None,
                metrics: compare_with_noise(truth, truth_noise(reference, light), image, covered, width, height),
                passes: measured.pass_medians_for_light(light),
                // Counted over the whole frame: the `all` row holds it.
                work: None,
                ..total.clone()
            });
        }
    }
    rows.insert(0, total);
    rows
}

/// The ground truth's noise image of light `light`, when the reference was measured with its
/// noise output ([`ssm_core::reference::NOISE_OUTPUT`]).
#[must_use]
pub fn truth_noise(reference: &Measured, light: usize) -> Option<&[f32]> {
    let name = if light == 0 {
        ssm_core::reference::NOISE_OUTPUT.to_owned()
    } else {
        format!("{}-light{light}", ssm_core::reference::NOISE_OUTPUT)
    };
    reference.extra_images.iter().find(|image| image.name == name).map(|image| image.values.as_slice())
}
