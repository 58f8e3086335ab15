//! `results.csv` and `sweep.csv`: the columns ([`CSV_COLUMNS`]), the rows written ([`csv`]) and
//! read back ([`parse_csv`], what `ssm merge` reads).

use ssm_core::metrics::ErrorMetrics;
use ssm_core::{FrameWork, TimingSource};

use super::work::{Totals, field, parse_passes_column};
use super::{Row, number};

/// The leading columns of `results.csv`, in order; more follow.
pub const CSV_COLUMNS: &[&str] = &[
    "scene",
    "technique",
    "params",
    "width",
    "height",
    "gpu_ms_median",
    "gpu_ms_min",
    "cpu_ms",
    "mae_penumbra",
    "rmse",
    "max_abs",
    "psnr",
    "ssim",
    "frac_over_0_05",
    "adapter",
    "light",
    "flip_mean",
    "mean_signed_error",
    "umbra_leak",
    "penumbra_pixels",
    "umbra_pixels",
    "timing_source",
    "passes_ms",
    "diagnostics",
    "vertex_invocations",
    "fragment_invocations",
    "compute_invocations",
    "texel_reads",
    "passes_work",
    "mae",
    "truth_noise",
    "truth_noise_penumbra",
    "shadowed_pixels",
    "gpu_ms_q1",
    "gpu_ms_q3",
    "cpu_step_ms",
    "read_bytes",
    "flip_noise",
];

fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_owned() }
}

fn pairs(items: &[(String, f64)]) -> String {
    items.iter().map(|(k, v)| format!("{k}={v:.4}")).collect::<Vec<_>>().join(";")
}

impl Row {
    fn csv_fields(&self) -> Vec<String> {
        let m = &self.metrics;
        vec![
            csv_field(&self.scene),
            csv_field(&self.technique),
            csv_field(&self.params),
            self.width.to_string(),
            self.height.to_string(),
            number(self.gpu_ms_median, 4),
            number(self.gpu_ms_min, 4),
            number(Some(self.cpu_ms), 4),
            number(Some(m.mae_penumbra), 6),
            number(Some(m.rmse), 6),
            number(Some(m.max_abs), 6),
            number(Some(m.psnr), 4),
            number(Some(m.ssim), 6),
            number(Some(m.frac_over_0_05), 6),
            csv_field(&self.adapter),
            self.light.map_or_else(|| "all".to_owned(), |light| light.to_string()),
            number(Some(self.flip), 6),
            number(Some(m.mean_signed), 6),
            number(Some(m.umbra_leak), 6),
            m.penumbra_pixels.to_string(),
            m.umbra_pixels.to_string(),
            match self.timing_source {
                TimingSource::GpuTimestamps => "gpu_timestamps".into(),
                TimingSource::CpuWallOnly => "cpu_wall_only".into(),
            },
            csv_field(&pairs(&self.passes)),
            csv_field(&pairs(&self.diagnostics)),
        ]
        .into_iter()
        .chain(self.work_fields())
        .chain([number(Some(m.mae), 6), number(m.truth_noise, 6), number(m.truth_noise_penumbra, 6), m.shadowed_pixels.to_string()])
        .chain([number(self.gpu_ms_quartiles.map(|q| q.0), 4), number(self.gpu_ms_quartiles.map(|q| q.1), 4), number(self.cpu_step_ms, 4)])
        // Derived from `passes_work` (each pass's `read_bytes`), which the CSV reads back.
        .chain([self.work.as_ref().map_or_else(String::new, |work| field(Totals::of(work).read_bytes))])
        .chain([number(self.flip_noise, 6)])
        .collect()
    }

    /// The work columns: per frame (every light) vertex, fragment and compute invocations and
    /// texel reads, then `passes_work`; empty where not counted.
    fn work_fields(&self) -> [String; 5] {
        match &self.work {
            None => Default::default(),
            Some(work) => {
                let totals = Totals::of(work);
                [
                    field(totals.vertex_invocations),
                    field(totals.fragment_invocations),
                    field(totals.compute_invocations),
                    field(totals.texel_reads),
                    csv_field(&work.passes_column()),
                ]
            }
        }
    }
}

/// The CSV text of `rows`, header first.
#[must_use]
pub fn csv(rows: &[Row]) -> String {
    let mut out = CSV_COLUMNS.join(",") + "\n";
    for row in rows {
        out += &row.csv_fields().join(",");
        out.push('\n');
    }
    out
}

/// Rows from the text of a `results.csv` or `sweep.csv` that [`csv`] wrote (what `ssm merge`
/// reads back). The CSV does not hold the image names or the count of compared pixels: they come
/// back empty. Numbers come back as printed, so that writing the rows again gives the same text.
///
/// # Errors
/// A header other than [`CSV_COLUMNS`], a row with another number of fields, or a field that
/// does not parse, naming the line and the column.
pub fn parse_csv(text: &str) -> anyhow::Result<Vec<Row>> {
    use anyhow::Context as _;
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    if header != CSV_COLUMNS.join(",") {
        anyhow::bail!("the header is not ssm's CSV header ({})", CSV_COLUMNS.join(","));
    }
    lines
        .enumerate()
        .filter(|(_, line)| !line.is_empty())
        .map(|(index, line)| {
            let line_number = index + 2;
            let fields = split_csv_line(line).with_context(|| format!("line {line_number}"))?;
            if fields.len() != CSV_COLUMNS.len() {
                anyhow::bail!("line {line_number}: {} fields, expected {}", fields.len(), CSV_COLUMNS.len());
            }
            let field = |name: &str| -> &str {
                let column = CSV_COLUMNS.iter().position(|c| *c == name).unwrap_or(0);
                fields[column].as_str()
            };
            let float = |name: &str| -> anyhow::Result<f64> {
                match field(name) {
                    "" => Ok(f64::NAN),
                    text => text.parse().with_context(|| format!("line {line_number}, {name}: `{text}` is not a number")),
                }
            };
            let optional =
                |name: &str| -> anyhow::Result<Option<f64>> { if field(name).is_empty() { Ok(None) } else { float(name).map(Some) } };
            let whole = |name: &str| -> anyhow::Result<usize> {
                field(name).parse().with_context(|| format!("line {line_number}, {name}: `{}` is not a whole number", field(name)))
            };
            let pairs = |name: &str| -> anyhow::Result<Vec<(String, f64)>> {
                field(name)
                    .split(';')
                    .filter(|p| !p.is_empty())
                    .map(|pair| {
                        let (key, value) =
                            pair.split_once('=').with_context(|| format!("line {line_number}, {name}: `{pair}` is not key=value"))?;
                        Ok((
                            key.to_owned(),
                            value.parse().with_context(|| format!("line {line_number}, {name}: `{value}` is not a number"))?,
                        ))
                    })
                    .collect()
            };
            Ok(Row {
                scene: field("scene").to_owned(),
                technique: field("technique").to_owned(),
                light: match field("light") {
                    "all" => None,
                    _ => Some(whole("light")?),
                },
                params: field("params").to_owned(),
                width: u32::try_from(whole("width")?).context("width")?,
                height: u32::try_from(whole("height")?).context("height")?,
                gpu_ms_median: optional("gpu_ms_median")?,
                gpu_ms_min: optional("gpu_ms_min")?,
                gpu_ms_quartiles: optional("gpu_ms_q1")?.zip(optional("gpu_ms_q3")?),
                cpu_step_ms: optional("cpu_step_ms")?,
                flip_noise: optional("flip_noise")?,
                cpu_ms: float("cpu_ms")?,
                metrics: ErrorMetrics {
                    mae: float("mae")?,
                    mae_penumbra: float("mae_penumbra")?,
                    truth_noise: optional("truth_noise")?,
                    truth_noise_penumbra: optional("truth_noise_penumbra")?,
                    shadowed_pixels: whole("shadowed_pixels")?,
                    rmse: float("rmse")?,
                    max_abs: float("max_abs")?,
                    psnr: float("psnr")?,
                    ssim: float("ssim")?,
                    frac_over_0_05: float("frac_over_0_05")?,
                    mean_signed: float("mean_signed_error")?,
                    umbra_leak: float("umbra_leak")?,
                    pixels: 0,
                    penumbra_pixels: whole("penumbra_pixels")?,
                    umbra_pixels: whole("umbra_pixels")?,
                },
                flip: float("flip_mean")?,
                adapter: field("adapter").to_owned(),
                timing_source: match field("timing_source") {
                    "gpu_timestamps" => TimingSource::GpuTimestamps,
                    "cpu_wall_only" => TimingSource::CpuWallOnly,
                    other => anyhow::bail!("line {line_number}, timing_source: `{other}` is neither gpu_timestamps nor cpu_wall_only"),
                },
                passes: pairs("passes_ms")?,
                diagnostics: pairs("diagnostics")?,
                extra_images: Vec::new(),
                overlays: Vec::new(),
                work: {
                    let columns = ["vertex_invocations", "fragment_invocations", "compute_invocations", "texel_reads", "passes_work"];
                    if columns.iter().all(|c| field(c).is_empty()) {
                        None
                    } else {
                        Some(FrameWork {
                            pipeline_statistics: !field("vertex_invocations").is_empty(),
                            shader_counts: !field("texel_reads").is_empty(),
                            passes: parse_passes_column(field("passes_work")).with_context(|| format!("line {line_number}"))?,
                            uncounted_passes: 0,
                            // Already among the row's diagnostics column.
                            diagnostics: Vec::new(),
                        })
                    }
                },
            })
        })
        .collect()
}

/// The fields of one CSV line: separated by commas, a field in double quotes may hold commas and
/// doubled quotes (as [`csv_field`] writes them).
fn split_csv_line(line: &str) -> anyhow::Result<Vec<String>> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut chars = line.chars().peekable();
    let mut quoted = false;
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', false) if field.is_empty() => quoted = true,
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', true) => quoted = false,
            (',', false) => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    if quoted {
        anyhow::bail!("a quoted field is not closed");
    }
    fields.push(field);
    Ok(fields)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(csv_field("q\",x"), "\"q\"\",x\"");
        assert_eq!(number(Some(f64::INFINITY), 2), "inf");
        assert_eq!(number(None, 2), "");
    }

    /// A row of every column, for the tests: `gpu` None is a row timed on the CPU alone.
    pub(crate) fn sample_row(technique: &str, light: Option<usize>, gpu: Option<f64>) -> Row {
        Row {
            scene: "parallel-square[light_scale=0.5]".into(),
            technique: technique.into(),
            light,
            params: "a=1;b=x,y".into(),
            width: 96,
            height: 72,
            gpu_ms_median: gpu,
            gpu_ms_min: gpu,
            gpu_ms_quartiles: gpu.map(|ms| (ms * 0.9, ms * 1.1)),
            cpu_step_ms: gpu.map(|ms| ms * 0.25),
            flip_noise: gpu.map(|_| 0.0012),
            cpu_ms: 12.5,
            metrics: ErrorMetrics {
                mae: 0.0234567,
                mae_penumbra: 0.0123456,
                truth_noise: gpu.map(|_| 0.0012345),
                truth_noise_penumbra: Some(0.0023456),
                shadowed_pixels: 25,
                rmse: 0.5,
                max_abs: 1.0,
                psnr: f64::INFINITY,
                ssim: 0.987654321,
                frac_over_0_05: 0.25,
                mean_signed: -0.001,
                umbra_leak: 0.02,
                pixels: 0,
                penumbra_pixels: 17,
                umbra_pixels: 3,
            },
            flip: 0.1,
            adapter: "llvmpipe \"x\", y".into(),
            timing_source: if gpu.is_some() { TimingSource::GpuTimestamps } else { TimingSource::CpuWallOnly },
            passes: vec![("hard_shadow_map".into(), 1.25), ("hard_filter".into(), 2.0)],
            diagnostics: vec![("memory_mib".into(), 4.0)],
            extra_images: Vec::new(),
            overlays: Vec::new(),
            work: None,
        }
    }

    #[test]
    fn rows_read_back_from_their_csv_give_the_same_csv() {
        let row = sample_row;
        let mut rows = vec![row("hard", None, Some(3.25)), row("pcss", Some(1), None), row("pcss", None, None)];
        // Counted with pipeline statistics but not in the shaders: its reads are unknown, not 0.
        rows[0].work = Some(FrameWork {
            pipeline_statistics: true,
            shader_counts: false,
            passes: vec![ssm_core::PassWork {
                name: "hard_lookup".into(),
                runs: 1,
                vertex_invocations: 3,
                fragment_invocations: 3456,
                target_bytes: 12288,
                ..ssm_core::PassWork::default()
            }],
            uncounted_passes: 0,
            diagnostics: Vec::new(),
        });
        rows[2].work = Some(FrameWork { shader_counts: true, pipeline_statistics: false, ..rows[0].work.clone().unwrap() });
        let text = csv(&rows);
        let back = parse_csv(&text).unwrap();
        assert_eq!(csv(&back), text);
        assert_eq!(back[0].work, rows[0].work);
        assert_eq!((back[1].work.as_ref(), back[2].work.as_ref()), (None, rows[2].work.as_ref()));
        let first = CSV_COLUMNS.iter().position(|c| *c == "vertex_invocations").unwrap();
        let work_columns = |line: &str| -> Vec<String> { split_csv_line(line).unwrap()[first..first + 5].to_vec() };
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            work_columns(lines[1]),
            ["3", "3456", "0", "", "hard_lookup:runs=1,vertex_invocations=3,fragment_invocations=3456,target_bytes=12288"]
        );
        assert_eq!(work_columns(lines[2]), ["", "", "", "", ""], "not counted: every work column empty");
        assert_eq!(&work_columns(lines[3])[..4], ["", "", "", "0"], "no statistics: invocations unknown; shaders counted no read");
        assert_eq!((back[1].light, back[0].metrics.penumbra_pixels, back[0].adapter.as_str()), (Some(1), 17, "llvmpipe \"x\", y"));
        assert!(parse_csv("scene,technique\n").is_err(), "another header");
        assert!(parse_csv(&text.replace("96,72", "96")).is_err(), "a field missing");
    }

    #[test]
    fn the_leading_columns_are_the_documented_ones() {
        assert_eq!(
            CSV_COLUMNS[..15].join(","),
            "scene,technique,params,width,height,gpu_ms_median,gpu_ms_min,cpu_ms,mae_penumbra,rmse,max_abs,psnr,ssim,frac_over_0_05,adapter"
        );
    }
}
