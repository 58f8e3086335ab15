//! The extremes matrix: every registered technique (a new crate joins by
//! registering) against scenes at the edges of what the techniques model.
//! Each must return finite visibility in [0, 1] (checked on readback) or a
//! typed error; never a panic, a hang or a NaN. Beyond that, each scene
//! asserts only what every correct technique must satisfy, whatever its
//! approximation: a light facing away lights nothing, an occluder behind the
//! light casts nothing, a point light has no penumbra, an unoccluded receiver
//! is lit.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3};
use ssm_core::Error;
use ssm_integration_tests::registry;
use ssm_scene::{Instance, Manifest, Mesh, RectLight, Role, Scene, SceneError, builtin, primitives};
use ssm_testing::{Rendered, at, gpu, pixel_of, render};

const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

/// What must hold for every technique on a scene.
#[derive(Clone, Copy, Debug)]
enum Expect {
    /// Finite and in [0, 1]; nothing more can be said for every technique.
    InRange,
    /// Every covered pixel is 0: the light faces away from everything.
    AllDark,
    /// Every covered pixel is (nearly) 1: nothing lies between the light and the receivers.
    AllLit,
    /// (Nearly) no penumbra: a point light casts none. A pixel strictly between 0 and 1 with both a
    /// lit and a dark pixel among its eight neighbours is an anti-aliased edge, not a penumbra.
    NoPenumbra,
    /// The surface seen at this world point is (nearly) in umbra: the exact visibility there is 0.
    ShadowedAt(Vec3),
}

fn from_manifest(name: &str, text: &str) -> Scene {
    let origin = PathBuf::from(format!("extreme:{name}"));
    Manifest::parse(text, &origin).unwrap().build(&origin, Path::new(".")).unwrap()
}

/// `parallel-square` with its light and occluder changed.
fn parallel_square_with(light: RectLight, occluder_height: f32) -> Scene {
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.lights = vec![light];
    let occluder = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.transform = Mat4::from_translation(Vec3::new(0.0, occluder_height, 0.0));
    scene
}

fn square_light(centre: Vec3, normal: Vec3, size: f32) -> RectLight {
    RectLight::try_facing(centre, normal, Vec3::X, Vec2::splat(size), 1.0).unwrap()
}

fn extreme_scenes() -> Vec<(&'static str, Scene, Expect)> {
    let down = -Vec3::Y;
    let mut scenes = vec![
        ("occluder touching the receiver", builtin("contact").unwrap().build(), Expect::InRange),
        // Atty et al., Eq. 3: the penumbra extent grows without bound as the occluder nears the light.
        // The light frame must keep it (it lies 1/12000 of the scene's size below the light), and it
        // hides the whole light from the receiver's centre: the exact visibility there is 0.
        (
            "occluder almost touching the light",
            parallel_square_with(square_light(Vec3::new(0.0, 4.0, 0.0), down, 1.0), 3.999),
            Expect::ShadowedAt(Vec3::ZERO),
        ),
        ("occluder in the light's plane", parallel_square_with(square_light(Vec3::new(0.0, 4.0, 0.0), down, 1.0), 4.0), Expect::InRange),
        ("point light", parallel_square_with(square_light(Vec3::new(0.0, 4.0, 0.0), down, 0.0), 2.0), Expect::NoPenumbra),
        (
            "light far larger than the occluder",
            parallel_square_with(square_light(Vec3::new(0.0, 4.0, 0.0), down, 50.0), 2.0),
            Expect::InRange,
        ),
        ("tiny light", parallel_square_with(square_light(Vec3::new(0.0, 4.0, 0.0), down, 1e-4), 2.0), Expect::InRange),
        (
            "grazing light",
            parallel_square_with(square_light(Vec3::new(-12.0, 0.25, 0.0), Vec3::new(1.0, -0.02, 0.0), 1.0), 2.0),
            Expect::InRange,
        ),
        (
            "light facing away from everything",
            parallel_square_with(square_light(Vec3::new(0.0, -1.0, 0.0), down, 1.0), 2.0),
            Expect::AllDark,
        ),
        ("occluder behind the light", parallel_square_with(square_light(Vec3::new(0.0, 4.0, 0.0), down, 1.0), 5.0), Expect::AllLit),
    ];

    // Far to the side, just below the light's plane: past the frame's widest angle (MAX_HALF_ANGLE_TANGENT), so outside every map.
    let mut scene = builtin("parallel-square").unwrap().build();
    let occluder = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.transform = Mat4::from_translation(Vec3::new(30.0, 3.99, 0.0));
    scenes.push(("occluder outside the light frustum", scene, Expect::InRange));

    scenes.push((
        "no occluder at all",
        from_manifest(
            "no-occluder",
            "[camera]\nposition = [0.0, 5.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n[[light]]\ncentre = [0.0, 4.0, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [1.0, 1.0]\n[[object]]\nprimitive = \"plane\"\nsize = [8.0, 8.0]\nrole = \"receiver\"\n",
        ),
        Expect::AllLit,
    ));

    // Degenerate occluders: collapsed triangles (a point, a line), a sliver, duplicate vertices.
    let mut scene = builtin("parallel-square").unwrap().build();
    let positions = vec![
        Vec3::ZERO,
        Vec3::ZERO,
        Vec3::ZERO,
        Vec3::new(-0.5, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(-0.5, 0.0, -1e-7),
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(0.5, 0.0, 1e-7),
    ];
    let degenerate = Mesh::with_generated_normals("degenerate", positions, (0..9).collect());
    scene.meshes.push(degenerate);
    scene.instances.push(Instance {
        name: "degenerate".into(),
        mesh: scene.meshes.len() - 1,
        transform: Mat4::from_translation(Vec3::new(1.0, 1.0, 1.0)),
        role: Role::Occluder,
    });
    scenes.push(("degenerate triangles", scene, Expect::InRange));

    // The same analytic scene at very small and very large scales: depth ranges of 1e-3 and 1e3.
    for (name, scale) in [("scene a thousandth the size", 1e-3f32), ("scene a thousand times the size", 1e3)] {
        let mut scene = builtin("parallel-square").unwrap().build();
        for instance in &mut scene.instances {
            instance.transform = Mat4::from_scale(Vec3::splat(scale)) * instance.transform;
        }
        let light = &mut scene.lights[0];
        light.centre *= scale;
        light.half_size *= scale;
        scene.camera.position *= scale;
        scene.camera.near *= scale;
        scene.camera.far *= scale;
        scenes.push((name, scene, Expect::InRange));
    }

    // The coarsest closed mesh the sphere generator makes (3 segments, 2 rings: a triangular bipyramid), resting on the ground.
    let mut scene = builtin("floating-sphere").unwrap().build();
    scene.meshes.push(primitives::sphere("bipyramid", 0.6, 3, 2));
    scene.instances.push(Instance {
        name: "coarse sphere".into(),
        mesh: scene.meshes.len() - 1,
        transform: Mat4::from_translation(Vec3::new(-1.5, 0.6, 0.5)),
        role: Role::Both,
    });
    scenes.push(("coarsest closed mesh", scene, Expect::InRange));

    // Three lights of different position, size and intensity, one of them a point light: every
    // light's visibility is checked on readback.
    let mut scene = builtin("sphere-cube").unwrap().build();
    let base = scene.lights[0];
    scene.lights = vec![
        base,
        RectLight::try_facing(base.centre + Vec3::new(3.0, 1.0, 0.0), Vec3::new(-0.5, -1.0, 0.0), Vec3::X, Vec2::new(3.0, 0.5), 0.5)
            .unwrap(),
        RectLight::try_facing(base.centre + Vec3::new(-2.0, 0.0, 2.0), Vec3::new(0.3, -1.0, -0.4), Vec3::X, Vec2::ZERO, 2.0).unwrap(),
    ];
    scenes.push(("three lights", scene, Expect::InRange));
    scenes
}

fn check(technique: &str, (scene_name, scene): (&str, &Scene), expect: Expect, rendered: &Rendered) {
    let covered = rendered.covered_visibility();
    assert!(!covered.is_empty(), "{scene_name}: the camera sees nothing");
    let share = |keep: &dyn Fn(f32) -> bool| covered.iter().filter(|v| keep(**v)).count() as f32 / covered.len() as f32;
    match expect {
        Expect::InRange => {}
        Expect::AllDark => assert!(covered.iter().all(|v| *v == 0.0), "{technique} / {scene_name}: lit pixels behind the light"),
        Expect::AllLit => {
            let dark = share(&|v| v < 0.95);
            assert!(dark < 0.01, "{technique} / {scene_name}: {:.1}% of pixels read below 0.95", dark * 100.0);
        }
        Expect::NoPenumbra => {
            let (width, height) = (WIDTH as i32, HEIGHT as i32);
            let value = |x: i32, y: i32| rendered.visibility[(y.clamp(0, height - 1) * width + x.clamp(0, width - 1)) as usize];
            let coverage = rendered.coverage();
            let mut penumbra = 0;
            for y in 0..height {
                for x in 0..width {
                    let v = value(x, y);
                    if !coverage[(y * width + x) as usize] || v <= 0.02 || v >= 0.98 {
                        continue;
                    }
                    let neighbours: Vec<f32> =
                        (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))).map(|(dx, dy)| value(x + dx, y + dy)).collect();
                    let edge = neighbours.iter().any(|n| *n >= 0.98) && neighbours.iter().any(|n| *n <= 0.02);
                    penumbra += usize::from(!edge);
                }
            }
            let share = penumbra as f32 / covered.len() as f32;
            assert!(share < 0.01, "{technique} / {scene_name}: {:.1}% of pixels in a penumbra", share * 100.0);
        }
        Expect::ShadowedAt(world) => {
            let value = at(rendered, pixel_of(scene, WIDTH, HEIGHT, world));
            assert!(value < 0.1, "{technique} / {scene_name}: visibility {value} at {world}, where the exact value is 0");
        }
    }
}

#[test]
fn every_technique_survives_every_extreme() {
    let gpu = gpu();
    let registry = registry();
    let mut failures = Vec::new();
    let mut runs = 0;
    for (scene_name, scene, expect) in extreme_scenes() {
        for info in registry.iter() {
            match render(&gpu, &scene, info, &[], WIDTH, HEIGHT) {
                Ok(rendered) => {
                    runs += 1;
                    if let Err(panic) =
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| check(info.name, (scene_name, &scene), expect, &rendered)))
                    {
                        failures.push(
                            panic
                                .downcast_ref::<String>()
                                .cloned()
                                .unwrap_or_else(|| format!("{} / {scene_name}: check failed", info.name)),
                        );
                    }
                }
                // A clear refusal is allowed; a wrong or broken output is not.
                Err(Error::MissingFeatures { .. } | Error::LimitTooLow { .. } | Error::Unrepresentable { .. }) => {}
                Err(e) => failures.push(format!("{} / {scene_name}: {e}", info.name)),
            }
        }
    }
    assert!(runs >= 2 * 15, "only {runs} technique/scene pairs ran");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Non-finite geometry and lights are refused with a typed error before any rendering, by every technique.
#[test]
fn non_finite_geometry_is_a_typed_error_before_any_rendering() {
    let gpu = gpu();
    for info in registry().iter() {
        let mut scene = builtin("parallel-square").unwrap().build();
        scene.meshes[1].positions[2].y = f32::NAN;
        match render(&gpu, &scene, info, &[], WIDTH, HEIGHT) {
            Err(Error::Scene(SceneError::NonFiniteVertex { vertex: 2, .. })) => {}
            Err(other) => panic!("{}: expected a non-finite vertex error, got: {other}", info.name),
            Ok(_) => panic!("{}: a NaN vertex was rendered", info.name),
        }
        let mut scene = builtin("parallel-square").unwrap().build();
        scene.instances[1].transform.w_axis.x = f32::INFINITY;
        let transform = render(&gpu, &scene, info, &[], WIDTH, HEIGHT);
        assert!(matches!(transform, Err(Error::Scene(SceneError::InvalidTransform { .. }))), "{}", info.name);
        let mut scene = builtin("parallel-square").unwrap().build();
        scene.lights[0].half_size.x = f32::NAN;
        let light = render(&gpu, &scene, info, &[], WIDTH, HEIGHT);
        assert!(matches!(light, Err(Error::Scene(SceneError::InvalidLight { .. }))), "{}", info.name);
    }
}
