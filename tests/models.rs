//! The fetched third-party models (scripts/fetch-models.sh) load through
//! their manifests and render with every registered real-time technique. A
//! missing cache fails the test with the command that fills it: it is never
//! skipped.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use ssm_core::{Error, TechniqueKind};
use ssm_integration_tests::registry;
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
    for (manifest, triangles) in [("dragon.toml", 202_520), ("bunny.toml", 69_666), ("sponza.toml", 66_000)] {
        let scene = load(manifest);
        // Receiver planes add two triangles; Sponza's quads are split, so only a lower bound holds there.
        assert!(scene.triangle_count() >= triangles, "{manifest}: {} triangles", scene.triangle_count());
        for info in registry().iter().filter(|i| i.kind == TechniqueKind::Realtime) {
            let technique = info.name;
            let rendered = match render(&gpu, &scene, info, &[], 128, 96) {
                Ok(rendered) => rendered,
                Err(Error::MissingFeatures { .. } | Error::LimitTooLow { .. }) => continue,
                Err(e) => panic!("{manifest} / {technique}: {e}"),
            };
            let shadowed = rendered.visibility.iter().filter(|v| **v < 0.5).count();
            let lit = rendered.visibility.iter().filter(|v| **v > 0.5).count();
            assert!(shadowed > 100 && lit > 100, "{manifest} / {technique}: {shadowed} shadowed, {lit} lit");
        }
    }
}
