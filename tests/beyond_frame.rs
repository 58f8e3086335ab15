//! Receivers past the light frame's widest angle (`ssm-core/src/beyond_frame.rs`): where a light's
//! frame reaches MAX_HALF_ANGLE_TANGENT (about 84 degrees off its normal), no map of a technique
//! that sees the light through that frame has a texel, and the framework answers those pixels
//! with a hard shadow from the light's centre through a hemicube's side faces, counts them and
//! reports them. A light inside an enclosure of open quads on a wide ground (no closed mesh, so no
//! framework cull): the ground outside is umbra past 84 degrees, where every frame technique read
//! 0.75 to 0.89 before. A scene inside the widest angle gets no faces and no pass.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use glam::Vec3;
use ssm_core::{BEYOND_FRAME_DIAGNOSTIC, BEYOND_FRAME_PASS, LightView, Renderer, Requirements, TechniqueInfo, TechniqueKind};
use ssm_integration_tests::{missing_must_run, registry};
use ssm_scene::{Scene, builtin};
use ssm_testing::{gpu, pixel_of};

const SIZE: (u32, u32) = (96, 72);

/// Four walls down to the ground around a light 0.3 above it, a ceiling behind the light, on a
/// ground 24 wide: past 3 units out the ground is more than 84 degrees off the light's normal.
const ENCLOSURE: &str = "[camera]\nposition = [0.0, 7.0, 9.0]\ntarget = [0.0, 0.0, 0.0]\n\
    [[light]]\ncentre = [0.0, 0.3, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.4, 0.4]\n\
    [[object]]\nprimitive = \"plane\"\nsize = [24.0, 24.0]\nrole = \"receiver\"\n\
    [[object]]\nprimitive = \"plane\"\nsize = [2.0, 2.0]\ntranslate = [0.0, 0.8, 0.0]\nrole = \"occluder\"\n\
    [[object]]\nprimitive = \"plane\"\nsize = [2.0, 0.8]\nrotate_degrees = [90.0, 0.0, 0.0]\ntranslate = [0.0, 0.4, 1.0]\n\
    [[object]]\nprimitive = \"plane\"\nsize = [2.0, 0.8]\nrotate_degrees = [90.0, 0.0, 0.0]\ntranslate = [0.0, 0.4, -1.0]\n\
    [[object]]\nprimitive = \"plane\"\nsize = [0.8, 2.0]\nrotate_degrees = [0.0, 0.0, 90.0]\ntranslate = [1.0, 0.4, 0.0]\n\
    [[object]]\nprimitive = \"plane\"\nsize = [0.8, 2.0]\nrotate_degrees = [0.0, 0.0, 90.0]\ntranslate = [-1.0, 0.4, 0.0]\n";

/// Ground points outside the enclosure and past the frame's widest angle (tangent > 10 at 0.3
/// below the light).
const PAST_THE_FRAME: [Vec3; 3] = [Vec3::new(5.0, 0.0, 0.0), Vec3::new(-4.0, 0.0, 3.0), Vec3::new(0.0, 0.0, 5.0)];

fn enclosure() -> Scene {
    let origin = PathBuf::from("beyond-frame:enclosure");
    ssm_scene::Manifest::parse(ENCLOSURE, &origin).unwrap().build(&origin, Path::new(".")).unwrap()
}

/// What one frame of a technique gave: light 0's visibility, the technique's diagnostics and the
/// labels of its timed passes.
struct Frame {
    visibility: Vec<f32>,
    diagnostics: Vec<(String, f64)>,
    passes: Vec<String>,
}

/// One frame of `info` at its defaults.
fn render(scene: &Scene, info: &'static TechniqueInfo) -> ssm_core::Result<Frame> {
    let gpu = gpu();
    let params = info.default_params();
    let needs = info.needs(&params)?.union(Requirements { gbuffer: true, ..Requirements::NONE });
    let mut renderer = Renderer::new(&gpu, scene, SIZE.0, SIZE.1, &needs)?;
    let mut technique = renderer.create_technique(info, &params)?;
    let timings = renderer.render(technique.as_mut(), info.name)?;
    let visibility = renderer.read_visibility(0, info.name)?;
    let diagnostics = technique.diagnostics(&renderer.gpu);
    Ok(Frame { visibility, diagnostics, passes: timings.passes.iter().map(|p| p.name.clone()).collect() })
}

#[test]
fn the_framework_answers_receivers_past_the_frame_and_counts_them() {
    let scene = enclosure();
    let mut failures: Vec<String> = missing_must_run().iter().map(|name| format!("{name} must run here but is not registered")).collect();
    let mut ran = Vec::new();
    for info in registry().iter().filter(|info| info.kind == TechniqueKind::Realtime) {
        let Frame { visibility, diagnostics, passes } = match render(&scene, info) {
            Ok(result) => result,
            Err(error) => {
                failures.push(format!("{}: {error}", info.name));
                continue;
            }
        };
        ran.push(info.name);
        let answered = diagnostics.iter().find(|(key, _)| key == BEYOND_FRAME_DIAGNOSTIC).map(|(_, v)| *v);
        let has_pass = passes.iter().any(|p| p.ends_with(BEYOND_FRAME_PASS));
        match info.light_view {
            LightView::Frame => {
                // About a third of the image is ground past 84 degrees.
                let floor = (SIZE.0 * SIZE.1 / 5) as f64;
                if !answered.is_some_and(|n| n > floor) || !has_pass {
                    failures.push(format!(
                        "{}: answered past the frame {answered:?} (at least {floor} expected), pass run: {has_pass}",
                        info.name
                    ));
                }
            }
            LightView::Hemisphere => {
                if answered.is_some() || has_pass {
                    failures.push(format!("{}: sees the whole hemisphere but got the framework's pass", info.name));
                }
            }
        }
        for world in PAST_THE_FRAME {
            let (x, y) = pixel_of(&scene, SIZE.0, SIZE.1, world);
            let value = visibility[(y * SIZE.0 + x) as usize];
            if value > 0.05 {
                failures
                    .push(format!("{}: visibility {value} at {world}, outside the enclosure past the frame, where it is umbra", info.name));
            }
        }
    }
    println!("ran {}", ran.join(", "));
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn scenes_inside_the_widest_angle_get_no_faces_and_no_pass() {
    let scene = builtin("contact").unwrap().build();
    for info in registry().iter().filter(|info| info.kind == TechniqueKind::Realtime && info.light_view == LightView::Frame) {
        let Frame { diagnostics, passes, .. } = render(&scene, info).unwrap();
        assert!(!diagnostics.iter().any(|(key, _)| key == BEYOND_FRAME_DIAGNOSTIC), "{}: reports pixels past the frame", info.name);
        assert!(!passes.iter().any(|p| p.contains(BEYOND_FRAME_PASS)), "{}: runs the pass past the frame: {passes:?}", info.name);
    }
}
