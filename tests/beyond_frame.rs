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
use ssm_core::metrics::compare_with_noise;
use ssm_core::reference::{GroundTruth, Sampling, surface_points};
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

/// A light a thousandth of the floor's size above it, facing it, with a block beside it: the floor
/// sees the light at grazing angles everywhere but under it (the extremes matrix's case).
const RESTING: &str = "[camera]\nposition = [0.0, 4.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n\
    [[light]]\ncentre = [0.0, 0.01, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [1.0, 1.0]\n\
    [[object]]\nprimitive = \"plane\"\nsize = [10.0, 10.0]\nrole = \"receiver\"\n\
    [[object]]\nprimitive = \"box\"\nsize = [0.4, 0.4, 0.4]\ntranslate = [1.5, 0.2, 0.0]\nrole = \"both\"\n";

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
            LightView::SideFaces | LightView::Hemisphere => {
                if answered.is_some() || has_pass {
                    failures.push(format!("{}: answers the whole hemisphere itself but got the framework's pass", info.name));
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
    let mut side_face_techniques = 0;
    for info in registry().iter().filter(|info| info.kind == TechniqueKind::Realtime && info.light_view != LightView::Hemisphere) {
        let Frame { diagnostics, passes, .. } = render(&scene, info).unwrap();
        assert!(!diagnostics.iter().any(|(key, _)| key == BEYOND_FRAME_DIAGNOSTIC), "{}: reports pixels past the frame", info.name);
        assert!(!passes.iter().any(|p| p.contains(BEYOND_FRAME_PASS)), "{}: runs the pass past the frame: {passes:?}", info.name);
        // A technique with side faces of its own draws and reads them only where a frame reaches
        // the widest angle (pcss: `pcss_side_faces`, its faces `pcss_light<i>_face<k>`).
        if info.light_view == LightView::SideFaces {
            side_face_techniques += 1;
            assert!(!passes.iter().any(|p| p.contains("side_faces") || p.contains("_face")), "{}: draws side faces: {passes:?}", info.name);
        }
    }
    assert!(side_face_techniques > 0, "no registered technique answers past the frame with side faces of its own");
}

/// A technique with side faces of its own (pcss, multi-sm) answers the receivers past the frame
/// with its own method, not a hard shadow: beside a light resting on a floor, a block's shadow past
/// 84° is a penumbra as wide as the block's distance, where its mean error where either shadows
/// must be under a third of hard shadows' from the light's centre (0.19: the framework's answer
/// past the frame).
#[test]
fn side_faces_draw_the_penumbra_past_the_frame() {
    let origin = PathBuf::from("beyond-frame:resting");
    let scene = ssm_scene::Manifest::parse(RESTING, &origin).unwrap().build(&origin, Path::new(".")).unwrap();
    let gpu = gpu();
    let needs = Requirements { gbuffer: true, ..Requirements::NONE };
    let renderer = Renderer::new(&gpu, &scene, SIZE.0, SIZE.1, &needs).unwrap();
    let positions = renderer.read_positions().unwrap();
    let points = surface_points(&positions, &renderer.read_normals().unwrap(), &renderer.scene.camera, false);
    let truth = GroundTruth::new(&scene).trace(&scene.lights[0], &points, Sampling::DEFAULT, 1);
    let frame = &renderer.scene.light_frames[0];
    assert!(frame.reaches_widest_angle(), "the case must reach past the frame");
    // Past the frame: in front of the light, outside the frame's map (LightFrame::uv_depth, the
    // lookup every frame technique makes).
    let only_past: Vec<bool> = positions
        .iter()
        .map(|p| {
            let uvd = frame.uv_depth(Vec3::new(p[0], p[1], p[2]));
            p[3] > 0.5 && uvd.z > 0.0 && (uvd.x < 0.0 || uvd.x > 1.0 || uvd.y < 0.0 || uvd.y > 1.0)
        })
        .collect();
    let error_past = |visibility: &[f32]| {
        compare_with_noise(&truth.visibility, Some(&truth.noise), visibility, &only_past, SIZE.0 as usize, SIZE.1 as usize).mae
    };
    let hard = registry().iter().find(|info| info.name == "hard").expect("hard shadows are registered");
    let hard_error = error_past(&render(&scene, hard).unwrap().visibility);
    println!("hard (the framework's answer past the frame): {hard_error:.4} where either shadows past the frame");
    assert!(hard_error > 0.1, "hard shadows past the frame err by only {hard_error:.4}: the case no longer tells a penumbra from none");
    let mut checked = 0;
    for info in registry().iter().filter(|info| info.light_view == LightView::SideFaces) {
        let error = error_past(&render(&scene, info).unwrap().visibility);
        println!("{}: {error:.4} where either shadows past the frame", info.name);
        assert!(
            error < hard_error / 3.0,
            "{}: mean |error| {error:.4} past the frame where either shadows (hard: {hard_error:.4})",
            info.name
        );
        checked += 1;
    }
    assert!(checked > 0, "no registered technique answers past the frame with side faces of its own");
}

/// The pass's counted work (`--count-work`) in the enclosure, after vssm: one invocation per pixel
/// (96 × 72 is whole 8 × 8 groups), each reading the G-buffer's position and normal (Rgba32Float,
/// 16 bytes each), and, at each pixel it answers (the diagnostic [`BEYOND_FRAME_DIAGNOSTIC`] of
/// the same frame), one side face's texel (R32Float, 4 bytes) and one R32Float visibility stored.
#[test]
fn the_pass_counts_its_reads_with_their_bytes() {
    let gpu = gpu();
    let scene = enclosure();
    let info = registry().get("vssm").unwrap();
    let params = info.params_from([("shadow_map_size", "256")]).unwrap();
    let needs = info.needs(&params).unwrap().union(Requirements { gbuffer: true, ..Requirements::NONE });
    let mut renderer = Renderer::new(&gpu, &scene, SIZE.0, SIZE.1, &needs).unwrap();
    let work = renderer.count_work(info, &params).unwrap();
    println!("{}", work.passes_column());
    let answered = work.diagnostics.iter().find(|(key, _)| key == BEYOND_FRAME_DIAGNOSTIC).map(|(_, v)| *v as u64).unwrap();
    let pixels = u64::from(SIZE.0 * SIZE.1);
    assert!(answered > pixels / 5, "{answered} pixels answered past the frame");
    let pass = work.passes.iter().find(|p| p.name == ssm_core::beyond_frame_label(info.name)).unwrap();
    assert_eq!(
        (pass.runs, pass.counted_invocations, pass.texel_reads, pass.read_bytes, pass.storage_bytes),
        (1, pixels, 2 * pixels + answered, 2 * 16 * pixels + 4 * answered, 4 * answered)
    );
}
