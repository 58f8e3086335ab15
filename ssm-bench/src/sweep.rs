//! `ssm sweep`: a grid over techniques' quality knobs, each point measured
//! like a row of `ssm compare`, and the plot of time against error with the
//! Pareto front marked: the speed/accuracy trade.

use anyhow::{Context, Result, bail};
use plotters::prelude::*;

use crate::report::Row;

/// One axis of a sweep: parameters of one technique that vary together.
/// `pcss.pcf_kernel=7,15,21` varies one; `pcss.blocker_kernel:pcf_kernel=7:15,11:21`
/// varies two in step (the kernel pairs of Buades et al., Table 4).
#[derive(Clone, Debug, PartialEq)]
pub struct Vary {
    /// The technique.
    pub technique: String,
    /// Parameter names varied in step.
    pub params: Vec<String>,
    /// The values, one tuple per step.
    pub values: Vec<Vec<String>>,
}

impl Vary {
    /// Parses `technique.p1[:p2...]=a1[:a2...],b1[:b2...],...`.
    ///
    /// # Errors
    /// A malformed specification, with what was expected.
    pub fn parse(text: &str) -> Result<Self> {
        let expected = || format!("--vary `{text}`: expected <technique>.<param>[:<param>...]=<value>[:<value>...],...");
        let (key, values) = text.split_once('=').with_context(expected)?;
        let (technique, params) = key.split_once('.').with_context(expected)?;
        let params: Vec<String> = params.split(':').map(|p| p.trim().to_owned()).collect();
        let values: Vec<Vec<String>> = values.split(',').map(|v| v.split(':').map(|x| x.trim().to_owned()).collect()).collect();
        if params.iter().any(String::is_empty) || values.is_empty() {
            bail!(expected());
        }
        if let Some(bad) = values.iter().find(|v| v.len() != params.len() || v.iter().any(String::is_empty)) {
            bail!("--vary `{text}`: `{}` has {} values for {} parameters", bad.join(":"), bad.len(), params.len());
        }
        Ok(Self { technique: technique.trim().to_owned(), params, values })
    }
}

/// A named sweep: the techniques and their varies (the studies of the papers).
#[derive(Clone, Copy, Debug)]
pub struct Preset {
    /// Name for `--preset`.
    pub name: &'static str,
    /// What it reproduces.
    pub summary: &'static str,
    /// `--vary` specifications.
    pub varies: &'static [&'static str],
}

/// The built-in presets.
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "trade",
        summary: "the baselines' trade curves: PCSS kernel pairs, multi-sm sample counts, hard shadow-map sizes",
        varies: &[
            "pcss.blocker_kernel:pcf_kernel=3:5,7:15,11:21,29:41",
            "multi-sm.samples=1,4,16,64",
            "hard.shadow_map_size=512,1024,2048,4096",
        ],
    },
    Preset {
        name: "pcss-kernels",
        summary: "PCSS with the kernel pairs of Buades et al., Table 4 (7/15, 11/21, 29/41)",
        varies: &["pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41"],
    },
    Preset {
        name: "multi-sm-samples",
        summary: "multi-sm with K = 1, 4, 16, 64, 256 shadow maps",
        varies: &["multi-sm.samples=1,4,16,64,256"],
    },
    Preset {
        name: "shadow-map-size",
        summary: "hard and PCSS against shadow-map resolution",
        varies: &["hard.shadow_map_size=256,512,1024,2048,4096", "pcss.shadow_map_size=256,512,1024,2048,4096"],
    },
];

/// The preset called `name`.
///
/// # Errors
/// An unknown name, listing the known ones.
pub fn preset(name: &str) -> Result<&'static Preset> {
    PRESETS
        .iter()
        .find(|p| p.name == name)
        .with_context(|| format!("unknown preset `{name}`; presets: {}", PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")))
}

/// Every point of the grid of one technique: the cartesian product of its varies, as `(param, value)` lists.
#[must_use]
pub fn grid(varies: &[&Vary]) -> Vec<Vec<(String, String)>> {
    let mut points: Vec<Vec<(String, String)>> = vec![Vec::new()];
    for vary in varies {
        points = points
            .into_iter()
            .flat_map(|point| {
                vary.values.iter().map(move |values| {
                    let mut next = point.clone();
                    next.extend(vary.params.iter().cloned().zip(values.iter().cloned()));
                    next
                })
            })
            .collect();
    }
    points
}

/// Which measure is plotted against time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ErrorAxis {
    /// Mean absolute error over the reference's umbra and penumbra.
    MaePenumbra,
    /// Root-mean-square error.
    Rmse,
    /// 1 − SSIM.
    OneMinusSsim,
    /// Mean FLIP of the shaded images.
    Flip,
}

impl ErrorAxis {
    /// The value of this measure in `row`.
    #[must_use]
    pub fn of(self, row: &Row) -> f64 {
        match self {
            Self::MaePenumbra => row.metrics.mae_penumbra,
            Self::Rmse => row.metrics.rmse,
            Self::OneMinusSsim => 1.0 - row.metrics.ssim,
            Self::Flip => row.flip,
        }
    }

    /// Axis label.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::MaePenumbra => "mean absolute error over umbra and penumbra",
            Self::Rmse => "RMSE",
            Self::OneMinusSsim => "1 - SSIM",
            Self::Flip => "mean FLIP (shaded)",
        }
    }
}

/// The time a row is plotted at: GPU median, else CPU wall median.
#[must_use]
pub fn time_of(row: &Row) -> f64 {
    row.gpu_ms_median.unwrap_or(row.cpu_ms)
}

/// Indices of the rows on the Pareto front of (time, error): no other row is
/// at least as fast and at least as accurate, and better in one. Sorted by time.
#[must_use]
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let dominated = |i: usize| {
        let (t, e) = points[i];
        points.iter().enumerate().any(|(j, &(u, f))| j != i && u <= t && f <= e && (u < t || f < e))
    };
    let mut front: Vec<usize> =
        (0..points.len()).filter(|&i| points[i].0.is_finite() && points[i].1.is_finite() && !dominated(i)).collect();
    front.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0));
    front
}

/// The short label of a point: its varied values.
#[must_use]
pub fn point_label(varied: &[(String, String)]) -> String {
    varied.iter().map(|(_, v)| v.as_str()).collect::<Vec<_>>().join("/")
}

/// Draws time (log) against error (log), one series per technique, the Pareto
/// front as a dashed line, into `png` and `svg`.
///
/// # Errors
/// Drawing or file errors.
pub fn plot(rows: &[Row], labels: &[String], axis: ErrorAxis, title: &str, png: &std::path::Path, svg: &std::path::Path) -> Result<()> {
    // The font for PNG text; SVG text is drawn by whatever opens the file.
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
    draw(&BitMapBackend::new(png, (1000, 700)).into_drawing_area(), rows, labels, axis, title)
        .with_context(|| format!("drawing {}", png.display()))?;
    draw(&SVGBackend::new(svg, (1000, 700)).into_drawing_area(), rows, labels, axis, title)
        .with_context(|| format!("drawing {}", svg.display()))?;
    Ok(())
}

fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    rows: &[Row],
    labels: &[String],
    axis: ErrorAxis,
    title: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let points: Vec<(f64, f64)> = rows.iter().map(|r| (time_of(r), axis.of(r).max(1e-6))).collect();
    let finite: Vec<&(f64, f64)> = points.iter().filter(|(t, e)| t.is_finite() && e.is_finite() && *t > 0.0).collect();
    if finite.is_empty() {
        bail!("no finite (time, error) point to plot");
    }
    let (t_min, t_max) = finite.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), (t, _)| (lo.min(*t), hi.max(*t)));
    let (e_min, e_max) = finite.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), (_, e)| (lo.min(*e), hi.max(*e)));
    area.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 24))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d((t_min / 1.5..t_max * 1.5).log_scale(), (e_min / 1.5..e_max * 1.5).log_scale())
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc(format!("{} per frame, ms (log)", if rows.iter().all(|r| r.gpu_ms_median.is_some()) { "GPU time" } else { "time" }))
        .y_desc(format!("{} (log)", axis.label()))
        .label_style(("sans-serif", 15))
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.3}"))
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut techniques: Vec<&str> = Vec::new();
    for row in rows {
        if !techniques.contains(&row.technique.as_str()) {
            techniques.push(&row.technique);
        }
    }
    for (index, technique) in techniques.iter().enumerate() {
        let colour = Palette99::pick(index).mix(0.9);
        let series: Vec<(usize, (f64, f64))> =
            rows.iter().enumerate().filter(|(_, r)| r.technique == *technique).map(|(i, _)| (i, points[i])).collect();
        chart
            .draw_series(LineSeries::new(series.iter().map(|(_, p)| *p), colour.stroke_width(2)))
            .map_err(|e| anyhow::anyhow!("{e}"))?
            .label(technique.to_string())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(3)));
        chart.draw_series(series.iter().map(|(_, p)| Circle::new(*p, 5, colour.filled()))).map_err(|e| anyhow::anyhow!("{e}"))?;
        chart
            .draw_series(
                series.iter().map(|(i, p)| {
                    EmptyElement::at(*p) + Text::new(labels[*i].clone(), (8, -16), ("sans-serif", 13).into_font().color(&BLACK))
                }),
            )
            .map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let front = pareto_front(&points);
    chart
        .draw_series(DashedLineSeries::new(front.iter().map(|&i| points[i]), 6, 4, BLACK.stroke_width(1)))
        .map_err(|e| anyhow::anyhow!("{e}"))?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
    chart.draw_series(front.iter().map(|&i| Circle::new(points[i], 9, BLACK.stroke_width(2)))).map_err(|e| anyhow::anyhow!("{e}"))?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    area.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vary_specifications_parse_and_expand() {
        let single = Vary::parse("pcss.pcf_kernel=7,15,21").unwrap();
        assert_eq!(single.params, vec!["pcf_kernel"]);
        assert_eq!(single.values.len(), 3);
        let paired = Vary::parse("pcss.blocker_kernel:pcf_kernel=7:15,11:21").unwrap();
        let size = Vary::parse("pcss.shadow_map_size=512,1024").unwrap();
        let points = grid(&[&paired, &size]);
        assert_eq!(points.len(), 4);
        assert_eq!(
            points[1],
            vec![("blocker_kernel".into(), "7".into()), ("pcf_kernel".into(), "15".into()), ("shadow_map_size".into(), "1024".into())]
        );
        assert_eq!(point_label(&points[1]), "7/15/1024");
        assert!(Vary::parse("pcss.a:b=1:2,3").is_err());
        assert!(Vary::parse("pcss=1").is_err());
        assert!(Vary::parse("pcss.a=").is_err());
        for p in PRESETS {
            for v in p.varies {
                Vary::parse(v).unwrap();
            }
        }
        assert!(preset("nope").unwrap_err().to_string().contains("trade"));
    }

    #[test]
    fn pareto_front_keeps_the_undominated_points_in_time_order() {
        let points = [(1.0, 0.5), (2.0, 0.2), (3.0, 0.3), (4.0, 0.1), (2.0, 0.6), (f64::NAN, 0.0)];
        assert_eq!(pareto_front(&points), vec![0, 1, 3]);
        // Ties are not domination.
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0, 1]);
    }
}
