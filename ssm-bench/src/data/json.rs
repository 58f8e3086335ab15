//! A row as JSON (`--format json`): the CSV's columns, typed ([`row_json`]).

use ssm_core::{FrameWork, TimingSource};

use super::Row;
use super::work::Totals;

/// One row as JSON (`--format json`): the CSV's columns, typed; the errors under `metrics`,
/// passes and diagnostics as objects; infinite or missing numbers as `null`.
#[must_use]
pub fn row_json(row: &Row) -> serde_json::Value {
    let object = |items: &[(String, f64)]| items.iter().map(|(k, v)| (k.clone(), finite(*v))).collect::<serde_json::Map<_, _>>();
    let m = &row.metrics;
    let totals = row.work.as_ref().map(Totals::of);
    serde_json::json!({
        "scene": row.scene,
        "technique": row.technique,
        "light": row.light,
        "params": row.params,
        "width": row.width,
        "height": row.height,
        "gpu_ms_median": row.gpu_ms_median.map(finite),
        "gpu_ms_min": row.gpu_ms_min.map(finite),
        "gpu_ms_iqr": row.gpu_ms_quartiles.map(|(q1, q3)| [finite(q1), finite(q3)]),
        "cpu_step_ms": row.cpu_step_ms.map(finite),
        "flip_noise": row.flip_noise.map(finite),
        "cpu_ms": finite(row.cpu_ms),
        "metrics": {
            "mae": finite(m.mae),
            "truth_noise": m.truth_noise.map(finite),
            "mae_penumbra": finite(m.mae_penumbra),
            "truth_noise_penumbra": m.truth_noise_penumbra.map(finite),
            "shadowed_pixels": m.shadowed_pixels,
            "rmse": finite(m.rmse),
            "max_abs": finite(m.max_abs),
            "psnr": finite(m.psnr),
            "ssim": finite(m.ssim),
            "frac_over_0_05": finite(m.frac_over_0_05),
            "mean_signed_error": finite(m.mean_signed),
            "umbra_leak": finite(m.umbra_leak),
            "penumbra_pixels": m.penumbra_pixels,
            "umbra_pixels": m.umbra_pixels,
        },
        "flip_mean": finite(row.flip),
        "adapter": row.adapter,
        "timing_source": match row.timing_source {
            TimingSource::GpuTimestamps => "gpu_timestamps",
            TimingSource::CpuWallOnly => "cpu_wall_only",
        },
        "passes_ms": object(&row.passes),
        "diagnostics": object(&row.diagnostics),
        "vertex_invocations": totals.and_then(|t| t.vertex_invocations),
        "fragment_invocations": totals.and_then(|t| t.fragment_invocations),
        "compute_invocations": totals.and_then(|t| t.compute_invocations),
        "texel_reads": totals.and_then(|t| t.texel_reads),
        "read_bytes": totals.and_then(|t| t.read_bytes),
        "passes_work": row.work.as_ref().map(FrameWork::passes_column),
        // Every pass's counts, and whether the invocations (pipeline_statistics) and the texel
        // reads (shader_counts) were counted at all.
        "work": row.work.as_ref().map(|work| serde_json::to_value(work).unwrap_or(serde_json::Value::Null)),
    })
}

/// A number for JSON: `null` when not finite (JSON has no infinity; PSNR of identical images is one).
pub(crate) fn finite(value: f64) -> serde_json::Value {
    if value.is_finite() { serde_json::json!(value) } else { serde_json::Value::Null }
}
