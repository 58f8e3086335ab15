//! The unlit side of a closed mesh: where the whole light is behind a closed surface's tangent
//! plane, no light reaches the side the camera sees (the ground truth's rule for closed meshes,
//! `SurfacePoint::closed`), so the ground truth is 0, and the framework's shared rule
//! (`trivial_visibility` in `shaders/common/screen_pass.wgsl`) gives every technique that 0
//! instead of whatever its shadow map holds there. Open surfaces (a floor, a leaf card) are left
//! to the techniques: the ground truth's rays leave them on the side facing the light. Every
//! technique of `MUST_RUN_ON_LAVAPIPE` (tests/support.rs) must run.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::Vec3;
use ssm_core::{GBuffer, TechniqueKind};
use ssm_integration_tests::{missing_must_run, registry, render_or_refusal};
use ssm_scene::builtin;
use ssm_testing::{gpu, render};

const SIZE: (u32, u32) = (160, 120);

#[test]
fn the_unlit_side_of_a_closed_mesh_is_umbra_in_the_ground_truth_and_every_technique() {
    let gpu = gpu();
    let mut failures: Vec<String> = missing_must_run().iter().map(|name| format!("{name} must run here but is not registered")).collect();
    for name in ["floating-sphere", "sphere-cube", "contact"] {
        let mut ran = Vec::new();
        let scene = builtin(name).unwrap().build();
        let light = scene.lights[0];
        let reference = render(&gpu, &scene, &ssm_core::reference::INFO, &[("samples", "8"), ("cache", "false")], SIZE.0, SIZE.1).unwrap();
        let positions = reference.renderer.read_positions().unwrap();
        let normals = reference.renderer.read_normals().unwrap();
        let hidden: Vec<bool> = positions
            .iter()
            .zip(&normals)
            .map(|(p, n)| {
                p[3] > 0.5
                    && GBuffer::flags(n[3]) & GBuffer::CLOSED != 0
                    && light.is_behind_plane(Vec3::new(p[0], p[1], p[2]), Vec3::new(n[0], n[1], n[2]))
            })
            .collect();
        let count = hidden.iter().filter(|h| **h).count();
        let closed = normals.iter().filter(|n| GBuffer::flags(n[3]) & GBuffer::CLOSED != 0).count();
        println!("{name}: {closed} pixels on closed meshes, {count} with the light wholly behind their tangent plane");
        assert!(count > 60, "{name}: too few pixels ({count}) on the unlit side of a closed mesh to test anything");
        let lit_in_truth = hidden.iter().zip(&reference.visibility).filter(|(h, v)| **h && **v > 0.0).count();
        assert_eq!(lit_in_truth, 0, "{name}: the ground truth sees the light from {lit_in_truth} of {count} such pixels");
        for info in registry().iter().filter(|info| info.kind == TechniqueKind::Realtime) {
            let rendered = match render_or_refusal(info.name, name, render(&gpu, &scene, info, &[], SIZE.0, SIZE.1)) {
                Ok(Some(rendered)) => rendered,
                Ok(None) => continue,
                Err(message) => {
                    failures.push(message);
                    continue;
                }
            };
            ran.push(info.name);
            let lit = hidden.iter().zip(&rendered.visibility).filter(|(h, v)| **h && **v != 0.0).count();
            if lit > 0 {
                failures.push(format!("{name}: {} gives {lit} of {count} pixels on the unlit side of a closed mesh some light", info.name));
            }
        }
        println!("{name}: ran {}", ran.join(", "));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn open_surfaces_are_not_marked_closed() {
    let gpu = gpu();
    // leaves: a floor and open leaf cards only.
    let scene = builtin("leaves").unwrap().build();
    let rendered = render(&gpu, &scene, &ssm_core::reference::INFO, &[("samples", "2"), ("cache", "false")], SIZE.0, SIZE.1).unwrap();
    let normals = rendered.renderer.read_normals().unwrap();
    let covered = rendered.renderer.read_positions().unwrap().iter().filter(|p| p[3] > 0.5).count();
    assert!(covered > 1000);
    assert!(normals.iter().all(|n| GBuffer::flags(n[3]) & GBuffer::CLOSED == 0), "an open surface was marked closed");
}

/// A light sealed in a closed box, seen from outside, reaches nothing the camera sees (every
/// technique's pixels read 0, `LightFrame::sealed`); with the camera moved into the box
/// (`Renderer::set_camera`), the floor inside is lit again.
#[test]
fn a_sealed_light_follows_the_camera_in_and_out_of_its_box() {
    let gpu = gpu();
    let scene = ssm_testing::scene_from_manifest(
        "[camera]\nposition = [0.0, 3.0, 9.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[light]]\ncentre = [0.0, 1.5, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.5, 0.5]\n\
         [[object]]\nprimitive = \"box\"\nsize = [4.0, 2.0, 4.0]\ntranslate = [0.0, 1.0, 0.0]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [40.0, 40.0]\nrole = \"receiver\"\n",
    );
    let hard = registry().get("hard").unwrap();
    let mut outside = render(&gpu, &scene, hard, &[], SIZE.0, SIZE.1).unwrap();
    assert!(outside.renderer.scene.light_frames[0].sealed);
    let covered = outside.covered_visibility();
    assert!(covered.len() > 1000 && covered.iter().all(|v| *v == 0.0), "some of {} pixels see the sealed light", covered.len());
    let inside = ssm_scene::Camera { position: glam::Vec3::new(1.5, 1.2, 1.5), target: glam::Vec3::new(-1.0, 0.0, -1.0), ..scene.camera };
    outside.renderer.set_camera(&inside).unwrap();
    assert!(!outside.renderer.scene.light_frames[0].sealed);
    let mut technique = outside.renderer.create_technique(hard, &hard.default_params()).unwrap();
    outside.renderer.render(technique.as_mut(), hard.name).unwrap();
    let lit = outside.renderer.read_visibility(0, hard.name).unwrap().iter().filter(|v| **v == 1.0).count();
    assert!(lit > 1000, "only {lit} pixels lit inside the box");
    // And out again.
    outside.renderer.set_camera(&scene.camera).unwrap();
    assert!(outside.renderer.scene.light_frames[0].sealed);
    outside.renderer.render(technique.as_mut(), hard.name).unwrap();
    let covered = outside.covered_visibility();
    assert!(covered.iter().all(|v| *v == 0.0), "the camera outside again sees the sealed light");
}
