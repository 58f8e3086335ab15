//! `ssm sweep`'s plan: a grid over techniques' quality knobs (and the scene's), each point
//! measured like a row of `ssm compare` ([`crate::measure`]): the `--vary` axes ([`Vary`]), the
//! presets ([`presets`]), the grid resolved before the GPU is touched ([`SweepPlan`]) and the
//! scene's overrides ([`SceneOverrides`]). The plot of time against error with the Pareto front
//! marked, the speed/accuracy trade, is [`crate::present::sweep`]'s (drawn by
//! [`crate::present::charts`]).

use anyhow::{Context, Result, bail};

use ssm_core::{ParamValues, Registry, TechniqueInfo, TechniqueKind};

use crate::measure::pixels::PixelSet;
use crate::present::sweep::ErrorAxis;

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
    /// Fixed `--set` assignments (`<technique>.<param>=<value>`), under the command line's own.
    pub settings: Vec<String>,
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
            settings: preset.settings.iter().map(|s| (*s).to_owned()).collect(),
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
        y_axis: ErrorAxis::Mae,
        pixels: PixelSet::All,
        size: None,
        settings: Vec::new(),
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
        settings: Vec::new(),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::present::sweep::{point_label, spans_decades};

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
    fn image_folders_are_named_by_the_points_assignments() {
        let point = vec![("atty.occluder_map_size".to_owned(), "128".to_owned()), ("atty.two_sided".to_owned(), "true".to_owned())];
        assert_eq!(assignment_label(&point), "occluder_map_size=128;two_sided=true");
        assert_eq!(path_component(&assignment_label(&point)), "occluder_map_size=128_two_sided=true");
        assert_eq!(assignment_label(&[]), "defaults");
        assert_eq!(path_component("a/b:c d"), "a_b_c_d");
    }
}
