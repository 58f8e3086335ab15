//! Multiple lights are a first-class case: for every registered technique (a
//! loop over the registry, the ground truth included), the visibility of
//! light k in a scene lit by three lights of different position, size and
//! intensity equals the visibility of the same scene lit by light k alone.
//! Guards against per-light state that one light's work overwrites before
//! another's is used (an upload recorded once for the whole frame, say).
//! Every technique of `MUST_RUN_ON_LAVAPIPE` (tests/support.rs) must run.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::{Vec2, Vec3};
use ssm_integration_tests::{MUST_RUN_ON_LAVAPIPE, missing_must_run, registry, render_or_refusal};
use ssm_scene::{RectLight, Scene, builtin};
use ssm_testing::{gpu, render};

const WIDTH: u32 = 80;
const HEIGHT: u32 = 60;
/// Every technique here is deterministic: the same inputs give the same floats, up to this.
const TOLERANCE: f32 = 1e-5;

/// `floating-sphere` lit by three lights that differ in position, orientation, size and intensity.
fn three_lights() -> Vec<RectLight> {
    let light =
        |centre: Vec3, normal: Vec3, size: Vec2, intensity: f32| RectLight::try_facing(centre, normal, Vec3::X, size, intensity).unwrap();
    vec![
        light(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, Vec2::new(1.0, 1.0), 1.0),
        light(Vec3::new(2.0, 5.0, 1.0), Vec3::new(-0.3, -1.0, -0.2), Vec2::new(2.0, 0.5), 0.5),
        light(Vec3::new(-2.0, 3.0, -1.0), Vec3::new(0.4, -1.0, 0.3), Vec2::new(0.2, 0.2), 2.0),
    ]
}

fn scene_with(lights: Vec<RectLight>) -> Scene {
    let mut scene = builtin("floating-sphere").unwrap().build();
    scene.lights = lights;
    scene
}

#[test]
fn each_light_of_three_equals_that_light_alone_for_every_technique() {
    let gpu = gpu();
    let lights = three_lights();
    let all = scene_with(lights.clone());
    let mut failures: Vec<String> = missing_must_run().iter().map(|name| format!("{name} must run here but is not registered")).collect();
    let mut checked = 0;
    for info in registry().iter() {
        // The ground truth with few rays and no cache: deterministic per pixel, and quick.
        let settings: &[(&str, &str)] = if info.name == "reference" { &[("samples", "4"), ("cache", "false")] } else { &[] };
        let together = match render_or_refusal(info.name, "three lights", render(&gpu, &all, info, settings, WIDTH, HEIGHT)) {
            Ok(Some(rendered)) => rendered,
            Ok(None) => continue,
            Err(message) => {
                failures.push(message);
                continue;
            }
        };
        let mut alone_images = Vec::new();
        for (k, light) in lights.iter().enumerate() {
            let of_three = together.renderer.read_visibility(k, info.name).unwrap();
            let alone = render(&gpu, &scene_with(vec![*light]), info, settings, WIDTH, HEIGHT).unwrap().visibility;
            let worst = of_three.iter().zip(&alone).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
            if worst > TOLERANCE {
                failures.push(format!("{}: light {k} of three differs from light {k} alone by up to {worst}", info.name));
            }
            alone_images.push(alone);
        }
        if info.name == "reference" {
            // The lights' shadows differ, so a technique that wrote one light's image for all fails.
            for (k, image) in alone_images.iter().enumerate() {
                assert!(image.iter().any(|v| *v < 0.5), "light {k} shadows part of the scene");
                for (j, other) in alone_images.iter().enumerate().skip(k + 1) {
                    let mean = image.iter().zip(other).map(|(a, b)| (a - b).abs()).sum::<f32>() / image.len() as f32;
                    assert!(mean > 0.01, "lights {k} and {j} give nearly the same image ({mean})");
                }
            }
        }
        checked += 1;
    }
    // Every must-run technique and the ground truth.
    assert!(checked > MUST_RUN_ON_LAVAPIPE.len(), "only {checked} techniques ran");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Each light's colour tints its own contribution to the shaded image and nothing else: under a
/// red light and a blue one, a lit ground pixel is red plus blue with no green beyond the
/// ambient term, and the visibility is the same as under white lights.
#[test]
fn light_colours_tint_the_shaded_image_only() {
    let gpu = gpu();
    let lights = three_lights();
    let coloured = vec![lights[0].with_colour(Vec3::new(1.0, 0.0, 0.0)), lights[1].with_colour(Vec3::new(0.0, 0.0, 1.0))];
    let white = vec![lights[0], lights[1]];
    let hard = registry().get("hard").unwrap();
    let mut shaded = Vec::new();
    let mut visibility = Vec::new();
    for lights in [coloured, white] {
        let mut rendered = render(&gpu, &scene_with(lights), hard, &[], WIDTH, HEIGHT).unwrap();
        visibility.push(rendered.visibility.clone());
        shaded.push(rendered.renderer.shade().unwrap());
    }
    assert_eq!(visibility[0], visibility[1], "colour does not change visibility");
    // A ground pixel near the bottom corner, lit by both lights.
    let pixel = ((HEIGHT - 4) * WIDTH + 6) as usize * 4;
    let (tinted, plain) = (&shaded[0][pixel..pixel + 3], &shaded[1][pixel..pixel + 3]);
    println!("shaded pixel: coloured lights {tinted:?}, white lights {plain:?}");
    let ambient = tinted[1];
    assert!(tinted[0] > ambient + 20 && tinted[2] > ambient + 20, "red and blue over the ambient green: {tinted:?}");
    assert!(plain[1] > ambient + 20, "white lights light green too: {plain:?}");
}
