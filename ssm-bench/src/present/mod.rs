//! Presenting what was measured, from its [`crate::data`] alone: `report.md` ([`markdown`]), the
//! offline `index.html` with the images side by side and its interactive viewer's data
//! ([`page`]), the charts ([`charts`]), the tables of counted work ([`work`]) and a sweep's
//! `sweep.md`, plots and printed lines ([`sweep`]). Here: what `report.md` and `index.html` share
//! (the header's context, the table's cells, the notes under it) and how a command prints.

/// Writes a line to stdout, failing (rather than panicking like `println!`) when stdout is closed.
macro_rules! say {
    ($($arg:tt)*) => {
        writeln!(std::io::stdout().lock(), $($arg)*).context("writing to stdout")?
    };
}
pub(crate) use say;

pub mod charts;
pub mod markdown;
pub mod page;
pub mod sweep;
pub mod work;

use ssm_core::FrameWork;

use crate::data::{Row, number};

/// How a command prints what it found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Format {
    /// Lines for people.
    Text,
    /// One JSON document on stdout, for scripts (progress and notes go to stderr).
    Json,
}

/// What the report header says about the run.
pub struct ReportContext<'a> {
    /// Scene as given.
    pub scene: &'a str,
    /// Adapter description.
    pub adapter: &'a str,
    /// Image size.
    pub size: (u32, u32),
    /// Timed frames per technique.
    pub frames: u32,
    /// The reference's parameters.
    pub reference_params: &'a str,
    /// What the reference's tracing cost (or that it came from the cache).
    pub reference_cost: &'a str,
    /// Techniques not run, with the reason.
    pub skipped: &'a [(String, String)],
    /// The per-pass time chart beside the report (`passes.svg`), when one was drawn.
    pub pass_chart: Option<&'a str>,
    /// Whether the work was counted (`--count-work`): the reports then have a section on it.
    pub count_work: bool,
    /// The per-pass work charts beside the report, when drawn: (what they count, `passes-reads.svg`).
    pub work_charts: &'a [(&'a str, &'a str)],
}

/// The columns of the report tables (Markdown and HTML).
const TABLE_HEADER: [&str; 12] = [
    "technique",
    "params",
    "GPU ms (median)",
    "GPU ms (IQR)",
    "MAE (± truth)",
    "MAE penumbra (± truth)",
    "RMSE",
    "max",
    "PSNR dB",
    "SSIM",
    "> 0.05",
    "FLIP",
];

/// An error with the ground truth's own error over the same pixels beside it: `0.0123 ± 0.0015`.
#[must_use]
pub fn with_noise(error: f64, noise: Option<f64>) -> String {
    match noise {
        Some(noise) => format!("{error:.4} ± {noise:.4}"),
        None => format!("{error:.4}"),
    }
}

/// One row of the report tables, as text (the technique name without markup).
fn table_cells(r: &Row) -> [String; 12] {
    let m = &r.metrics;
    [
        r.technique.clone(),
        r.params.replace(';', "; "),
        number(r.gpu_ms_median, 3),
        r.gpu_ms_quartiles.map_or_else(String::new, |(q1, q3)| format!("{q1:.3}–{q3:.3}")),
        with_noise(m.mae, m.truth_noise),
        with_noise(m.mae_penumbra, m.truth_noise_penumbra),
        format!("{:.4}", m.rmse),
        format!("{:.3}", m.max_abs),
        number(Some(m.psnr), 2),
        format!("{:.4}", m.ssim),
        format!("{:.2}%", m.frac_over_0_05 * 100.0),
        with_noise(r.flip, r.flip_noise),
    ]
}

/// What follows the technique's name in a per-light row: ` · light <k>`.
fn light_suffix(row: &Row) -> String {
    row.light.map(|light| format!(" · light {light}")).unwrap_or_default()
}

/// The counted techniques of `rows` (their `all` rows), in order.
fn counted(rows: &[Row]) -> Vec<(&str, &FrameWork)> {
    rows.iter().filter(|r| r.light.is_none()).filter_map(|r| r.work.as_ref().map(|w| (r.technique.as_str(), w))).collect()
}

/// The pixels of the rows' images (for texel reads per pixel).
fn pixels_of(rows: &[Row]) -> u64 {
    rows.first().map_or(1, |r| u64::from(r.width) * u64::from(r.height))
}

/// The pixels the framework answered past the light frame's widest angle, per technique
/// ([`ssm_core::BEYOND_FRAME_DIAGNOSTIC`]), as one sentence; `None` when it answered none.
#[must_use]
pub fn beyond_frame_note(rows: &[Row]) -> Option<String> {
    let answered: Vec<String> = rows
        .iter()
        .filter(|r| r.light.is_none())
        .filter_map(|r| {
            let pixels = r.diagnostics.iter().find(|(key, _)| key == ssm_core::BEYOND_FRAME_DIAGNOSTIC).map(|(_, v)| *v)?;
            (pixels > 0.0).then(|| format!("`{}` {pixels:.0}", r.technique))
        })
        .collect();
    (!answered.is_empty()).then(|| {
        format!(
            "Past the light frame's widest angle (about 84° off the light's normal) these techniques' maps have no texel: the framework answered those pixels with a hard shadow from the light's centre (pixels, summed over lights: {}).",
            answered.join(", ")
        )
    })
}

/// A sentence on what tracing the ground truth cost, from its diagnostics.
#[must_use]
pub fn reference_cost(diagnostics: &[(String, f64)]) -> String {
    let get = |key: &str| diagnostics.iter().find(|(k, _)| k == key).map(|(_, v)| *v);
    match (get("reference_rays"), get("reference_trace_ms"), get("reference_rays_per_second")) {
        (Some(rays), Some(ms), Some(rate)) if rays > 0.0 => {
            format!(
                "{:.1} M light samples evaluated on the CPU in {:.0} ms ({:.1} M samples/s, exact shares of the light included)",
                rays / 1e6,
                ms,
                rate / 1e6
            )
        }
        _ => "read from the cache".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::csv::tests::sample_row;

    #[test]
    fn the_beyond_frame_note_names_each_technique_the_framework_answered_for() {
        let with = |technique: &str, light: Option<usize>, pixels: f64| {
            let mut row = sample_row(technique, light, Some(1.0));
            row.diagnostics.push((ssm_core::BEYOND_FRAME_DIAGNOSTIC.to_owned(), pixels));
            row
        };
        let rows =
            vec![with("hard", None, 1234.0), with("pcss", Some(0), 99.0), with("vssm", None, 0.0), sample_row("wedges", None, Some(1.0))];
        let note = beyond_frame_note(&rows).unwrap();
        assert!(note.contains("`hard` 1234"), "{note}");
        // Per-light rows repeat the frame's; a technique that answered none, or has no such pass, is not named.
        assert!(!note.contains("pcss") && !note.contains("vssm") && !note.contains("wedges"), "{note}");
        assert_eq!(beyond_frame_note(&rows[2..]), None);
    }
}
