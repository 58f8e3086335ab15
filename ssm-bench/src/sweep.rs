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
    /// The plot's x axis unless `--x` says otherwise: `time` or a varied parameter.
    pub x_axis: &'static str,
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
        x_axis: "time",
    },
    Preset {
        name: "pcss-kernels",
        summary: "PCSS with the kernel pairs of Buades et al., Table 4 (7/15, 11/21, 29/41)",
        varies: &["pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41"],
        x_axis: "time",
    },
    Preset {
        name: "multi-sm-samples",
        summary: "multi-sm with K = 1, 4, 16, 64, 256 shadow maps",
        varies: &["multi-sm.samples=1,4,16,64,256"],
        x_axis: "time",
    },
    Preset {
        name: "shadow-map-size",
        summary: "hard and PCSS against shadow-map resolution",
        varies: &["hard.shadow_map_size=256,512,1024,2048,4096", "pcss.shadow_map_size=256,512,1024,2048,4096"],
        x_axis: "time",
    },
    Preset {
        name: "sssm-table4",
        summary: "Buades et al., Table 4: PCSS and SSSM at kernel pairs 7/15, 11/21, 29/41, SSSM with alpha = beta from little to much reuse (use on leaves, the plant scene's nearest)",
        varies: &[
            "pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41",
            "sssm.blocker_kernel:blur_kernel=7:15,11:21,29:41",
            "sssm.alpha:beta=0.001:0.001,0.01:0.01,0.02:0.02,0.05:0.05,0.2:0.2",
        ],
        x_axis: "time",
    },
    Preset {
        name: "atty-map-size",
        summary: "Atty et al., Fig. 17 (error) and Fig. 22 (time, with --error time) against the occluder map's size, one- and two-sided",
        varies: &["atty.occluder_map_size=33,63,127,200,255,383,511", "atty.two_sided=false,true"],
        x_axis: "atty.occluder_map_size",
    },
    Preset {
        name: "atty-light-size",
        summary: "Atty et al., Fig. 18 and Fig. 24 (error, or time with --error time) against the light's size for 63², 127², 255² maps (not powers of two, as the paper notes in Sec. 5.2.3; use a thick occluder such as floating-sphere)",
        varies: &["scene.light_scale=0.02,0.25,0.5,1,1.5,2", "atty.occluder_map_size=63,127,255"],
        x_axis: "scene.light_scale",
    },
    Preset {
        name: "atty-occluder-height",
        summary: "Atty et al., Fig. 20: error as the occluders move from the receiver towards the light (on floating-sphere: from 0.05 above the ground to 0.05 below the light)",
        varies: &["scene.occluder_lift=-0.75,-0.5,0,0.5,1,1.5,1.9,1.95", "atty.two_sided=false,true"],
        x_axis: "scene.occluder_lift",
    },
];

/// The pseudo-technique whose varies change the scene instead of a technique.
pub const SCENE_AXIS: &str = "scene";

/// Changes to the scene a sweep can vary, by name after `scene.`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneOverrides {
    /// Every light's size is multiplied by this (`scene.light_scale`).
    pub light_scale: f32,
    /// Occluder-only instances move this far towards the first light, along its normal, world units (`scene.occluder_lift`).
    pub occluder_lift: f32,
}

impl Default for SceneOverrides {
    fn default() -> Self {
        Self { light_scale: 1.0, occluder_lift: 0.0 }
    }
}

impl SceneOverrides {
    /// The overrides of one grid point.
    ///
    /// # Errors
    /// An unknown scene parameter or a non-numeric value.
    pub fn from_point(point: &[(String, String)]) -> Result<Self> {
        let mut overrides = Self::default();
        for (name, value) in point {
            let number: f32 =
                value.parse().ok().filter(|v: &f32| v.is_finite()).with_context(|| format!("scene.{name}={value}: not a finite number"))?;
            match name.as_str() {
                "light_scale" if number >= 0.0 => overrides.light_scale = number,
                "light_scale" => bail!("scene.light_scale={value}: must be non-negative"),
                "occluder_lift" => overrides.occluder_lift = number,
                other => bail!("unknown scene parameter `scene.{other}`; scene parameters: light_scale, occluder_lift"),
            }
        }
        Ok(overrides)
    }

    /// The scene with the overrides applied (and validated).
    ///
    /// # Errors
    /// The modified scene is invalid (an occluder lifted to a non-finite place, say).
    pub fn apply(&self, scene: &ssm_scene::Scene) -> Result<ssm_scene::Scene> {
        let mut scene = scene.clone();
        for light in &mut scene.lights {
            light.half_size *= self.light_scale;
        }
        if let Some(first) = scene.lights.first() {
            let lift = glam::Mat4::from_translation(-first.normal() * self.occluder_lift);
            for instance in scene.instances.iter_mut().filter(|i| i.role == ssm_scene::Role::Occluder) {
                instance.transform = lift * instance.transform;
            }
        }
        scene.validate()?;
        Ok(scene)
    }
}

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
    /// GPU time per frame (or CPU wall time without timestamps), for the paper's timing figures.
    Time,
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
            Self::Time => time_of(row),
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
            Self::Time => "time per frame, ms",
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

/// One point of a plot.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotPoint {
    /// The series it belongs to (its technique and the varied values not on the x axis).
    pub series: String,
    /// Position.
    pub x: f64,
    /// Position.
    pub y: f64,
    /// A short label drawn beside it.
    pub label: String,
}

/// What the plot's axes show.
#[derive(Clone, Debug)]
pub struct PlotAxes {
    /// x axis caption.
    pub x_label: String,
    /// y axis caption.
    pub y_label: String,
    /// Logarithmic x.
    pub log_x: bool,
    /// Mark the Pareto front of (x, y), both to be minimised (time against error).
    pub pareto: bool,
}

/// Draws the points, one line per series, y logarithmic, the Pareto front as a
/// dashed line when asked, into `png` and `svg`.
///
/// # Errors
/// Drawing or file errors, or no finite point.
pub fn plot(points: &[PlotPoint], axes: &PlotAxes, title: &str, png: &std::path::Path, svg: &std::path::Path) -> Result<()> {
    // The font for PNG text; SVG text is drawn by whatever opens the file.
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
    draw(&BitMapBackend::new(png, (1000, 700)).into_drawing_area(), points, axes, title)
        .with_context(|| format!("drawing {}", png.display()))?;
    draw(&SVGBackend::new(svg, (1000, 700)).into_drawing_area(), points, axes, title)
        .with_context(|| format!("drawing {}", svg.display()))?;
    Ok(())
}

fn chart_error(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    points: &[PlotPoint],
    axes: &PlotAxes,
    title: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let usable: Vec<&PlotPoint> =
        points.iter().filter(|p| p.x.is_finite() && p.y.is_finite() && p.y > 0.0 && (!axes.log_x || p.x > 0.0)).collect();
    if usable.is_empty() {
        bail!("no finite point to plot");
    }
    let (x_min, x_max) = usable.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.x), hi.max(p.x)));
    let (y_min, y_max) = usable.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
    area.fill(&WHITE).map_err(chart_error)?;
    let mut builder = ChartBuilder::on(area);
    builder.caption(title, ("sans-serif", 24)).margin(20).x_label_area_size(50).y_label_area_size(70);
    let y_range = (y_min / 1.5..y_max * 1.5).log_scale();
    if axes.log_x {
        let chart = builder.build_cartesian_2d((x_min / 1.5..x_max * 1.5).log_scale(), y_range).map_err(chart_error)?;
        draw_series(chart, &usable, axes)
    } else {
        let pad = ((x_max - x_min) * 0.08).max(1e-6);
        let chart = builder.build_cartesian_2d(x_min - pad..x_max + pad, y_range).map_err(chart_error)?;
        draw_series(chart, &usable, axes)
    }
}

fn draw_series<'a, DB, X>(
    mut chart: ChartContext<'a, DB, Cartesian2d<X, plotters::coord::combinators::LogCoord<f64>>>,
    points: &[&PlotPoint],
    axes: &PlotAxes,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(axes.x_label.as_str())
        .y_desc(axes.y_label.as_str())
        .label_style(("sans-serif", 15))
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.3}"))
        .draw()
        .map_err(chart_error)?;
    let mut series_names: Vec<&str> = Vec::new();
    for p in points {
        if !series_names.contains(&p.series.as_str()) {
            series_names.push(&p.series);
        }
    }
    for (index, name) in series_names.iter().enumerate() {
        let colour = Palette99::pick(index).mix(0.9);
        let mut series: Vec<&PlotPoint> = points.iter().copied().filter(|p| p.series == *name).collect();
        if !axes.pareto {
            series.sort_by(|a, b| a.x.total_cmp(&b.x));
        }
        chart
            .draw_series(LineSeries::new(series.iter().map(|p| (p.x, p.y)), colour.stroke_width(2)))
            .map_err(chart_error)?
            .label(name.to_string())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(3)));
        chart.draw_series(series.iter().map(|p| Circle::new((p.x, p.y), 5, colour.filled()))).map_err(chart_error)?;
        chart
            .draw_series(
                series.iter().map(|p| {
                    EmptyElement::at((p.x, p.y)) + Text::new(p.label.clone(), (8, -16), ("sans-serif", 13).into_font().color(&BLACK))
                }),
            )
            .map_err(chart_error)?;
    }
    if axes.pareto {
        let coordinates: Vec<(f64, f64)> = points.iter().map(|p| (p.x, p.y)).collect();
        let front = pareto_front(&coordinates);
        chart
            .draw_series(DashedLineSeries::new(front.iter().map(|&i| coordinates[i]), 6, 4, BLACK.stroke_width(1)))
            .map_err(chart_error)?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
        chart.draw_series(front.iter().map(|&i| Circle::new(coordinates[i], 9, BLACK.stroke_width(2)))).map_err(chart_error)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 15))
        .draw()
        .map_err(chart_error)?;
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
            let varies: Vec<Vary> = p.varies.iter().map(|v| Vary::parse(v).unwrap()).collect();
            let on_an_axis =
                p.x_axis == "time" || varies.iter().any(|v| v.params.iter().any(|n| format!("{}.{n}", v.technique) == p.x_axis));
            assert!(on_an_axis, "preset {}: x axis {} is not varied", p.name, p.x_axis);
        }
        assert!(preset("nope").unwrap_err().to_string().contains("trade"));
    }

    #[test]
    fn scene_overrides_scale_lights_and_lift_occluders() {
        let scene = ssm_scene::builtin("parallel-square").unwrap().build();
        let point = vec![("light_scale".to_owned(), "0.5".to_owned()), ("occluder_lift".to_owned(), "1".to_owned())];
        let changed = SceneOverrides::from_point(&point).unwrap().apply(&scene).unwrap();
        assert_eq!(changed.lights[0].half_size, scene.lights[0].half_size * 0.5);
        let occluder = changed.bounds_where(|r| r == ssm_scene::Role::Occluder);
        assert!((occluder.min.y - 3.0).abs() < 1e-5, "lifted towards the light: {}", occluder.min.y);
        assert_eq!(changed.bounds_where(|r| r == ssm_scene::Role::Receiver), scene.bounds_where(|r| r == ssm_scene::Role::Receiver));
        assert!(SceneOverrides::from_point(&[("size".into(), "1".into())]).is_err());
        assert!(SceneOverrides::from_point(&[("light_scale".into(), "-1".into())]).is_err());
    }

    #[test]
    fn pareto_front_keeps_the_undominated_points_in_time_order() {
        let points = [(1.0, 0.5), (2.0, 0.2), (3.0, 0.3), (4.0, 0.1), (2.0, 0.6), (f64::NAN, 0.0)];
        assert_eq!(pareto_front(&points), vec![0, 1, 3]);
        // Ties are not domination.
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0, 1]);
    }
}
