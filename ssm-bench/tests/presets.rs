//! Every preset a technique declares (and the assembled `trade`) resolves:
//! its scenes load, its varies name registered techniques and parameters
//! with valid values, its x axis is one of them. A new technique's presets
//! are checked without editing this file.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_bench::registry;
use ssm_bench::sweep::{SweepPlan, preset, presets, trade_preset};
use ssm_core::TechniqueKind;

#[test]
fn every_preset_resolves_against_the_registry() {
    let registry = registry().unwrap();
    let all = presets(registry).unwrap();
    assert!(all.len() >= 8, "{} presets", all.len());
    for spec in &all {
        let plan = SweepPlan::new(registry, &spec.varies, &[]).unwrap_or_else(|e| panic!("preset {}: {e:#}", spec.name));
        assert!(!plan.points.is_empty(), "preset {} has no point", spec.name);
        assert!(spec.x_axis == "time" || plan.varied.contains(&spec.x_axis), "preset {}: x axis {} is not varied", spec.name, spec.x_axis);
        assert!(!spec.scenes.is_empty(), "preset {} names no scene", spec.name);
        // Scene axes (a built-in scene's own parameters among them) fit every scene it names.
        for overrides in &plan.scene_overrides {
            for scene in &spec.scenes {
                overrides.check_scene(scene).unwrap_or_else(|e| panic!("preset {}: scene {scene}: {e:#}", spec.name));
            }
        }
        // The fixed settings name a registered technique (the ground truth included) and one of
        // its parameters, with a value in range.
        for setting in &spec.settings {
            let (key, value) = setting.split_once('=').unwrap_or_else(|| panic!("preset {}: setting {setting}", spec.name));
            let (technique, param) = key.split_once('.').unwrap_or_else(|| panic!("preset {}: setting {setting}", spec.name));
            let info = registry.iter().find(|i| i.name == technique).unwrap_or_else(|| panic!("preset {}: {setting}", spec.name));
            info.params_from([(param, value)]).unwrap_or_else(|e| panic!("preset {}: {setting}: {e}", spec.name));
        }
        for scene in &spec.scenes {
            // Built-in names load; manifests are resolved from the repository's root.
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(scene);
            let spec_path = if ssm_scene::parse_builtin(scene).is_some() { scene.clone() } else { path.display().to_string() };
            ssm_scene::Scene::load(&spec_path).unwrap_or_else(|e| panic!("preset {}: scene {scene}: {e}", spec.name));
        }
    }
    assert!(preset(registry, "nope").unwrap_err().to_string().contains("trade"));
}

/// `trade` is assembled from what each technique declares: every real-time technique with a
/// quality knob is in it, varied over its values.
#[test]
fn trade_takes_every_techniques_quality_knob() {
    let registry = registry().unwrap();
    let trade = trade_preset(registry);
    for info in registry.iter().filter(|i| i.kind == TechniqueKind::Realtime) {
        if let Some(knob) = info.trade {
            assert!(trade.varies.contains(&format!("{}.{knob}", info.name)), "{} missing from {:?}", info.name, trade.varies);
        }
    }
    let with_knobs = registry.iter().filter(|i| i.trade.is_some()).count();
    assert!(with_knobs >= 5, "only {with_knobs} techniques declare a quality knob");
}

/// A parameter on two axes would be set twice at every point, the later value silently winning:
/// refused with its name.
#[test]
fn a_parameter_varied_twice_is_refused() {
    let registry = registry().unwrap();
    let twice = ["pcss.pcf_kernel=7,15".to_owned(), "pcss.blocker_kernel:pcf_kernel=3:5,7:9".to_owned()];
    let error = SweepPlan::new(registry, &twice, &[]).unwrap_err();
    assert!(format!("{error:#}").contains("pcss.pcf_kernel is varied twice"), "{error:#}");
    let scene_twice = ["scene.light_scale=1,2".to_owned(), "scene.light_scale=3".to_owned(), "pcss".to_owned()];
    assert!(SweepPlan::new(registry, &scene_twice, &[]).is_err());
}

/// A preset that reproduces a paper's measurements renders at the paper's viewport unless the
/// command line gives a size, each dimension on its own; one without a viewport at 640×480.
#[test]
fn a_preset_carries_its_papers_image_size() {
    use ssm_bench::sweep::{DEFAULT_SIZE, image_size};
    let registry = ssm_bench::registry().unwrap();
    let steps = preset(registry, "sssm-steps").unwrap();
    assert_eq!(steps.size, Some((1280, 720)), "Buades et al., Sec. 5: a 1,280 × 720 viewport");
    let table4 = preset(registry, "sssm-table4").unwrap();
    assert_eq!(table4.size, Some((1280, 960)), "Buades et al., Table 4's caption: a 1,280 × 960 viewport");
    assert_eq!(image_size(None, None, Some(&table4)), (1280, 960));
    assert_eq!(image_size(Some(320), None, Some(&table4)), (320, 960));
    assert_eq!(image_size(Some(320), Some(240), Some(&table4)), (320, 240));
    let trade = trade_preset(registry);
    assert_eq!(image_size(None, None, Some(&trade)), DEFAULT_SIZE);
    assert_eq!(image_size(None, Some(100), None), (DEFAULT_SIZE.0, 100));
    for spec in presets(registry).unwrap() {
        if let Some((width, height)) = spec.size {
            assert!(width > 0 && height > 0, "preset {}: {width}x{height}", spec.name);
        }
    }
}

/// Buades et al.'s Table 4 preset sweeps the table's own rows: its three kernel pairs for both
/// techniques and its five SSSM thresholds (α; β with it), the paper's headline α = 0.1 among them.
#[test]
fn the_table4_preset_sweeps_the_tables_rows() {
    let registry = ssm_bench::registry().unwrap();
    let table4 = preset(registry, "sssm-table4").unwrap();
    for expected in [
        "pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41",
        "sssm.blocker_kernel:blur_kernel=7:15,11:21,29:41",
        "sssm.alpha:beta=0.01:0.01,0.1:0.1,0.15:0.15,0.2:0.2,0.5:0.5",
    ] {
        assert!(table4.varies.iter().any(|vary| vary == expected), "{expected} missing from {:?}", table4.varies);
    }
}
