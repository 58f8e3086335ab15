//! The data of a measurement: one [`Row`] per technique (and per light) of `results.csv` and
//! `sweep.csv`, as CSV ([`csv`]: written, and read back for `ssm merge`) and as JSON ([`json`]:
//! `--format json`), the counted work's totals with what is unknown kept unknown ([`work`]), and
//! the names of a run's image files ([`visibility_stem`]).
//!
//! Rows are made by [`crate::measure`] and shown by [`crate::present`].

pub mod csv;
pub mod json;
pub mod work;

use ssm_core::metrics::ErrorMetrics;
use ssm_core::{FrameWork, TimingSource};

/// One row of `results.csv` / `sweep.csv`.
#[derive(Clone, Debug)]
pub struct Row {
    /// Scene name as given.
    pub scene: String,
    /// Technique name.
    pub technique: String,
    /// The light this row measures, or `None` for all lights together (errors
    /// averaged over lights, time summed).
    pub light: Option<usize>,
    /// Parameters, `name=value;...`.
    pub params: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Median GPU ms per frame (sum of passes; of this light's passes in a per-light row), when timestamps exist.
    pub gpu_ms_median: Option<f64>,
    /// Minimum GPU ms per frame.
    pub gpu_ms_min: Option<f64>,
    /// First and third quartiles of the GPU ms per frame: the spread printed beside the median
    /// (`None` in per-light rows and without timestamps).
    pub gpu_ms_quartiles: Option<(f64, f64)>,
    /// Median CPU ms per frame of the work inside the frame that a paper puts on the CPU (and
    /// mid-frame read-backs' mapping), part of the frame's time; `None` where there is none.
    pub cpu_step_ms: Option<f64>,
    /// Median CPU wall ms per frame.
    pub cpu_ms: f64,
    /// Error metrics against the reference, averaged over lights.
    pub metrics: ErrorMetrics,
    /// Mean FLIP of the shaded image against the shaded reference.
    pub flip: f64,
    /// FLIP's noise floor on these pixels: what the reference's own noise alone shows
    /// ([`crate::measure::Measured::flip_noise`]); `None` without the reference's noise.
    pub flip_noise: Option<f64>,
    /// Adapter description.
    pub adapter: String,
    /// GPU timestamps or CPU wall time only.
    pub timing_source: TimingSource,
    /// Median ms per pass name.
    pub passes: Vec<(String, f64)>,
    /// Technique diagnostics.
    pub diagnostics: Vec<(String, f64)>,
    /// Names of the technique's extra images (`<name>.png` beside its visibility).
    pub extra_images: Vec<String>,
    /// Those of them the HTML report draws over the visibility image.
    pub overlays: Vec<String>,
    /// The frame's counted work (every light; `--count-work`), in the `all` row only: `None`
    /// when not counted, and in per-light rows.
    pub work: Option<FrameWork>,
}

/// The stem of light `light`'s image files: `visibility` for light 0, `visibility-light<k>` for the others.
#[must_use]
pub fn visibility_stem(light: usize) -> String {
    if light == 0 { "visibility".to_owned() } else { format!("visibility-light{light}") }
}

pub(crate) fn number(value: Option<f64>, decimals: usize) -> String {
    match value {
        Some(v) if v.is_infinite() => "inf".into(),
        Some(v) if v.is_finite() => format!("{v:.decimals$}"),
        _ => String::new(),
    }
}
