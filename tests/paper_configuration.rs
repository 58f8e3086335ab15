//! Every technique's defaults against its paper's own configuration
//! ([`ssm_core::PaperConfiguration`]), on the paper's own kind of scene: where a default departs
//! from the paper (a receiver model, an anti-aliasing mode, a blur's weights), it must be no less
//! accurate there than the paper's configuration, beyond the ground truth's noise, against the
//! ground truth every technique's tables are judged by (its defaults: the visibility at each
//! pixel's point). Where the paper judges its output against another truth (a pixel-footprint
//! truth for an anti-aliased visibility), both configurations are also printed against that one.
//! Where one value of a parameter is decided by how the scene falls on a texel grid, both are
//! judged by their mean over a whole cycle of that parameter's values.
//!
//! Each comparison is printed with both errors: the technique READMEs quote them.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use ssm_core::TechniqueKind;
use ssm_core::metrics::compare_with_noise;
use ssm_core::reference::{GroundTruth, Sampling, surface_points};
use ssm_integration_tests::{missing_must_run, registry};
use ssm_scene::Scene;
use ssm_testing::{gpu, render};

/// Settings as `(param, value)` pairs.
type Settings = Vec<(&'static str, &'static str)>;

/// The settings of one run of a configuration, given the averaged parameter's value (if any).
type SettingsOf<'a> = &'a dyn Fn(&[(&'static str, &'static str)]) -> Settings;

const WIDTH: u32 = 128;
const HEIGHT: u32 = 96;

/// Rays per axis per pixel of the ground truth (each of its two sets).
const REFERENCE_SAMPLES: u32 = 8;

/// The techniques that must declare a paper configuration: their defaults depart from their
/// papers (see each README's deviations). The test fails when one of them declares none.
const DEPARTING_FROM_THEIR_PAPERS: &[&str] = &["atty", "pcss", "pvsm", "sssm"];

/// A scene by built-in name or manifest path (from the workspace's root).
fn load(spec: &str) -> Scene {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let spec = if ssm_scene::parse_builtin(spec).is_some() { spec.to_owned() } else { root.join(spec).display().to_string() };
    Scene::load(&spec).unwrap_or_else(|e| panic!("{spec}: {e}")).0
}

/// `param=value` as a pair.
fn pair(setting: &str) -> (&str, &str) {
    setting.split_once('=').unwrap_or_else(|| panic!("`{setting}` is not param=value"))
}

/// Light 0's ground truth of `scene` and its noise, at the pixels' points or averaged over each
/// pixel's footprint (the truth's `footprint` parameter in `truth`), and the covered pixels.
fn truth(gpu: &ssm_core::GpuContext, scene: &Scene, truth: &[&str]) -> (Vec<f32>, Vec<f32>, Vec<bool>) {
    let params = ssm_core::reference::INFO.params_from(truth.iter().map(|s| pair(s))).unwrap();
    let footprint = params.choice("footprint").unwrap() == "pixel";
    let needs = ssm_core::Requirements { gbuffer: true, ..ssm_core::Requirements::NONE };
    let renderer = ssm_core::Renderer::new(gpu, scene, WIDTH, HEIGHT, &needs).unwrap();
    let positions = renderer.read_positions().unwrap();
    let points = surface_points(&positions, &renderer.read_normals().unwrap(), &renderer.scene.camera, footprint);
    let sampling = Sampling { samples_per_axis: REFERENCE_SAMPLES, ..Sampling::DEFAULT };
    let image = GroundTruth::new(scene).trace(&scene.lights[0], &points, sampling, 1);
    (image.visibility, image.noise, positions.iter().map(|p| p[3] > 0.5).collect())
}

#[test]
fn every_default_is_no_less_accurate_than_its_papers_configuration_on_the_papers_scenes() {
    assert!(missing_must_run().is_empty(), "techniques that must run are not registered: {:?}", missing_must_run());
    let gpu = gpu();
    let mut compared = Vec::new();
    let mut failures = Vec::new();
    for info in registry().iter().filter(|info| info.kind == TechniqueKind::Realtime) {
        let paper = info.paper_configuration;
        if paper.settings.is_empty() {
            assert!(!DEPARTING_FROM_THEIR_PAPERS.contains(&info.name), "{} declares no paper configuration", info.name);
            continue;
        }
        assert!(!paper.scenes.is_empty(), "{}: a paper configuration names the paper's scenes", info.name);
        let paper_settings: Vec<(&str, &str)> = paper.settings.iter().map(|s| pair(s)).collect();
        info.params_from(paper_settings.iter().copied()).unwrap_or_else(|e| panic!("{}: the paper's settings: {e}", info.name));
        // One value per run: the default alone, or every value of the averaged parameter.
        let cycle: Vec<Vec<(&str, &str)>> = match paper.averaged_over {
            None => vec![Vec::new()],
            Some(spec) => {
                let (param, values) = pair(spec);
                values.split(',').map(|value| vec![(param, value)]).collect()
            }
        };
        for scene_name in paper.scenes {
            let scene = load(scene_name);
            let (default_truth, default_noise, covered) = truth(&gpu, &scene, &[]);
            let (paper_truth, paper_noise, _) = truth(&gpu, &scene, paper.truth);
            let mean = |settings_of: SettingsOf<'_>, truth: &[f32], noise: &[f32]| {
                let (mut error, mut truth_noise) = (0.0, 0.0);
                for values in &cycle {
                    let settings = settings_of(values);
                    let rendered = render(&gpu, &scene, info, &settings, WIDTH, HEIGHT)
                        .unwrap_or_else(|e| panic!("{} on {scene_name} with {settings:?}: {e}", info.name));
                    let metrics = compare_with_noise(truth, Some(noise), &rendered.visibility, &covered, WIDTH as usize, HEIGHT as usize);
                    error += metrics.mae;
                    truth_noise += metrics.truth_noise.unwrap_or(0.0);
                }
                (error / cycle.len() as f64, truth_noise / cycle.len() as f64)
            };
            let defaults = |values: &[(&'static str, &'static str)]| values.to_vec();
            let papers = |values: &[(&'static str, &'static str)]| paper_settings.iter().copied().chain(values.iter().copied()).collect();
            let (default_error, default_truth_noise) = mean(&defaults, &default_truth, &default_noise);
            let (paper_error, paper_truth_noise) = mean(&papers, &default_truth, &default_noise);
            let averaged = paper.averaged_over.map(|a| format!(" (means over {a})")).unwrap_or_default();
            println!(
                "{:<6} {scene_name:<16} defaults {default_error:.4} ± {default_truth_noise:.4}, the paper's configuration ({}) {paper_error:.4} ± {paper_truth_noise:.4}{averaged}",
                info.name,
                paper.settings.join(", "),
            );
            if !paper.truth.is_empty() {
                let (default_on_papers, noise_on_papers) = mean(&defaults, &paper_truth, &paper_noise);
                let (paper_on_papers, _) = mean(&papers, &paper_truth, &paper_noise);
                println!(
                    "{:<6} {scene_name:<16} against the paper's truth ({}): defaults {default_on_papers:.4}, the paper's configuration {paper_on_papers:.4} (± {noise_on_papers:.4})",
                    info.name,
                    paper.truth.join(", ")
                );
            }
            compared.push(info.name);
            // Equal pixels can differ in the last bits of a sum over the cycle.
            if default_error > paper_error + default_truth_noise + paper_truth_noise + 1e-6 {
                failures.push(format!(
                    "{} on {scene_name}: the defaults' error {default_error:.4} is above the paper configuration's {paper_error:.4}",
                    info.name
                ));
            }
        }
    }
    for name in DEPARTING_FROM_THEIR_PAPERS {
        assert!(compared.contains(name), "{name} was not compared");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
