//! `ssm sweep`: a grid over techniques' quality knobs, each point measured
//! like a row of `ssm compare`, and the plot of time against error with the
//! Pareto front marked: the speed/accuracy trade.

use anyhow::{Context, Result, bail};
use plotters::prelude::*;

use ssm_core::{ParamValues, Registry, TechniqueInfo, TechniqueKind};

use crate::report::{PixelSet, Row};

/// One axis of a sweep: parameters of one technique that vary together.
/// `mine.kernel=7,15,21` varies one; `mine.search:kernel=7:15,11:21`
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
    /// Parses `technique.p1[:p2...]=a1[:a2...],b1[:b2...],...`, or a bare `technique`: one
    /// point at its defaults (a technique compared as it is while the scene varies).
    ///
    /// # Errors
    /// A malformed specification, with what was expected.
    pub fn parse(text: &str) -> Result<Self> {
        let bare = text.trim();
        if !bare.is_empty() && !bare.contains(['.', '=', ':', ',']) {
            return Ok(Self { technique: bare.to_owned(), params: Vec::new(), values: vec![Vec::new()] });
        }
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

/// A sweep preset as the tool runs it: one a technique declares
/// ([`ssm_core::Preset`], next to its parameters), or `trade`, assembled from
/// every technique's quality knob ([`ssm_core::TechniqueInfo::trade`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PresetSpec {
    /// Name for `--preset`.
    pub name: String,
    /// What it reproduces.
    pub summary: String,
    /// The technique that declares it (`None` for `trade`).
    pub owner: Option<&'static str>,
    /// Scenes it is meant for; the first is used without `--scene`.
    pub scenes: Vec<String>,
    /// `--vary` specifications.
    pub varies: Vec<String>,
    /// The plot's x axis unless `--x` says otherwise: `time` or a varied parameter.
    pub x_axis: String,
    /// The plot's y axis unless `--error` says otherwise.
    pub y_axis: ErrorAxis,
    /// The pixels the errors cover unless `--pixels` says otherwise.
    pub pixels: PixelSet,
    /// The image size (width, height) unless `--width`/`--height` say otherwise: the paper's,
    /// where it states one.
    pub size: Option<(u32, u32)>,
}

impl PresetSpec {
    /// A technique's preset, its axes checked.
    ///
    /// # Errors
    /// A y axis or pixel set the tool does not know.
    pub fn from_technique(owner: &'static str, preset: &ssm_core::Preset) -> Result<Self> {
        let y_axis = <ErrorAxis as clap::ValueEnum>::from_str(preset.y_axis, false)
            .map_err(|e| anyhow::anyhow!("preset `{}` of `{owner}`: y axis `{}`: {e}", preset.name, preset.y_axis))?;
        let pixels = <PixelSet as clap::ValueEnum>::from_str(preset.pixels, false)
            .map_err(|e| anyhow::anyhow!("preset `{}` of `{owner}`: pixels `{}`: {e}", preset.name, preset.pixels))?;
        Ok(Self {
            name: preset.name.to_owned(),
            summary: preset.summary.to_owned(),
            owner: Some(owner),
            scenes: preset.scenes.iter().map(|s| (*s).to_owned()).collect(),
            varies: preset.varies.iter().map(|v| (*v).to_owned()).collect(),
            x_axis: preset.x_axis.to_owned(),
            y_axis,
            pixels,
            size: preset.size,
        })
    }
}

/// The scene the `trade` preset runs on without `--scene`.
pub const TRADE_SCENE: &str = "sphere-cube";

/// `trade`: every real-time technique's quality knob on one scene, time
/// against error: the cross-technique speed/accuracy plot.
#[must_use]
pub fn trade_preset(registry: &Registry) -> PresetSpec {
    let knobs: Vec<(&str, &str)> =
        registry.iter().filter(|i| i.kind == TechniqueKind::Realtime).filter_map(|i| i.trade.map(|knob| (i.name, knob))).collect();
    PresetSpec {
        name: "trade".into(),
        summary: format!(
            "every technique's quality knob, time against error: {}",
            knobs.iter().map(|(name, knob)| format!("{name} {}", knob.split('=').next().unwrap_or(knob))).collect::<Vec<_>>().join(", ")
        ),
        owner: None,
        scenes: vec![TRADE_SCENE.into()],
        varies: knobs.iter().map(|(name, knob)| format!("{name}.{knob}")).collect(),
        x_axis: "time".into(),
        y_axis: ErrorAxis::MaePenumbra,
        pixels: PixelSet::All,
        size: None,
    }
}

/// The scene the `lights` preset runs on without `--scene`.
pub const LIGHTS_SCENE: &str = "sphere-cube";

/// `lights`: every real-time technique at its defaults with 1, 2 and 3 lights (Buades et al.,
/// Fig. 11): the frame's time should grow linearly, since only per-light work repeats.
#[must_use]
pub fn lights_preset(registry: &Registry) -> PresetSpec {
    let mut varies = vec!["scene.lights=1,2,3".to_owned()];
    varies.extend(registry.iter().filter(|i| i.kind == TechniqueKind::Realtime).map(|i| i.name.to_owned()));
    PresetSpec {
        name: "lights".into(),
        summary: "every technique at its defaults with 1, 2 and 3 copies of the scene's light (the timing of Buades et al., Fig. 11): time per frame against the light count, linear when only per-light work repeats".into(),
        owner: None,
        scenes: vec![LIGHTS_SCENE.into()],
        varies,
        x_axis: "scene.lights".into(),
        y_axis: ErrorAxis::Time,
        pixels: PixelSet::All,
        size: None,
    }
}

/// Every preset: `trade`, `lights`, then each technique's, by technique name.
///
/// # Errors
/// A technique's preset with axes the tool does not know, or two presets of one name.
pub fn presets(registry: &Registry) -> Result<Vec<PresetSpec>> {
    let mut all = vec![trade_preset(registry), lights_preset(registry)];
    for info in registry.iter() {
        for preset in info.presets {
            let spec = PresetSpec::from_technique(info.name, preset)?;
            if let Some(other) = all.iter().find(|p| p.name == spec.name) {
                bail!("two presets are named `{}`: {} and {}", spec.name, other.owner.unwrap_or("ssm"), info.name);
            }
            all.push(spec);
        }
    }
    Ok(all)
}

/// The image size a sweep renders at without `--width`/`--height`.
pub const DEFAULT_SIZE: (u32, u32) = (640, 480);

/// The image size of a sweep: each of `width` and `height` the command line's, else the preset's
/// (the paper's viewport, where it states one), else [`DEFAULT_SIZE`]'s.
#[must_use]
pub fn image_size(width: Option<u32>, height: Option<u32>, preset: Option<&PresetSpec>) -> (u32, u32) {
    let preset = preset.and_then(|p| p.size);
    (width.or(preset.map(|(w, _)| w)).unwrap_or(DEFAULT_SIZE.0), height.or(preset.map(|(_, h)| h)).unwrap_or(DEFAULT_SIZE.1))
}

/// The preset called `name`.
///
/// # Errors
/// An unknown name, listing the known ones.
pub fn preset(registry: &Registry, name: &str) -> Result<PresetSpec> {
    let all = presets(registry)?;
    let known = all.iter().map(|p| p.name.clone()).collect::<Vec<_>>().join(", ");
    all.into_iter().find(|p| p.name == name).with_context(|| format!("unknown preset `{name}`; presets: {known}"))
}

/// One technique point of a sweep: the technique, its parameters, and its
/// varied values (`<technique>.<param>`, value).
pub type SweepPoint = (&'static TechniqueInfo, ParamValues, Vec<(String, String)>);

/// A sweep resolved against the registry before the GPU is touched: every
/// technique point with its parameters, and every scene point.
#[derive(Debug)]
pub struct SweepPlan {
    /// The points of every varied technique.
    pub points: Vec<SweepPoint>,
    /// The scene points (`scene.<param>`, value), one renderer and ground truth each.
    pub scene_points: Vec<Vec<(String, String)>>,
    /// The overrides of each scene point.
    pub scene_overrides: Vec<SceneOverrides>,
    /// The varied parameters, qualified (`mine.kernel`, `scene.light_scale`).
    pub varied: Vec<String>,
}

impl SweepPlan {
    /// Resolves `varies` (specifications) with the fixed `settings` (technique, param, value).
    ///
    /// # Errors
    /// A malformed specification, an unknown technique or parameter, a bad value, or no technique varied.
    pub fn new(registry: &Registry, varies: &[String], settings: &[(&str, &str, &str)]) -> Result<Self> {
        let varies: Vec<Vary> = varies.iter().map(|s| Vary::parse(s)).collect::<Result<_>>()?;
        // A parameter on two axes would be set twice per point, the later value silently winning.
        let mut seen = std::collections::HashSet::new();
        for vary in &varies {
            for param in &vary.params {
                if !seen.insert(format!("{}.{param}", vary.technique)) {
                    bail!("{}.{param} is varied twice (by a --vary and the preset, say); give it one axis", vary.technique);
                }
            }
        }
        let scene_axes: Vec<&Vary> = varies.iter().filter(|v| v.technique == SCENE_AXIS).collect();
        let mut techniques: Vec<&'static TechniqueInfo> = Vec::new();
        for vary in varies.iter().filter(|v| v.technique != SCENE_AXIS) {
            let info = registry.get(&vary.technique)?;
            if !techniques.iter().any(|t| t.name == info.name) {
                techniques.push(info);
            }
        }
        if techniques.is_empty() {
            bail!("no technique is varied: add a --vary <technique>.<param>=... (scene parameters alone compare nothing)");
        }
        let scene_points = grid(&scene_axes);
        let scene_overrides = scene_points.iter().map(|p| SceneOverrides::from_point(p)).collect::<Result<_>>()?;
        let mut points = Vec::new();
        for info in &techniques {
            let axes: Vec<&Vary> = varies.iter().filter(|v| v.technique == info.name).collect();
            for point in grid(&axes) {
                let fixed = settings.iter().filter(|(t, _, _)| *t == info.name).map(|(_, p, v)| (*p, *v));
                let mut params = info.params_from(fixed)?;
                for (name, value) in &point {
                    params.set(name, value)?;
                }
                let qualified = point.into_iter().map(|(name, value)| (format!("{}.{name}", info.name), value)).collect();
                points.push((*info, params, qualified));
            }
        }
        let varied = varies.iter().flat_map(|v| v.params.iter().map(move |p| format!("{}.{p}", v.technique))).collect();
        Ok(Self { points, scene_points, scene_overrides, varied })
    }
}

/// The pseudo-technique whose varies change the scene instead of a technique.
pub const SCENE_AXIS: &str = "scene";

/// Changes to the scene a sweep can vary, by name after `scene.`: the sweep's own (below), and a
/// built-in scene's own parameters (`scene.segments`, `scene.triangles`: `ssm scenes` lists them).
#[derive(Clone, Debug, PartialEq)]
pub struct SceneOverrides {
    /// Every light's size is multiplied by this (`scene.light_scale`).
    pub light_scale: f32,
    /// Occluder-only instances move this far towards the first light, along its normal, world units (`scene.occluder_lift`).
    pub occluder_lift: f32,
    /// Occluder-only instances move sideways under the first light, along its first axis, by this
    /// fraction of its width after `light_scale` (`scene.occluder_shift`; Atty et al., Fig. 19).
    pub occluder_shift: f32,
    /// The number of lights (`scene.lights`): the scene's first ones, then copies of its first
    /// light when it has fewer. Copies cost what the first costs, so a frame's time against the
    /// light count shows what a technique repeats per light and what it shares.
    pub lights: Option<usize>,
    /// The built-in scene's own parameters, `(name, value)`, over those its specification gives.
    pub scene_params: Vec<(String, String)>,
}

impl Default for SceneOverrides {
    fn default() -> Self {
        Self { light_scale: 1.0, occluder_lift: 0.0, occluder_shift: 0.0, lights: None, scene_params: Vec::new() }
    }
}

/// Most lights `scene.lights` asks for.
pub const MAX_SWEPT_LIGHTS: usize = 8;

/// The scene parameters every sweep has, whatever the scene.
pub const SWEEP_SCENE_PARAMS: &str = "light_scale, occluder_lift, occluder_shift, lights";

impl SceneOverrides {
    /// The overrides of one grid point. A name that is not one of [`SWEEP_SCENE_PARAMS`] is taken
    /// as a parameter of the built-in scene, checked against it by [`SceneOverrides::check_scene`].
    ///
    /// # Errors
    /// A non-numeric value, or a value outside a sweep parameter's range.
    pub fn from_point(point: &[(String, String)]) -> Result<Self> {
        let mut overrides = Self::default();
        for (name, value) in point {
            let number: f32 =
                value.parse().ok().filter(|v: &f32| v.is_finite()).with_context(|| format!("scene.{name}={value}: not a finite number"))?;
            match name.as_str() {
                "light_scale" if number >= 0.0 => overrides.light_scale = number,
                "light_scale" => bail!("scene.light_scale={value}: must be non-negative"),
                "occluder_lift" => overrides.occluder_lift = number,
                "occluder_shift" => overrides.occluder_shift = number,
                "lights" if number.fract() == 0.0 && (1.0..=MAX_SWEPT_LIGHTS as f32).contains(&number) => {
                    overrides.lights = Some(number as usize);
                }
                "lights" => bail!("scene.lights={value}: must be a whole number from 1 to {MAX_SWEPT_LIGHTS}"),
                other => overrides.scene_params.push((other.to_owned(), value.clone())),
            }
        }
        Ok(overrides)
    }

    /// `spec` (a scene name or file, as `--scene` takes it) with this point's built-in
    /// parameters appended, `name:param=value,...`.
    #[must_use]
    pub fn scene_spec(&self, spec: &str) -> String {
        if self.scene_params.is_empty() {
            return spec.to_owned();
        }
        let assignments: Vec<String> = self.scene_params.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let separator = if spec.contains(':') { ',' } else { ':' };
        format!("{spec}{separator}{}", assignments.join(","))
    }

    /// Checks, without building it, that the scene of `spec` takes this point's built-in parameters.
    ///
    /// # Errors
    /// Built-in parameters on a scene that is no built-in one, or ones it does not have or
    /// accept (the message lists the sweep's scene parameters and the scene's).
    pub fn check_scene(&self, spec: &str) -> Result<()> {
        if self.scene_params.is_empty() {
            return Ok(());
        }
        let names = self.scene_params.iter().map(|(k, _)| format!("scene.{k}")).collect::<Vec<_>>().join(", ");
        let name = spec.split_once(':').map_or(spec, |(name, _)| name);
        let entry = ssm_scene::BUILTIN_SCENES.iter().find(|s| s.name == name).with_context(|| {
            format!("{names}: `{spec}` is not a built-in scene, so its only scene parameters are the sweep's: {SWEEP_SCENE_PARAMS}")
        })?;
        let full = self.scene_spec(spec);
        let assignments = full.split_once(':').map_or("", |(_, a)| a);
        entry.args(assignments).with_context(|| format!("{names}: the sweep's own scene parameters are {SWEEP_SCENE_PARAMS}"))?;
        Ok(())
    }

    /// The scene of `spec` built with this point's built-in parameters; `base` (the scene of
    /// `spec` as loaded) when the point has none.
    ///
    /// # Errors
    /// As [`SceneOverrides::check_scene`].
    pub fn base_scene(&self, spec: &str, base: &ssm_scene::Scene) -> Result<ssm_scene::Scene> {
        if self.scene_params.is_empty() {
            return Ok(base.clone());
        }
        self.check_scene(spec)?;
        let full = self.scene_spec(spec);
        let built = ssm_scene::parse_builtin(&full).with_context(|| format!("`{spec}` is not a built-in scene"))?;
        Ok(built.map(|(_, scene)| scene)?)
    }

    /// The scene with the overrides applied (and validated).
    ///
    /// # Errors
    /// The modified scene is invalid (an occluder lifted to a non-finite place, say).
    pub fn apply(&self, scene: &ssm_scene::Scene) -> Result<ssm_scene::Scene> {
        let mut scene = scene.clone();
        if let (Some(count), Some(first)) = (self.lights, scene.lights.first().copied()) {
            scene.lights.resize(count, first);
        }
        for light in &mut scene.lights {
            light.half_size *= self.light_scale;
        }
        if let Some(first) = scene.lights.first() {
            let shift = first.u_axis.normalize_or_zero() * (2.0 * first.half_size.x * self.occluder_shift);
            let lift = glam::Mat4::from_translation(shift - first.normal() * self.occluder_lift);
            for instance in scene.instances.iter_mut().filter(|i| i.role == ssm_scene::Role::Occluder) {
                instance.transform = lift * instance.transform;
            }
        }
        scene.validate()?;
        Ok(scene)
    }
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

/// One line of `sweep.md`.
#[derive(Clone, Debug, PartialEq)]
pub struct MarkdownRow {
    /// The scene, with its varied values (`sphere-cube[lights=2]`).
    pub scene: String,
    /// The technique.
    pub technique: String,
    /// Its own varied values as `param=value`, space-separated; empty at its defaults.
    pub point: String,
    /// Median time per frame, ms.
    pub ms: f64,
    /// Penumbra MAE against the ground truth.
    pub mae_penumbra: f64,
    /// PSNR against the ground truth, dB.
    pub psnr: f64,
}

/// `sweep.md`: the sweep's rows as one Markdown table whose first column names the sweep (a
/// preset's name), under a line naming the adapter, the image size and the frames timed. The
/// table's lines from the fifth on are rows only, so that tables of several sweeps on one machine
/// concatenate into one (`scripts/gpu-bench.sh`).
#[must_use]
pub fn markdown(sweep: &str, adapter: &str, size: (u32, u32), frames: u32, rows: &[MarkdownRow]) -> String {
    let mut text = format!("Adapter: {adapter}; {}×{} pixels; median of {frames} frames.\n\n", size.0, size.1);
    text.push_str("| sweep | scene | technique | point | ms | penumbra MAE | PSNR dB |\n|---|---|---|---|---:|---:|---:|\n");
    for row in rows {
        let point = if row.point.is_empty() { "defaults" } else { &row.point };
        text.push_str(&format!(
            "| {sweep} | {} | {} | {point} | {:.2} | {:.4} | {:.1} |\n",
            row.scene, row.technique, row.ms, row.mae_penumbra, row.psnr
        ));
    }
    text
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

/// `name=value;name=value` of a grid point (the parameter names without their technique), or
/// `defaults` for the empty point.
#[must_use]
pub fn assignment_label(point: &[(String, String)]) -> String {
    if point.is_empty() {
        return "defaults".to_owned();
    }
    point.iter().map(|(k, v)| format!("{}={v}", k.rsplit('.').next().unwrap_or(k))).collect::<Vec<_>>().join(";")
}

/// `label` as one file-name component: characters other than letters, digits, `.`, `-`, `_`
/// and `=` become `_`.
#[must_use]
pub fn path_component(label: &str) -> String {
    label.chars().map(|c| if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_' | '=') { c } else { '_' }).collect()
}

/// The other parameters of the `--vary` axis that holds `x_axis` (`scene.rings` for
/// `scene.segments` in `scene.segments:rings=...`), qualified; empty when it varies alone or is
/// not a parameter. Specifications that do not parse are skipped (they were checked before).
#[must_use]
pub fn in_step_with(specs: &[String], x_axis: &str) -> Vec<String> {
    specs
        .iter()
        .filter_map(|spec| Vary::parse(spec).ok())
        .find(|vary| vary.params.iter().any(|p| format!("{}.{p}", vary.technique) == x_axis))
        .map(|vary| vary.params.iter().map(|p| format!("{}.{p}", vary.technique)).filter(|p| p != x_axis).collect())
        .unwrap_or_default()
}

/// Whether positive values span more than a decade (so that a logarithmic axis reads better).
#[must_use]
pub fn spans_decades(values: &[f64]) -> bool {
    let positive: Vec<f64> = values.iter().copied().filter(|v| v.is_finite() && *v > 0.0).collect();
    let (low, high) = positive.iter().fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(*v), h.max(*v)));
    positive.len() == values.len() && !positive.is_empty() && high > 10.0 * low
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
    register_plot_font();
    draw(&BitMapBackend::new(png, (1000, 700)).into_drawing_area(), points, axes, title)
        .with_context(|| format!("drawing {}", png.display()))?;
    draw(&SVGBackend::new(svg, (1000, 700)).into_drawing_area(), points, axes, title)
        .with_context(|| format!("drawing {}", svg.display()))?;
    Ok(())
}

/// The font for PNG text; SVG text is drawn by whatever opens the file.
fn register_plot_font() {
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
}

/// Where each technique's frame time goes: one bar per technique (`(label, passes)`, each pass
/// `(name, ms)`), its passes stacked as shares of its frame so that a 10 ms technique and a 10 s
/// one read alike; the frame's milliseconds are in the bar's label, a pass's name in its
/// segment when the segment is wide enough. Written to `png` and `svg`.
///
/// # Errors
/// Drawing or file errors, or no bar with a positive time.
pub fn pass_chart(bars: &[(String, Vec<(String, f64)>)], title: &str, png: &std::path::Path, svg: &std::path::Path) -> Result<()> {
    let bars: Vec<&(String, Vec<(String, f64)>)> =
        bars.iter().filter(|(_, passes)| passes.iter().map(|(_, ms)| ms.max(0.0)).sum::<f64>() > 0.0).collect();
    if bars.is_empty() {
        bail!("no technique with a timed pass");
    }
    register_plot_font();
    let height = 120 + 76 * bars.len() as u32;
    draw_pass_chart(&BitMapBackend::new(png, (1000, height)).into_drawing_area(), &bars, title)
        .with_context(|| format!("drawing {}", png.display()))?;
    draw_pass_chart(&SVGBackend::new(svg, (1000, height)).into_drawing_area(), &bars, title)
        .with_context(|| format!("drawing {}", svg.display()))?;
    Ok(())
}

fn draw_pass_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    bars: &[&(String, Vec<(String, f64)>)],
    title: &str,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    area.fill(&WHITE).map_err(chart_error)?;
    let totals: Vec<f64> = bars.iter().map(|(_, passes)| passes.iter().map(|(_, ms)| ms.max(0.0)).sum()).collect();
    let names: Vec<String> = bars.iter().zip(&totals).map(|((label, _), total)| format!("{label} ({total:.1} ms)")).collect();
    let count = bars.len();
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(40)
        .y_label_area_size(230)
        // Shifted by 0.15 so that the labels plotters puts at k + 0.5 sit at the bars' centres, the
        // bars being in the upper part of their slots to leave room for the names under them.
        .build_cartesian_2d(0.0..100.0, -0.15..count as f64 - 0.15)
        .map_err(chart_error)?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .x_desc("share of the frame's GPU time, %")
        .label_style(("sans-serif", 15))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_labels(count * 2 + 1)
        .y_label_formatter(&|y| {
            // Labels at the bars' middles (k + 0.5), top bar first.
            let slot = y - y.floor();
            let index = count.checked_sub(1 + y.floor() as usize);
            match index {
                Some(index) if (slot - 0.5).abs() < 1e-6 => names[index].clone(),
                _ => String::new(),
            }
        })
        .draw()
        .map_err(chart_error)?;
    for (index, ((_, passes), total)) in bars.iter().zip(&totals).enumerate() {
        let top = (count - index) as f64 - 0.27;
        let bottom = (count - 1 - index) as f64 + 0.27;
        let mut start = 0.0;
        // Passes too narrow for their name are named under the bar, each after a swatch of its colour.
        let (mut key_cursor, mut key_line) = (0.0, 0.0);
        for (k, (pass, ms)) in passes.iter().enumerate() {
            let share = 100.0 * ms.max(0.0) / total;
            let colour = Palette99::pick(k).to_rgba();
            chart
                .draw_series(std::iter::once(Rectangle::new([(start, bottom), (start + share, top)], colour.filled())))
                .map_err(chart_error)?;
            // The pass's name inside its segment, when about 7 pixels a character fit (1% ≈ 7.2 pixels here).
            if share * 7.2 > 7.0 * pass.len() as f64 + 8.0 {
                let label = Text::new(pass.clone(), (start + 0.5, (top + bottom) / 2.0), ("sans-serif", 13).into_font().color(&BLACK));
                chart.draw_series(std::iter::once(label)).map_err(chart_error)?;
            } else {
                let key = format!("{pass} {share:.0}%");
                // About 6 pixels a character at 12 pixels, 7.2 pixels a percent; a second line when the first is full.
                let key_width = (6.0 * key.len() as f64 + 26.0) / 7.2;
                if key_cursor > 0.0 && key_cursor + key_width > 100.0 {
                    (key_cursor, key_line) = (0.0, key_line + 1.0);
                }
                let key_top = bottom - 0.04 - 0.19 * key_line;
                let key_bottom = key_top - 0.15;
                let swatch = Rectangle::new([(key_cursor, key_bottom), (key_cursor + 1.4, key_top)], colour.filled());
                chart.draw_series(std::iter::once(swatch)).map_err(chart_error)?;
                let text = Text::new(key.clone(), (key_cursor + 1.9, key_top + 0.02), ("sans-serif", 12).into_font().color(&BLACK));
                chart.draw_series(std::iter::once(text)).map_err(chart_error)?;
                key_cursor += key_width;
            }
            start += share;
        }
    }
    area.present().map_err(chart_error)?;
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
    let y_low = y_min / 1.5;
    let y_high_for = |x_fraction: &dyn Fn(f64) -> f64| legend_room(&usable, y_low, y_max, x_fraction, axes.pareto);
    if axes.log_x {
        let (x_low, x_high) = (x_min / 1.5, x_max * 1.5);
        let (y_high, legend) = y_high_for(&|x: f64| (x / x_low).ln() / (x_high / x_low).ln());
        // The ticks chosen here: plotters' own log ticks start at the first power of ten inside the
        // range, so an axis within one decade got that one label, or none.
        let y_range = (y_low..y_high).log_scale().with_key_points(log_key_points(y_low, y_high));
        let x_range = (x_low..x_high).log_scale().with_key_points(log_key_points(x_low, x_high));
        let chart = builder.build_cartesian_2d(x_range, y_range).map_err(chart_error)?;
        draw_series(chart, &usable, axes, legend, false)
    } else {
        let pad = ((x_max - x_min) * 0.08).max(1e-6);
        let (x_low, x_high) = (x_min - pad, x_max + pad);
        let (y_high, legend) = y_high_for(&|x: f64| (x - x_low) / (x_high - x_low));
        let y_range = (y_low..y_high).log_scale().with_key_points(log_key_points(y_low, y_high));
        let integers = usable.iter().all(|p| p.x.fract() == 0.0);
        let chart = builder.build_cartesian_2d(x_low..x_high, y_range).map_err(chart_error)?;
        draw_series(chart, &usable, axes, legend, integers)
    }
}

/// Ticks of a log axis from `low` to `high`: 1, 2 and 5 times each power of ten inside, and 3 as
/// well when the range spans less than two decades (few ticks otherwise).
fn log_key_points(low: f64, high: f64) -> Vec<f64> {
    if !(low > 0.0 && high > low && high.is_finite()) {
        return Vec::new();
    }
    let mantissas: &[f64] = if high / low < 100.0 { &[1.0, 2.0, 3.0, 5.0] } else { &[1.0, 2.0, 5.0] };
    let (first, last) = (low.log10().floor() as i32, high.log10().ceil() as i32);
    (first..=last).flat_map(|power| mantissas.iter().map(move |m| m * 10f64.powi(power))).filter(|v| *v >= low && *v <= high).collect()
}

/// A log axis's tick label: only at 1, 2, 3 and 5 times a power of ten, since plotters puts a tick at
/// every integer multiple and, over less than a decade, their labels overprint.
fn log_tick(value: f64) -> String {
    if !(value > 0.0 && value.is_finite()) {
        return String::new();
    }
    let mantissa = value / 10f64.powf(value.log10().floor());
    if [1.0, 2.0, 3.0, 5.0, 10.0].iter().any(|m| (mantissa - m).abs() < 1e-6 * m) { compact(value) } else { String::new() }
}

/// A number with at most three significant decimals and no trailing zeros.
fn compact(value: f64) -> String {
    let text = if value.abs() >= 100.0 { format!("{value:.0}") } else { format!("{value:.3}") };
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_owned() } else { text }
}

/// A label's rectangle in pixels: left, top, right, bottom.
type LabelBox = (i32, i32, i32, i32);

/// Where to draw the label of the point at pixel `at`, relative to it: above and to the right,
/// or else below, higher or lower, whichever first overlaps no label in `placed` (which it joins).
fn label_offset(at: (i32, i32), label: &str, placed: &mut Vec<LabelBox>) -> (i32, i32) {
    // 13-pixel sans-serif: about 7 pixels a character.
    let (width, height) = (7 * i32::try_from(label.chars().count()).unwrap_or(i32::MAX / 8), 13);
    let candidates = [(8, -16), (8, 6), (8, -30), (8, 20)];
    let rectangle = |(dx, dy): (i32, i32)| (at.0 + dx, at.1 + dy, at.0 + dx + width, at.1 + dy + height);
    let overlaps = |a: LabelBox, b: &LabelBox| a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
    let chosen = candidates.into_iter().find(|offset| !placed.iter().any(|b| overlaps(rectangle(*offset), b))).unwrap_or(candidates[0]);
    placed.push(rectangle(chosen));
    chosen
}

/// The top of a log y axis from `y_low` that leaves the legend room, and where the legend goes: the
/// emptiest corner when one holds no point (the axis tops at 1.5× the largest value); otherwise the
/// axis grows upwards until the legend's height at the top right holds no point. A legend must
/// hide no measurement.
fn legend_room(points: &[&PlotPoint], y_low: f64, y_max: f64, x_fraction: &dyn Fn(f64) -> f64, pareto: bool) -> (f64, SeriesLabelPosition) {
    let y_high = y_max * 1.5;
    let (corner, crowded) = emptiest_corner(points, x_fraction, |y: f64| (y / y_low).ln() / (y_high / y_low).ln());
    if crowded == 0 {
        return (y_high, corner);
    }
    // The legend's share of the plot's height: a 22-pixel line per series (and the Pareto
    // front's), in a plot area of about 560 pixels.
    let mut entries = points.iter().map(|p| p.series.as_str()).collect::<Vec<_>>();
    entries.sort_unstable();
    entries.dedup();
    let share = legend_share(entries.len() + usize::from(pareto));
    (y_low * (y_max / y_low).powf(1.0 / (1.0 - share - 0.03)), SeriesLabelPosition::UpperRight)
}

/// The fraction of the plot's height a legend of `entries` lines takes.
fn legend_share(entries: usize) -> f64 {
    ((22 * entries + 16) as f64 / 560.0).min(0.45)
}

/// A linear axis's tick label; on an axis of integers (a light count), none between them.
fn linear_tick(value: f64, integers: bool) -> String {
    if integers && value.fract().abs() > 1e-9 { String::new() } else { compact(value) }
}

/// The corner of the plot whose region (a third of the width, two fifths of the height) holds the
/// fewest points, for the legend, so that it hides no measurement, and how many it holds.
/// `x_fraction` and `y_fraction` place a value in [0, 1] along the axes as drawn.
fn emptiest_corner(
    points: &[&PlotPoint],
    x_fraction: impl Fn(f64) -> f64,
    y_fraction: impl Fn(f64) -> f64,
) -> (SeriesLabelPosition, usize) {
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerLeft, false, false),
        (SeriesLabelPosition::LowerRight, true, false),
    ];
    let crowding = |right: bool, upper: bool| {
        points
            .iter()
            .filter(|p| {
                let (x, y) = (x_fraction(p.x), y_fraction(p.y));
                (if right { x > 0.66 } else { x < 0.34 }) && (if upper { y > 0.6 } else { y < 0.4 })
            })
            .count()
    };
    corners
        .into_iter()
        .map(|(corner, right, upper)| (corner, crowding(right, upper)))
        .min_by_key(|(_, count)| *count)
        .unwrap_or((SeriesLabelPosition::UpperRight, 0))
}

fn draw_series<'a, DB, X>(
    mut chart: ChartContext<
        'a,
        DB,
        Cartesian2d<X, plotters::coord::combinators::WithKeyPoints<plotters::coord::combinators::LogCoord<f64>>>,
    >,
    points: &[&PlotPoint],
    axes: &PlotAxes,
    legend: SeriesLabelPosition,
    integer_x: bool,
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
        // An axis of integers (a light count) is labelled at integers only.
        .x_label_formatter(&|v| if axes.log_x { log_tick(*v) } else { linear_tick(*v, integer_x) })
        .y_label_formatter(&|v| log_tick(*v))
        .draw()
        .map_err(chart_error)?;
    let mut series_names: Vec<&str> = Vec::new();
    for p in points {
        if !series_names.contains(&p.series.as_str()) {
            series_names.push(&p.series);
        }
    }
    // Pixel rectangles of the labels drawn so far, so that close points' labels do not overprint.
    let mut placed_labels: Vec<LabelBox> = Vec::new();
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
        let offsets: Vec<(i32, i32)> =
            series.iter().map(|p| label_offset(chart.backend_coord(&(p.x, p.y)), &p.label, &mut placed_labels)).collect();
        chart
            .draw_series(series.iter().zip(offsets).map(|(p, offset)| {
                EmptyElement::at((p.x, p.y)) + Text::new(p.label.clone(), offset, ("sans-serif", 13).into_font().color(&BLACK))
            }))
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
        .position(legend)
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
    fn log_ticks_label_one_two_three_and_five_and_labels_do_not_overprint() {
        assert_eq!([10.0, 20.0, 30.0, 50.0, 70.0, 100.0, 0.05, 0.06].map(log_tick), ["10", "20", "30", "50", "", "100", "0.05", ""]);
        assert_eq!(compact(0.1), "0.1");
        let mut placed = Vec::new();
        let first = label_offset((100, 100), "1024", &mut placed);
        let second = label_offset((104, 100), "2048", &mut placed);
        assert_ne!(first, second, "a point 4 pixels away gets its label elsewhere");
        assert_eq!(label_offset((400, 100), "4096", &mut placed), first);
    }

    #[test]
    fn vary_specifications_parse_and_expand() {
        let single = Vary::parse("mine.kernel=7,15,21").unwrap();
        assert_eq!(single.params, vec!["kernel"]);
        assert_eq!(single.values.len(), 3);
        let paired = Vary::parse("mine.search:kernel=7:15,11:21").unwrap();
        let size = Vary::parse("mine.map_size=512,1024").unwrap();
        let points = grid(&[&paired, &size]);
        assert_eq!(points.len(), 4);
        assert_eq!(points[1], vec![("search".into(), "7".into()), ("kernel".into(), "15".into()), ("map_size".into(), "1024".into())]);
        assert_eq!(point_label(&points[1]), "7/15/1024");
        assert!(Vary::parse("mine.a:b=1:2,3").is_err());
        assert!(Vary::parse("mine=1").is_err());
        assert!(Vary::parse("mine.a=").is_err());
        // A bare technique: one point at its defaults.
        let bare = Vary::parse("mine").unwrap();
        assert_eq!(grid(&[&bare, &size]).len(), 2);
        assert_eq!(grid(&[&bare])[0], Vec::<(String, String)>::new());
    }

    #[test]
    fn scene_lights_keeps_the_first_lights_or_copies_the_first() {
        let scene = ssm_scene::builtin("sphere-cube").unwrap().build();
        let with = |n: &str| SceneOverrides::from_point(&[("lights".into(), n.into())]).unwrap().apply(&scene).unwrap();
        assert_eq!(with("1").lights, scene.lights[..1].to_vec());
        assert_eq!(with("3").lights, vec![scene.lights[0]; 3]);
        let mut two = scene.clone();
        two.lights.push(ssm_scene::RectLight { half_size: glam::Vec2::ZERO, ..scene.lights[0] });
        let kept = SceneOverrides::from_point(&[("lights".into(), "3".into())]).unwrap().apply(&two).unwrap();
        assert_eq!(kept.lights, vec![two.lights[0], two.lights[1], two.lights[0]], "the scene's own lights first");
        for bad in ["0", "1.5", "9", "-1"] {
            assert!(SceneOverrides::from_point(&[("lights".into(), bad.into())]).is_err(), "scene.lights={bad}");
        }
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
        assert!(SceneOverrides::from_point(&[("light_scale".into(), "-1".into())]).is_err());
        // Sideways by a quarter of the light's width (1 × 0.5 after the scale), along its first axis.
        let shifted = SceneOverrides::from_point(&[("light_scale".into(), "0.5".into()), ("occluder_shift".into(), "0.25".into())])
            .unwrap()
            .apply(&scene)
            .unwrap();
        let occluder = shifted.bounds_where(|r| r == ssm_scene::Role::Occluder);
        assert!((occluder.min.x - (-0.5 + 0.125)).abs() < 1e-5 && (occluder.min.y - 2.0).abs() < 1e-5, "{occluder:?}");
    }

    #[test]
    fn a_built_in_scenes_own_parameters_are_scene_parameters_of_a_sweep() {
        let point = |name: &str, value: &str| SceneOverrides::from_point(&[(name.to_owned(), value.to_owned())]).unwrap();
        let tessellated = point("segments", "4");
        assert_eq!(tessellated.scene_spec("floating-sphere"), "floating-sphere:segments=4");
        assert_eq!(tessellated.scene_spec("floating-sphere:rings=3"), "floating-sphere:rings=3,segments=4");
        let base = ssm_scene::builtin("floating-sphere").unwrap().build();
        let coarse = point("segments", "4").base_scene("floating-sphere:rings=3", &base).unwrap();
        // Ground (2 triangles) and a sphere of 2 · 4 · (3 − 1).
        assert_eq!((base.triangle_count(), coarse.triangle_count()), (2 + 2 * 48 * 23, 2 + 16));
        // Unknown to the scene, out of its range, or on a scene that has no parameters: refused before any GPU work.
        for (spec, name, value) in [
            ("floating-sphere", "size", "1"),
            ("floating-sphere", "segments", "1"),
            ("parallel-square", "segments", "4"),
            ("scene.toml", "segments", "4"),
        ] {
            let error = point(name, value).check_scene(spec).unwrap_err();
            assert!(format!("{error:#}").contains(&format!("scene.{name}")), "{spec} {name}={value}: {error:#}");
        }
        // The sweep's own parameters need no built-in scene.
        assert!(point("occluder_shift", "0.5").check_scene("scene.toml").is_ok());
    }

    #[test]
    fn parameters_in_step_with_the_x_axis_and_decade_spans() {
        let specs = ["scene.segments:rings=4:3,16:8".to_owned(), "atty.two_sided=false,true".to_owned()];
        assert_eq!(in_step_with(&specs, "scene.segments"), vec!["scene.rings".to_owned()]);
        assert!(in_step_with(&specs, "atty.two_sided").is_empty());
        assert!(in_step_with(&specs, "time").is_empty());
        assert!(spans_decades(&[4.0, 16.0, 512.0]) && !spans_decades(&[1.0, 2.0, 4.0]));
        assert!(!spans_decades(&[-1.0, 0.5, 100.0]), "a non-positive value keeps the axis linear");
    }

    #[test]
    fn the_pass_chart_labels_each_bar_with_its_frame_time() {
        let dir = std::env::temp_dir().join(format!("ssm-pass-chart-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (png, svg) = (dir.join("passes.png"), dir.join("passes.svg"));
        let bars = vec![
            ("fast".to_owned(), vec![("shadow_map".to_owned(), 1.0), ("filter".to_owned(), 3.0)]),
            ("slow".to_owned(), vec![("tiles".to_owned(), 900.0), ("filter".to_owned(), 100.0)]),
            ("untimed".to_owned(), Vec::new()),
        ];
        pass_chart(&bars, "title", &png, &svg).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("fast (4.0 ms)") && text.contains("slow (1000.0 ms)") && !text.contains("untimed"), "{text}");
        assert!(text.lines().any(|line| line.trim() == "tiles"), "a wide segment is named");
        assert!(pass_chart(&bars[2..], "title", &png, &svg).is_err(), "nothing timed");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn log_axes_get_round_ticks_even_within_a_decade() {
        assert_eq!(log_key_points(0.017, 0.1), vec![0.02, 0.03, 0.05, 0.1]);
        let wide = log_key_points(7.0, 5000.0);
        assert_eq!(wide.first().copied(), Some(10.0));
        assert!(wide.contains(&200.0) && wide.contains(&5000.0) && !wide.contains(&300.0), "{wide:?}");
        assert!(log_key_points(0.0, 1.0).is_empty());
    }

    #[test]
    fn an_axis_of_integers_is_labelled_at_integers_only() {
        assert_eq!(linear_tick(1.5, true), "");
        assert_eq!(linear_tick(2.0, true), "2");
        assert_eq!(linear_tick(1.5, false), "1.5");
    }

    #[test]
    fn the_legend_hides_no_point_even_when_every_corner_is_taken() {
        // Eight series over 1, 2 and 3 lights spread over two decades: every corner holds points.
        let points: Vec<PlotPoint> = (0..8)
            .flat_map(|series| {
                (1..=3).map(move |lights| PlotPoint {
                    series: format!("s{series}"),
                    x: f64::from(lights),
                    y: 10.0 * 1.9f64.powi(series) * f64::from(lights),
                    label: String::new(),
                })
            })
            .collect();
        let refs: Vec<&PlotPoint> = points.iter().collect();
        let (y_low, y_max) = (10.0 / 1.5, refs.iter().map(|p| p.y).fold(0.0, f64::max));
        let x_fraction = |x: f64| (x - 0.84) / 2.32;
        assert!(emptiest_corner(&refs, x_fraction, |y| (y / y_low).ln() / (y_max * 1.5 / y_low).ln()).1 > 0, "the case is crowded");
        let (y_high, corner) = legend_room(&refs, y_low, y_max, &x_fraction, false);
        assert_eq!(corner, SeriesLabelPosition::UpperRight);
        let top = 1.0 - legend_share(8);
        assert!(refs.iter().all(|p| (p.y / y_low).ln() / (y_high / y_low).ln() < top), "a point under the legend");
    }

    #[test]
    fn image_folders_are_named_by_the_points_assignments() {
        let point = vec![("atty.occluder_map_size".to_owned(), "128".to_owned()), ("atty.two_sided".to_owned(), "true".to_owned())];
        assert_eq!(assignment_label(&point), "occluder_map_size=128;two_sided=true");
        assert_eq!(path_component(&assignment_label(&point)), "occluder_map_size=128_two_sided=true");
        assert_eq!(assignment_label(&[]), "defaults");
        assert_eq!(path_component("a/b:c d"), "a_b_c_d");
    }

    #[test]
    fn markdown_tables_of_several_sweeps_concatenate() {
        let row = |technique: &str| MarkdownRow {
            scene: "sphere-cube[lights=2]".into(),
            technique: technique.into(),
            point: String::new(),
            ms: 12.345,
            mae_penumbra: 0.01234,
            psnr: 31.25,
        };
        let first = markdown("lights", "llvmpipe", (320, 240), 3, &[row("hard"), row("pcss")]);
        let lines: Vec<&str> = first.lines().collect();
        assert_eq!(lines[0], "Adapter: llvmpipe; 320×240 pixels; median of 3 frames.");
        assert_eq!(lines[4], "| lights | sphere-cube[lights=2] | hard | defaults | 12.35 | 0.0123 | 31.2 |");
        assert_eq!(lines.len(), 6, "a title, a blank line, the header, its rule, then one line per row");
    }

    #[test]
    fn pareto_front_keeps_the_undominated_points_in_time_order() {
        let points = [(1.0, 0.5), (2.0, 0.2), (3.0, 0.3), (4.0, 0.1), (2.0, 0.6), (f64::NAN, 0.0)];
        assert_eq!(pareto_front(&points), vec![0, 1, 3]);
        // Ties are not domination.
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0, 1]);
    }
}
