//! The fetched third-party models (scripts/fetch-models.sh) load through
//! their manifests and render with every registered real-time technique. A
//! missing cache fails the test with the command that fills it: it is never
//! skipped. Every technique of `MUST_RUN_ON_LAVAPIPE` (tests/support.rs) must
//! run; one registered from elsewhere may refuse with a typed device refusal.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use ssm_core::TechniqueKind;
use ssm_integration_tests::{missing_must_run, registry, render_or_refusal};
use ssm_scene::Scene;
use ssm_testing::{gpu, render};

fn load(manifest: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models").join(manifest);
    match Scene::load(path.to_str().unwrap()) {
        Ok((scene, _)) => scene,
        Err(e) => panic!("{e}\n(run scripts/fetch-models.sh to fetch the test models)"),
    }
}

#[test]
fn fetched_models_render_with_every_technique() {
    let gpu = gpu();
    let mut failures: Vec<String> = missing_must_run().iter().map(|name| format!("{name} must run here but is not registered")).collect();
    for (manifest, triangles) in [("dragon.toml", 202_520), ("bunny.toml", 69_666), ("sponza.toml", 66_000)] {
        let scene = load(manifest);
        // Receiver planes add two triangles; Sponza's quads are split, so only a lower bound holds there.
        assert!(scene.triangle_count() >= triangles, "{manifest}: {} triangles", scene.triangle_count());
        for info in registry().iter().filter(|i| i.kind == TechniqueKind::Realtime) {
            let technique = info.name;
            let rendered = match render_or_refusal(technique, manifest, render(&gpu, &scene, info, &[], 128, 96)) {
                Ok(Some(rendered)) => rendered,
                Ok(None) => continue,
                Err(message) => {
                    failures.push(message);
                    continue;
                }
            };
            let shadowed = rendered.visibility.iter().filter(|v| **v < 0.5).count();
            let lit = rendered.visibility.iter().filter(|v| **v > 0.5).count();
            if shadowed <= 100 || lit <= 100 {
                failures.push(format!("{manifest} / {technique}: {shadowed} shadowed, {lit} lit"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
