//! The extremes matrix: every registered technique (a new crate joins by registering) against
//! scenes at the edges of what the techniques model, each compared with the ground truth.
//!
//! For every technique and every scene:
//! - it renders, or refuses with the typed refusal this file expects of it, by name and reason
//!   ([`EXPECTED_REFUSALS`]); the techniques of `MUST_RUN_ON_LAVAPIPE` (tests/support.rs) must run everywhere
//!   else, and any other error fails. Visibility that is not finite or not in [0, 1] comes back from the
//!   readback as [`Error::InvalidOutput`], which fails like any other error;
//! - its headline error against the ground truth (`ErrorMetrics::mae`: over the pixels that the
//!   truth or the technique shadows, so that a shadow drawn where there is none counts), is at
//!   most [`COMMON_BOUND`] for every light of the scene, or the looser bound its registration
//!   declares for that scene ([`ssm_core::KnownLimit`], with the paper's reason). A declaration
//!   that names no scene here, or that the technique no longer needs, fails too;
//! - on every scene with a penumbra, every soft-shadow technique beats hard shadows from a map of
//!   its own size (a lower error, beyond the ground truth's noise), unless it declares a limit
//!   there; where that penumbra is narrower than a texel of the map everywhere, it must be no
//!   worse than them (a tie at most: the map holds no penumbra); and hard shadows fail the
//!   scenes whose penumbra they cannot draw ([`HARD_MUST_FAIL`]), so that the bound tells a soft
//!   technique from none;
//! - what every correct technique must satisfy there holds, whatever its approximation ([`Expect`]):
//!   a light facing away lights nothing, a point light casts no penumbra, no light leaves a
//!   sealed box.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3};
use ssm_core::metrics::{compare_with_noise, is_tie};
use ssm_core::reference::{GroundTruth, Sampling, surface_points};
use ssm_core::{Error, TechniqueInfo, TechniqueKind};
use ssm_integration_tests::{missing_must_run, registry, render_or_refusal};
use ssm_scene::{Instance, Manifest, Mesh, RectLight, Role, Scene, SceneError, builtin, primitives};
use ssm_testing::{Rendered, at, gpu, pixel_of, render};

const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

/// Rays per axis of each of the ground truth's two sets (refined where the visibility varies): its
/// own error is reported beside every technique's and decides ties with hard shadows.
const REFERENCE_SAMPLES: u32 = 8;

/// The mean absolute error against the ground truth, over the pixels either shadows, that every
/// technique must meet on every scene here unless its registration declares a looser one (hard
/// shadows need not where there is a penumbra: they are the baseline there). A shadow drawn at
/// 0.6 over the lit part of a floor exceeds it on every scene (seen: 0.22 to 0.40), and so do hard
/// shadows under a large light (0.28) or a tube (0.25 to 0.34).
const COMMON_BOUND: f32 = 0.1;

/// The hard-shadow techniques: the baseline every other technique must beat where there is a
/// penumbra (the plug-in test's `plugin-hard` is one too). Every other registered real-time
/// technique is a soft-shadow technique.
const HARD_SHADOW_TECHNIQUES: &[&str] = &["hard", "plugin-hard"];

/// The scenes whose penumbra covers so much of the shadow that a hard shadow exceeds
/// [`COMMON_BOUND`]: each hard-shadow technique must fail them, which shows that the bound tells a
/// soft technique from none.
const HARD_MUST_FAIL: &[&str] =
    &["light far larger than the occluder", "tube light along the occluder's side", "tube light across the scene at 30 degrees"];

/// A scene has a penumbra to compare soft techniques on when at least this share of its covered
/// pixels is in a visible penumbra (between 0.02 and 0.98) in the ground truth.
const PENUMBRA_SHARE: f32 = 0.01;

/// The interiors of the matrix (a closed mesh holds the light), where pvsm must do no worse than
/// pcss.
const INTERIORS: &[&str] = &["room lit from a wall over a table", "corridor lit from its ceiling", "light inside a closed room"];

/// The techniques that must beat hard shadows over the truth's umbra and penumbra in every interior
/// (issue #47), whatever their false shadows beside it.
const INTERIOR_SOFT: &[&str] = &["pcss", "sssm", "pvsm"];

/// (technique, scene, what is wrong): failures this matrix finds that the workspace has not fixed
/// yet. Each is reported when the test runs and must still fail: one that passes fails the test
/// until its line is removed. They are bugs or missing features of the implementation, not limits
/// of the papers (those are `KnownLimit`s, declared by the technique with the paper's reason).
const OPEN_FAILURES: &[(&str, &str, &str)] = &[];

/// (technique, scene, what its refusal must say): the refusals this matrix expects, each asserted
/// by its error's variant and a phrase of its reason. A technique that stops refusing a scene
/// listed here fails the test, so the list stays true.
const EXPECTED_REFUSALS: &[(&str, &str, Refusal)] = &[
    // The light frame must widen to nearly 180° to hold an occluder 1/12000 of the scene below the
    // light, and Atty's soft shadow map is one texture over that frame (Sec. 3.1): the receivers
    // would cover a texel or two of it, so it refuses rather than return a one-texel shadow.
    ("atty", "occluder almost touching the light", Refusal::Unrepresentable("receivers cover only")),
];

/// A refusal's variant and a phrase its message must contain.
#[derive(Clone, Copy, Debug)]
#[allow(dead_code)] // Not every variant is expected today; each says what an entry may expect.
enum Refusal {
    /// [`Error::Unrepresentable`] whose reason contains this.
    Unrepresentable(&'static str),
    /// [`Error::LimitTooLow`] whose `what` contains this.
    LimitTooLow(&'static str),
}

/// Ground points outside "light in an enclosure of open quads" (and its variant with a gap, away
/// from the gap): one inside the frame, four past its widest angle.
const OUTSIDE_THE_ENCLOSURE: [Vec3; 5] = [
    Vec3::new(1.8, 0.0, 1.8),
    Vec3::new(5.0, 0.0, 0.0),
    Vec3::new(-4.0, 0.0, 3.0),
    Vec3::new(0.0, 0.0, 5.0),
    // On a diagonal, where a hemicube's side faces meet.
    Vec3::new(3.5, 0.0, 3.5),
];

/// The manifest of a light inside five open quads on a wide ground: a ceiling above the light and
/// four walls 0.8 high around it, the wall at z = 1 `near_wall_height` high, centred
/// `near_wall_centre` above the ground (its bottom off the ground when shorter).
fn open_enclosure(near_wall_height: &str, near_wall_centre: &str) -> String {
    format!(
        "[camera]\nposition = [0.0, 7.0, 9.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[light]]\ncentre = [0.0, 0.3, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.4, 0.4]\n\
         [[object]]\nprimitive = \"plane\"\nsize = [24.0, 24.0]\nrole = \"receiver\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [2.0, 2.0]\ntranslate = [0.0, 0.8, 0.0]\nrole = \"occluder\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [2.0, {near_wall_height}]\nrotate_degrees = [90.0, 0.0, 0.0]\ntranslate = [0.0, {near_wall_centre}, 1.0]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [2.0, 0.8]\nrotate_degrees = [90.0, 0.0, 0.0]\ntranslate = [0.0, 0.4, -1.0]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [0.8, 2.0]\nrotate_degrees = [0.0, 0.0, 90.0]\ntranslate = [1.0, 0.4, 0.0]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [0.8, 2.0]\nrotate_degrees = [0.0, 0.0, 90.0]\ntranslate = [-1.0, 0.4, 0.0]\nrole = \"both\"\n"
    )
}

/// What must hold for every technique on a scene, beyond the error bound.
#[derive(Clone, Copy, Debug)]
enum Expect {
    /// Only the error bound.
    Bound,
    /// Every covered pixel is exactly 0: the light faces away from everything.
    AllDark,
    /// At most 1% of covered pixels read above 0.1: the light is sealed away from everything seen.
    NoLightEscapes,
    /// Every covered pixel is (nearly) 1: nothing lies between the light and the receivers.
    AllLit,
    /// (Nearly) no penumbra: a point light casts none. A pixel strictly between 0 and 1 with both a
    /// lit and a dark pixel among its eight neighbours is an anti-aliased edge, not a penumbra.
    NoPenumbra,
    /// The surfaces seen at these world points are (nearly) in umbra: the exact visibility there is 0.
    ShadowedAt(&'static [Vec3]),
}

/// One scene of the matrix.
struct Case {
    name: &'static str,
    scene: Scene,
    expect: Expect,
    /// The framework answers this scene for every technique alike (a light sealed in a closed
    /// mesh is culled: `LightFrame::sealed`): it tests the framework, not the techniques, and is
    /// reported as such.
    framework_rule: Option<&'static str>,
}

fn case(name: &'static str, scene: Scene, expect: Expect) -> Case {
    Case { name, scene, expect, framework_rule: None }
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

/// The scenes at the edges of what the techniques model.
fn extreme_cases() -> Vec<Case> {
    let down = -Vec3::Y;
    let above = Vec3::new(0.0, 4.0, 0.0);
    let mut cases = vec![
        case("occluder touching the receiver", builtin("contact").unwrap().build(), Expect::Bound),
        // Atty et al., Eq. 3: the penumbra extent grows without bound as the occluder nears the light.
        // The light frame must keep it (it lies 1/12000 of the scene's size below the light), and it
        // hides the whole light from the receiver's centre: the exact visibility there is 0.
        case(
            "occluder almost touching the light",
            parallel_square_with(square_light(above, down, 1.0), 3.999),
            Expect::ShadowedAt(&[Vec3::ZERO]),
        ),
        case("occluder in the light's plane", parallel_square_with(square_light(above, down, 1.0), 4.0), Expect::Bound),
        case("point light", parallel_square_with(square_light(above, down, 0.0), 2.0), Expect::NoPenumbra),
        case("light far larger than the occluder", parallel_square_with(square_light(above, down, 50.0), 2.0), Expect::Bound),
        case("tiny light", parallel_square_with(square_light(above, down, 1e-4), 2.0), Expect::NoPenumbra),
        // Tubes 1000 times longer than wide: a penumbra as wide as the tube along it, none across
        // it. Every filter, search region and projection must follow both of the light's sides.
        case(
            "tube light along the occluder's side",
            parallel_square_with(RectLight::try_facing(above, down, Vec3::X, Vec2::new(4.0, 0.004), 1.0).unwrap(), 2.0),
            Expect::Bound,
        ),
        case(
            "tube light across the scene at 30 degrees",
            parallel_square_with(RectLight::try_facing(above, down, Vec3::new(0.866, 0.0, 0.5), Vec2::new(4.0, 0.004), 1.0).unwrap(), 2.0),
            Expect::Bound,
        ),
        case(
            "grazing light",
            parallel_square_with(square_light(Vec3::new(-12.0, 0.25, 0.0), Vec3::new(1.0, -0.02, 0.0), 1.0), 2.0),
            Expect::Bound,
        ),
        case(
            "light facing away from everything",
            parallel_square_with(square_light(Vec3::new(0.0, -1.0, 0.0), down, 1.0), 2.0),
            Expect::AllDark,
        ),
        case("occluder behind the light", parallel_square_with(square_light(above, down, 1.0), 5.0), Expect::AllLit),
    ];

    // Far to the side, just below the light's plane: past the frame's widest angle (MAX_HALF_ANGLE_TANGENT), so outside every map.
    let mut scene = builtin("parallel-square").unwrap().build();
    let occluder = scene.instances.iter_mut().find(|i| i.role == Role::Occluder).unwrap();
    occluder.transform = Mat4::from_translation(Vec3::new(30.0, 3.99, 0.0));
    cases.push(case("occluder outside the light frustum", scene, Expect::AllLit));

    cases.push(case(
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
    cases.push(case("degenerate triangles", scene, Expect::Bound));

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
        cases.push(case(name, scene, Expect::ShadowedAt(&[Vec3::ZERO])));
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
    cases.push(case("coarsest closed mesh", scene, Expect::Bound));

    // Three lights of different position, size and intensity, one of them a point light: every
    // light's visibility is compared with the ground truth.
    let mut scene = builtin("sphere-cube").unwrap().build();
    let base = scene.lights[0];
    scene.lights = vec![
        base,
        RectLight::try_facing(base.centre + Vec3::new(3.0, 1.0, 0.0), Vec3::new(-0.5, -1.0, 0.0), Vec3::X, Vec2::new(3.0, 0.5), 0.5)
            .unwrap(),
        RectLight::try_facing(base.centre + Vec3::new(-2.0, 0.0, 2.0), Vec3::new(0.3, -1.0, -0.4), Vec3::X, Vec2::ZERO, 2.0).unwrap(),
    ];
    cases.push(case("three lights", scene, Expect::Bound));

    // Interiors: a closed room (its walls, floor and ceiling one box, seen from inside) with the
    // light under its ceiling and a block of furniture on its floor.
    cases.push(case(
        "light inside a closed room",
        from_manifest(
            "room",
            "[camera]\nposition = [-2.5, 1.6, 2.5]\ntarget = [0.5, 0.3, -0.5]\n\
             [[light]]\ncentre = [0.3, 2.7, -0.2]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.8, 0.6]\n\
             [[object]]\nprimitive = \"box\"\nsize = [8.0, 3.0, 8.0]\ntranslate = [0.0, 1.5, 0.0]\nrole = \"both\"\n\
             [[object]]\nprimitive = \"box\"\nsize = [1.0, 0.8, 1.0]\ntranslate = [0.5, 0.4, -0.5]\nrole = \"both\"\n",
        ),
        Expect::Bound,
    ));
    // Interiors, the camera inside: a closed room lit from a wall over a table (the light's normal
    // tilted down, so the floor and the wall beside the light lie near 90 degrees off it), and a
    // closed corridor lit from its ceiling with a block on its floor.
    cases.push(case(
        "room lit from a wall over a table",
        from_manifest(
            "wall-lit-room",
            "[camera]\nposition = [2.5, 1.7, 2.5]\ntarget = [-1.0, 0.5, -1.0]\n\
             [[light]]\ncentre = [-3.9, 2.0, 0.0]\nnormal = [1.0, -0.3, 0.0]\nsize = [0.6, 0.6]\n\
             [[object]]\nprimitive = \"box\"\nsize = [8.0, 3.0, 8.0]\ntranslate = [0.0, 1.5, 0.0]\nrole = \"both\"\n\
             [[object]]\nprimitive = \"box\"\nsize = [1.6, 0.08, 1.0]\ntranslate = [-1.2, 0.8, -0.4]\nrole = \"both\"\n\
             [[object]]\nprimitive = \"box\"\nsize = [0.1, 0.76, 0.1]\ntranslate = [-1.9, 0.38, -0.8]\nrole = \"both\"\n\
             [[object]]\nprimitive = \"box\"\nsize = [0.1, 0.76, 0.1]\ntranslate = [-0.5, 0.38, 0.0]\nrole = \"both\"\n\
             [[object]]\nprimitive = \"sphere\"\nsize = [0.4]\ntranslate = [0.5, 0.4, -1.5]\nrole = \"both\"\n",
        ),
        Expect::Bound,
    ));
    cases.push(case(
        "corridor lit from its ceiling",
        from_manifest(
            "corridor",
            "[camera]\nposition = [0.0, 1.6, 4.5]\ntarget = [0.0, 0.6, -3.0]\n\
             [[light]]\ncentre = [0.0, 2.45, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.5, 1.2]\n\
             [[object]]\nprimitive = \"box\"\nsize = [2.0, 2.5, 10.0]\ntranslate = [0.0, 1.25, 0.0]\nrole = \"both\"\n\
             [[object]]\nprimitive = \"box\"\nsize = [0.6, 0.9, 0.6]\ntranslate = [0.3, 0.45, -1.0]\nrole = \"both\"\n\
             [[object]]\nprimitive = \"sphere\"\nsize = [0.3]\ntranslate = [-0.5, 0.3, 1.2]\nrole = \"both\"\n",
        ),
        Expect::Bound,
    ));
    // A light sealed inside a closed box that rests on the ground, the camera outside: the ground
    // outside and the box's walls see none of it, also where the ground runs to the horizon, past
    // the widest view a light frame takes (MAX_HALF_ANGLE_TANGENT).
    cases.push(Case {
        framework_rule: Some("a light sealed in a closed mesh is culled for every technique (LightFrame::sealed)"),
        ..case(
            "light sealed inside a box",
            from_manifest(
                "sealed",
                "[camera]\nposition = [0.0, 3.0, 9.0]\ntarget = [0.0, 0.0, 0.0]\n\
             [[light]]\ncentre = [0.0, 0.8, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.5, 0.5]\n\
             [[object]]\nprimitive = \"box\"\nsize = [2.0, 1.0, 2.0]\ntranslate = [0.0, 0.5, 0.0]\nrole = \"both\"\n\
             [[object]]\nprimitive = \"plane\"\nsize = [80.0, 80.0]\nrole = \"receiver\"\n",
            ),
            Expect::NoLightEscapes,
        )
    });
    // The same light enclosed by five separate quads on the ground (open surfaces, so no closed
    // mesh seals it and each technique's own maps must keep the light in): the ground outside
    // reads 0; the walls' outer sides, sheets lit from either side, read lit.
    let wall = |size: [f32; 2], rotate: [f32; 3], translate: [f32; 3]| {
        format!(
            "[[object]]\nprimitive = \"plane\"\nsize = {size:?}\nrotate_degrees = {rotate:?}\ntranslate = {translate:?}\nrole = \"both\"\n"
        )
    };
    let walls = [
        wall([2.0, 2.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        wall([2.0, 1.0], [90.0, 0.0, 0.0], [0.0, 0.5, 1.0]),
        wall([2.0, 1.0], [90.0, 0.0, 0.0], [0.0, 0.5, -1.0]),
        wall([1.0, 2.0], [0.0, 0.0, 90.0], [1.0, 0.5, 0.0]),
        wall([1.0, 2.0], [0.0, 0.0, 90.0], [-1.0, 0.5, 0.0]),
    ]
    .concat();
    cases.push(case(
        "light inside a box of separate walls",
        from_manifest(
            "walls",
            &format!(
                "[camera]\nposition = [1.0, 4.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n\
                 [[light]]\ncentre = [0.1, 0.8, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.5, 0.5]\n\
                 [[object]]\nprimitive = \"plane\"\nsize = [10.0, 10.0]\nrole = \"receiver\"\n{walls}"
            ),
        ),
        Expect::Bound,
    ));
    // A light a thousandth of the floor's size above it, facing it, with a block beside it: the
    // floor sees the light at grazing angles everywhere but under it.
    cases.push(case(
        "light resting on the receiver",
        from_manifest(
            "resting",
            "[camera]\nposition = [0.0, 4.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n\
             [[light]]\ncentre = [0.0, 0.01, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [1.0, 1.0]\n\
             [[object]]\nprimitive = \"plane\"\nsize = [10.0, 10.0]\nrole = \"receiver\"\n\
             [[object]]\nprimitive = \"box\"\nsize = [0.4, 0.4, 0.4]\ntranslate = [1.5, 0.2, 0.0]\nrole = \"both\"\n",
        ),
        Expect::Bound,
    ));
    // Thin bars under a light a hundredth of their spacing: hard shadows a few pixels wide.
    let bars: String = (0..9)
        .map(|k| {
            format!(
                "[[object]]\nprimitive = \"box\"\nsize = [5.0, 0.03, 0.08]\ntranslate = [0.0, 1.0, {}]\nrole = \"occluder\"\n",
                -2.0 + 0.5 * k as f32
            )
        })
        .collect();
    cases.push(case(
        "thin bars under a near-point light",
        from_manifest(
            "bars",
            &format!(
                "[camera]\nposition = [0.0, 4.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\n\
                 [[light]]\ncentre = [0.3, 3.0, 0.2]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.005, 0.005]\n\
                 [[object]]\nprimitive = \"plane\"\nsize = [8.0, 8.0]\nrole = \"receiver\"\n{bars}"
            ),
        ),
        Expect::Bound,
    ));
    // A wall lit from far to its side, the light's normal 8.5 degrees off the wall's plane, a block
    // on the wall casting a long shadow along it.
    cases.push(case(
        "wall lit at grazing angles",
        from_manifest(
            "grazing-wall",
            "[camera]\nposition = [4.0, 2.0, 6.0]\ntarget = [0.0, 1.5, 0.0]\n\
             [[light]]\ncentre = [-6.0, 1.5, 1.0]\nnormal = [1.0, 0.0, -0.15]\nsize = [0.6, 0.6]\n\
             [[object]]\nprimitive = \"plane\"\nsize = [8.0, 3.0]\nrotate_degrees = [90.0, 0.0, 0.0]\ntranslate = [0.0, 1.5, 0.0]\nrole = \"receiver\"\n\
             [[object]]\nprimitive = \"box\"\nsize = [0.3, 0.3, 0.5]\ntranslate = [-1.0, 1.5, 0.25]\nrole = \"both\"\n",
        ),
        Expect::Bound,
    ));
    // A light inside five open quads (four walls down to the ground and a ceiling behind the
    // light) on a ground that reaches 84 degrees off the light's normal 3 units out: no closed mesh,
    // so no framework cull; outside, the ground is umbra, within the frame and past it.
    cases.push(case(
        "light in an enclosure of open quads",
        from_manifest("open-enclosure", &open_enclosure("0.8", "0.4")),
        Expect::ShadowedAt(&OUTSIDE_THE_ENCLOSURE),
    ));
    // The same enclosure with a gap under one wall (z = 1, raised 0.1 off the ground): light leaves
    // through it onto the ground just outside that wall (to z = 1.6), and everywhere else outside
    // stays umbra, within the frame and past it.
    cases.push(case(
        "light in an enclosure of open quads with a gap",
        from_manifest("open-enclosure-gap", &open_enclosure("0.7", "0.45")),
        Expect::ShadowedAt(&OUTSIDE_THE_ENCLOSURE),
    ));
    // An occluder quad lying in the receiver's plane (it shadows nothing), and a block above.
    cases.push(case(
        "coplanar occluder and receiver",
        from_manifest(
            "coplanar",
            "[camera]\nposition = [0.0, 4.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n\
             [[light]]\ncentre = [0.5, 3.0, 0.0]\nnormal = [-0.2, -1.0, 0.0]\nsize = [1.0, 1.0]\n\
             [[object]]\nprimitive = \"plane\"\nsize = [8.0, 8.0]\nrole = \"receiver\"\n\
             [[object]]\nprimitive = \"plane\"\nsize = [2.0, 2.0]\nrole = \"occluder\"\n\
             [[object]]\nprimitive = \"box\"\nsize = [0.5, 0.5, 0.5]\ntranslate = [-1.5, 1.0, 1.0]\nrole = \"both\"\n",
        ),
        Expect::Bound,
    ));
    cases
}

/// Checks `expect` on light 0's image; panics naming the technique and scene.
fn check_expectation(technique: &str, (case_name, scene): (&str, &Scene), expect: Expect, rendered: &Rendered) {
    let covered = rendered.covered_visibility();
    assert!(!covered.is_empty(), "{case_name}: the camera sees nothing");
    let share = |keep: &dyn Fn(f32) -> bool| covered.iter().filter(|v| keep(**v)).count() as f32 / covered.len() as f32;
    match expect {
        Expect::Bound => {}
        Expect::AllDark => assert!(covered.iter().all(|v| *v == 0.0), "{technique} / {case_name}: lit pixels behind the light"),
        Expect::NoLightEscapes => {
            let lit = share(&|v| v > 0.1);
            assert!(lit <= 0.01, "{technique} / {case_name}: {:.1}% of pixels read above 0.1", lit * 100.0);
        }
        Expect::AllLit => {
            let dark = share(&|v| v < 0.95);
            assert!(dark < 0.01, "{technique} / {case_name}: {:.1}% of pixels read below 0.95", dark * 100.0);
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
            assert!(share < 0.01, "{technique} / {case_name}: {:.1}% of pixels in a penumbra", share * 100.0);
        }
        Expect::ShadowedAt(points) => {
            for world in points {
                let value = at(rendered, pixel_of(scene, WIDTH, HEIGHT, *world));
                assert!(value < 0.1, "{technique} / {case_name}: visibility {value} at {world}, where the exact value is 0");
            }
        }
    }
}

/// The bound `info` must meet on `case_name`: its declared limit there, else the common one.
fn bound_of(info: &TechniqueInfo, case_name: &str) -> (f32, Option<&'static str>) {
    info.limits.iter().find(|limit| limit.case == case_name).map_or((COMMON_BOUND, None), |limit| (limit.mean_error, Some(limit.reason)))
}

/// A refusal `error` of `technique` on `case_name` is expected, by variant and reason.
fn refusal_expected(technique: &str, case_name: &str, error: &Error) -> bool {
    EXPECTED_REFUSALS.iter().any(|(name, scene, refusal)| {
        *name == technique
            && *scene == case_name
            && match (refusal, error) {
                (Refusal::Unrepresentable(phrase), Error::Unrepresentable { reason, .. }) => reason.contains(phrase),
                (Refusal::LimitTooLow(phrase), Error::LimitTooLow { what, .. }) => what.contains(phrase),
                _ => false,
            }
    })
}

/// Whether `case`, with this share of its pixels in penumbra, asks every soft technique to beat hard
/// shadows: it has a penumbra, and no framework rule answers it for every technique alike.
fn beats_hard_needed(case: &Case, penumbra_share: f32) -> bool {
    penumbra_share >= PENUMBRA_SHARE && case.framework_rule.is_none()
}

/// The side of the square map `info` looks its visible points up in, at its defaults (the first
/// of [`LOOKUP_MAP_SIZES`] it has), or `None` for a technique with none (its resolution is its
/// own method's: pvsm's predicted virtual maps, wedges' volumes).
fn shadow_map_size(info: &TechniqueInfo) -> Option<u32> {
    LOOKUP_MAP_SIZES
        .iter()
        .find(|name| info.params.iter().any(|spec| spec.name == **name))
        .and_then(|name| info.default_params().int(name).ok())
        .and_then(|size| u32::try_from(size).ok())
}

/// How a report names the hard-shadow baseline a technique was compared with.
fn map_size_text(size: Option<u32>) -> String {
    size.map_or_else(|| "its default map".to_owned(), |size| format!("{size}² map"))
}

/// The parameter that sets a shadow-map technique's map side.
const SHADOW_MAP_SIZE: &str = "shadow_map_size";

/// The parameters that set the side of the square map a technique's visible points are looked up
/// in, which its hard-shadow baseline is rendered at: a shadow map's, or the soft shadow map of
/// Atty et al. (`ssm_size`: the receivers' visibility, projected onto the scene like a shadow map,
/// Sec. 3.1 and 3.4; its occluder map is the occluders' discretisation, not where receivers read).
const LOOKUP_MAP_SIZES: &[&str] = &[SHADOW_MAP_SIZE, "ssm_size"];

/// An error against the ground truth and the truth's own error over the same pixels.
type ErrorWithNoise = (f64, Option<f64>);

/// A technique's worst errors over a scene's lights: the headline (where either shadows) and over
/// the truth's umbra and penumbra, each with the truth's noise there.
#[derive(Clone, Copy, Debug)]
struct Worst {
    headline: ErrorWithNoise,
    shadowed: ErrorWithNoise,
}

/// Hard shadows on one case, at the map sizes the soft techniques render: each soft technique is
/// compared with hard shadows from a map of its own size (like for like: the map's resolution is
/// not a soft technique's contribution), rendered once per size.
#[derive(Default)]
struct HardBaselines {
    /// Keyed by the map side; `None` is hard's own default.
    errors: Vec<(Option<u32>, Worst)>,
}

impl HardBaselines {
    fn insert(&mut self, size: Option<u32>, worst: Worst) {
        self.errors.push((size, worst));
    }

    /// Hard shadows' (headline, shadowed) errors from a map of side `size` (`None`: hard's default).
    fn at(
        &mut self,
        gpu: &ssm_core::GpuContext,
        case: &Case,
        truth: &Truth,
        size: Option<u32>,
    ) -> Result<(ErrorWithNoise, ErrorWithNoise), String> {
        let hard = registry().iter().find(|info| info.name == HARD_SHADOW_TECHNIQUES[0]).ok_or("hard shadows are not registered")?;
        // Hard's default size is its default run.
        let size = size.filter(|size| shadow_map_size(hard) != Some(*size));
        if let Some((_, worst)) = self.errors.iter().find(|(key, _)| *key == size) {
            return Ok((worst.headline, worst.shadowed));
        }
        let Some(side) = size else {
            return Err("hard shadows did not run, so no technique can be compared with them".to_owned());
        };
        let side_text = side.to_string();
        let rendered = render(gpu, &case.scene, hard, &[(SHADOW_MAP_SIZE, &side_text)], WIDTH, HEIGHT)
            .map_err(|e| format!("hard shadows at {side}² did not render: {e}"))?;
        let worst = truth.worst(&rendered, hard.name)?;
        self.insert(size, worst);
        Ok((worst.headline, worst.shadowed))
    }

    /// Hard shadows' headline error averaged over the texel grid's phase: from maps of side
    /// `size` (`None`: hard's default) and [`GRID_PHASE_SIDES`] either side of it. Where the
    /// penumbra is under a texel, which pixels a hard shadow gets wrong is decided by where the
    /// grid's texel edges fall against the scene's: on the axis-aligned thin bars, whole rows of
    /// pixels flip together, and hard's error from sides 1000 to 1060 takes the values 0.0212,
    /// 0.0571, 0.0994 and 0.1353 (1024²: 0.0212). One side is one draw of that phase.
    fn phase_mean(&mut self, gpu: &ssm_core::GpuContext, case: &Case, truth: &Truth, size: Option<u32>) -> Result<ErrorWithNoise, String> {
        let hard = registry().iter().find(|info| info.name == HARD_SHADOW_TECHNIQUES[0]).ok_or("hard shadows are not registered")?;
        let centre = size.or_else(|| shadow_map_size(hard)).ok_or("hard shadows have no map side")?;
        let (mut error, mut noise, mut count) = (0.0, None::<f64>, 0.0);
        for offset in GRID_PHASE_SIDES {
            let side = centre.saturating_add_signed(offset);
            let ((headline, headline_noise), _) = self.at(gpu, case, truth, Some(side))?;
            error += headline;
            noise = headline_noise.map(|n| noise.unwrap_or(0.0) + n);
            count += 1.0;
        }
        Ok((error / count, noise.map(|n| n / count)))
    }
}

/// Map sides, relative to a baseline's, whose hard shadows average over the texel grid's phase at
/// the scene's edges (a change of 3 texels in 1024 moves a texel edge 500 texels from the frame's
/// centre by about 1.5 texels, a new phase).
const GRID_PHASE_SIDES: [i32; 9] = [-12, -9, -6, -3, 0, 3, 6, 9, 12];

/// The ground truth of a scene's view: each light's visibility and noise, and the covered pixels.
struct Truth {
    images: Vec<(Vec<f32>, Vec<f32>)>,
    covered: Vec<bool>,
    /// Each light's frame, as every shadow-map technique fits it.
    frames: Vec<ssm_core::LightFrame>,
}

impl Truth {
    fn of(gpu: &ssm_core::GpuContext, scene: &Scene) -> Self {
        let needs = ssm_core::Requirements { gbuffer: true, ..ssm_core::Requirements::NONE };
        let renderer = ssm_core::Renderer::new(gpu, scene, WIDTH, HEIGHT, &needs).unwrap();
        let positions = renderer.read_positions().unwrap();
        let points = surface_points(&positions, &renderer.read_normals().unwrap(), &renderer.scene.camera, false);
        let tracer = GroundTruth::new(scene);
        let sampling = Sampling { samples_per_axis: REFERENCE_SAMPLES, ..Sampling::DEFAULT };
        let images = scene
            .lights
            .iter()
            .map(|light| {
                let image = tracer.trace(light, &points, sampling, 1);
                (image.visibility, image.noise)
            })
            .collect();
        Self { images, covered: positions.iter().map(|p| p[3] > 0.5).collect(), frames: renderer.scene.light_frames.clone() }
    }

    /// The widest penumbra any occluder of the scene can cast, over the lights, in texels of a
    /// `map_size`² map over the light's frame: the light seen through the frame's nearest depth
    /// from its farthest, projected onto the map (PCSS's filter at its widest, Fernando 2005).
    fn widest_penumbra_texels(&self, map_size: u32) -> f32 {
        self.frames
            .iter()
            .map(|frame| {
                let through = (1.0 / frame.near.max(f32::MIN_POSITIVE) - 1.0 / frame.far).max(0.0);
                (2.0 * frame.light.half_size * through / frame.tan_half * map_size as f32).max_element()
            })
            .fold(0.0, f32::max)
    }

    /// The largest headline error over the scene's lights of `technique`'s `rendered` images, with
    /// the truth's noise there; and the largest over the truth's umbra and penumbra alone.
    fn worst(&self, rendered: &Rendered, technique: &str) -> Result<Worst, String> {
        let mut worst = Worst { headline: (0.0, None), shadowed: (0.0, None) };
        for (light, (truth_image, noise)) in self.images.iter().enumerate() {
            let image = rendered.renderer.read_visibility(light, technique).map_err(|e| format!("light {light}: {e}"))?;
            let metrics = compare_with_noise(truth_image, Some(noise), &image, &self.covered, WIDTH as usize, HEIGHT as usize);
            if metrics.mae >= worst.headline.0 {
                worst.headline = (metrics.mae, metrics.truth_noise);
            }
            if metrics.mae_penumbra >= worst.shadowed.0 {
                worst.shadowed = (metrics.mae_penumbra, metrics.truth_noise_penumbra);
            }
        }
        Ok(worst)
    }

    /// The largest share, over the lights, of covered pixels in a visible penumbra (between 0.02 and 0.98).
    fn penumbra_share(&self) -> f32 {
        let covered = self.covered.iter().filter(|c| **c).count().max(1) as f32;
        self.images
            .iter()
            .map(|(image, _)| image.iter().zip(&self.covered).filter(|(v, c)| **c && **v > 0.02 && **v < 0.98).count() as f32 / covered)
            .fold(0.0, f32::max)
    }
}

#[test]
fn every_technique_is_near_the_ground_truth_on_every_extreme() {
    let gpu = gpu();
    let registry = registry();
    let cases = extreme_cases();
    let names: Vec<&str> = cases.iter().map(|c| c.name).collect();
    let mut failures = Vec::new();

    for name in missing_must_run() {
        failures.push(format!("{name} must run here but is not registered"));
    }
    for info in registry.iter() {
        for limit in info.limits {
            if !names.contains(&limit.case) {
                failures.push(format!("{} declares a limit for `{}`, which is no case of the matrix", info.name, limit.case));
            }
        }
    }

    for name in HARD_MUST_FAIL {
        if !names.contains(name) {
            failures.push(format!("HARD_MUST_FAIL names `{name}`, which is no case of the matrix"));
        }
    }

    let mut report = Vec::new();
    for case in &cases {
        let truth = Truth::of(&gpu, &case.scene);
        let penumbra = truth.penumbra_share();
        let mut hard_baselines = HardBaselines::default();
        let mut errors: Vec<(&'static TechniqueInfo, f64, Option<f64>)> = Vec::new();
        let mut shadowed_errors: Vec<(&'static str, f64, Option<f64>)> = Vec::new();
        for info in registry.iter() {
            if info.kind == TechniqueKind::GroundTruth {
                // The ground truth is what the others are measured against.
                continue;
            }
            let rendered = match render(&gpu, &case.scene, info, &[], WIDTH, HEIGHT) {
                Err(e) if refusal_expected(info.name, case.name, &e) => {
                    println!("{} / {}: refused as expected: {e}", info.name, case.name);
                    continue;
                }
                result => match render_or_refusal(info.name, case.name, result) {
                    Ok(Some(rendered)) => rendered,
                    Ok(None) => continue,
                    Err(message) => {
                        failures.push(format!("{} / {}: {message}", info.name, case.name));
                        continue;
                    }
                },
            };
            if EXPECTED_REFUSALS.iter().any(|(name, scene, _)| *name == info.name && *scene == case.name) {
                failures.push(format!("{} / {}: renders, but this test expects a refusal: update EXPECTED_REFUSALS", info.name, case.name));
            }
            let Worst { headline: (worst, worst_noise), shadowed } = match truth.worst(&rendered, info.name) {
                Ok(worst) => worst,
                Err(message) => {
                    failures.push(format!("{} / {}: {message}", info.name, case.name));
                    continue;
                }
            };
            errors.push((info, worst, worst_noise));
            shadowed_errors.push((info.name, shadowed.0, shadowed.1));
            if info.name == HARD_SHADOW_TECHNIQUES[0] {
                hard_baselines.insert(None, Worst { headline: (worst, worst_noise), shadowed });
            }
            let (bound, reason) = bound_of(info, case.name);
            let (bound, common) = (f64::from(bound), f64::from(COMMON_BOUND));
            report.push(format!(
                "{:>12} {:>7.4} ± {:.4} (bound {bound:.2}) {}{}",
                info.name,
                worst,
                worst_noise.unwrap_or(0.0),
                case.name,
                case.framework_rule.map_or(String::new(), |rule| format!(" [framework cull: {rule}]"))
            ));
            let hard_technique = HARD_SHADOW_TECHNIQUES.contains(&info.name);
            if hard_technique && HARD_MUST_FAIL.contains(&case.name) {
                if worst <= common {
                    failures.push(format!(
                        "{} / {}: a hard shadow meets the common bound ({worst:.4} <= {common}): the case no longer tells soft shadows from hard",
                        info.name, case.name
                    ));
                }
            } else if hard_technique && beats_hard_needed(case, penumbra) {
                // The baseline where there is a penumbra: it cannot draw one, and is not asked to.
            } else if worst > bound {
                failures.push(format!(
                    "{} / {}: mean |error| {worst:.4} against the ground truth where either shadows, above {bound}{}",
                    info.name,
                    case.name,
                    reason.map_or(String::new(), |r| format!(" (its declared limit: {r})"))
                ));
            } else if reason.is_some() && worst <= common && !beats_hard_needed(case, penumbra) {
                failures.push(format!(
                    "{} / {}: mean |error| {worst:.4} meets the common bound {COMMON_BOUND}: remove its declared limit",
                    info.name, case.name
                ));
            }
            let name = info.name;
            if let Err(panic) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                check_expectation(name, (case.name, &case.scene), case.expect, &rendered);
            })) {
                failures.push(panic.downcast_ref::<String>().cloned().unwrap_or_else(|| format!("{name} / {}: check failed", case.name)));
            }
        }
        // Where there is a penumbra, every soft technique beats hard shadows beyond the truth's noise.
        if beats_hard_needed(case, penumbra) {
            let hard_map_size = registry.iter().find(|info| info.name == HARD_SHADOW_TECHNIQUES[0]).and_then(shadow_map_size);
            for (info, error, noise) in &errors {
                if HARD_SHADOW_TECHNIQUES.contains(&info.name) {
                    continue;
                }
                let map_size = shadow_map_size(info);
                let ((hard_error, hard_noise), _) = match hard_baselines.at(&gpu, case, &truth, map_size) {
                    Ok(hard) => hard,
                    Err(message) => {
                        failures.push(format!("{} / {}: {message}", info.name, case.name));
                        continue;
                    }
                };
                let beats_hard = *error < hard_error && !is_tie(*error, *noise, hard_error, hard_noise);
                // A penumbra narrower than a texel of the technique's map everywhere is not in its
                // map: the most it can draw is the map's hard shadow, so it must be no worse than
                // that, or than its mean over the texel grid's phase, which decides which edge
                // pixels either gets wrong.
                let penumbra_texels = truth.widest_penumbra_texels(map_size.or(hard_map_size).unwrap_or(0));
                let sub_texel = penumbra_texels < 1.0;
                let no_worse = *error <= hard_error || is_tie(*error, *noise, hard_error, hard_noise);
                let phase = if sub_texel && !no_worse {
                    match hard_baselines.phase_mean(&gpu, case, &truth, map_size) {
                        Ok(mean) => Some(mean),
                        Err(message) => {
                            failures.push(format!("{} / {}: {message}", info.name, case.name));
                            continue;
                        }
                    }
                } else {
                    None
                };
                let no_worse_over_phase = phase
                    .is_some_and(|(phase_error, phase_noise)| *error <= phase_error || is_tie(*error, *noise, phase_error, phase_noise));
                let meets = if sub_texel { no_worse || no_worse_over_phase } else { beats_hard };
                if bound_of(info, case.name).1.is_some() {
                    if meets && *error <= f64::from(COMMON_BOUND) {
                        failures.push(format!(
                            "{} / {}: error {error:.4} {} hard shadows and meets the common bound {COMMON_BOUND}: remove its declared limit",
                            info.name,
                            case.name,
                            if sub_texel { "is no worse than" } else { "beats" }
                        ));
                    }
                    continue;
                }
                match (phase, meets) {
                    (Some((phase_error, _)), true) => report.push(format!(
                        "{:>12} {error:>7.4} no worse than hard shadows' mean {phase_error:.4} over the texel grid's phase ({}: {hard_error:.4}) {}",
                        info.name,
                        map_size_text(map_size),
                        case.name
                    )),
                    (Some((phase_error, _)), false) => failures.push(format!(
                        "{} / {}: error {error:.4} worse than hard shadows' {hard_error:.4} ({}), and than their mean {phase_error:.4} over the texel grid's phase (map sides {:+} to {:+} texels from it), beyond the truth's noise, where the widest penumbra is {penumbra_texels:.2} texels of its map",
                        info.name,
                        case.name,
                        map_size_text(map_size),
                        GRID_PHASE_SIDES[0],
                        GRID_PHASE_SIDES[GRID_PHASE_SIDES.len() - 1],
                    )),
                    (None, false) => failures.push(format!(
                        "{} / {}: error {error:.4} does not beat hard shadows' {hard_error:.4} ({}) beyond the truth's noise ({:.4} + {:.4}), on a scene with {:.1}% of its pixels in penumbra",
                        info.name,
                        case.name,
                        map_size_text(map_size),
                        noise.unwrap_or(0.0),
                        hard_noise.unwrap_or(0.0),
                        penumbra * 100.0
                    )),
                    (None, true) => {}
                }
            }
        }
        // In an interior, pvsm (PCSS's blocker average with its own search and filter) does no
        // worse than PCSS beyond the truth's noise.
        if INTERIORS.contains(&case.name) {
            let error_of = |name: &str| errors.iter().find(|(info, _, _)| info.name == name).map(|(_, e, n)| (*e, *n));
            match (error_of("pvsm"), error_of("pcss")) {
                (Some((pvsm, pvsm_noise)), Some((pcss, pcss_noise))) => {
                    if pvsm > pcss && !is_tie(pvsm, pvsm_noise, pcss, pcss_noise) {
                        failures
                            .push(format!("pvsm / {}: error {pvsm:.4} worse than pcss's {pcss:.4} beyond the truth's noise", case.name));
                    }
                }
                _ => failures.push(format!("{}: pvsm and pcss must both run on an interior", case.name)),
            }
            // And pcss and sssm beat hard shadows over the truth's umbra and penumbra (their false
            // shadows beside it are the matrix's headline error, above).
            let shadowed_of = |name: &str| shadowed_errors.iter().find(|(n, _, _)| *n == name).map(|(_, e, n)| (*e, *n));
            for name in INTERIOR_SOFT {
                let Some(info) = registry.iter().find(|info| info.name == *name) else {
                    failures.push(format!("{}: {name} must run on an interior", case.name));
                    continue;
                };
                let map_size = shadow_map_size(info);
                let (hard, hard_noise) = match hard_baselines.at(&gpu, case, &truth, map_size) {
                    Ok((_, shadowed)) => shadowed,
                    Err(message) => {
                        failures.push(format!("{name} / {}: {message}", case.name));
                        continue;
                    }
                };
                let hard_size = map_size_text(map_size);
                match shadowed_of(name) {
                    Some((error, noise)) if error < hard && !is_tie(error, noise, hard, hard_noise) => report.push(format!(
                        "{name:>12} {error:>7.4} over the truth's umbra and penumbra (hard {hard:.4}, {hard_size}) {}",
                        case.name
                    )),
                    Some((error, _)) => failures.push(format!(
                        "{name} / {} (umbra and penumbra): error {error:.4} does not beat hard shadows' {hard:.4} ({hard_size}) beyond the truth's noise",
                        case.name
                    )),
                    None => failures.push(format!("{}: {name} must run on an interior", case.name)),
                }
            }
        }
    }
    println!(
        "mean |error| where the truth or the technique shadows, ± the truth's own ({WIDTH}x{HEIGHT}, two sets of {REFERENCE_SAMPLES}² rays):\n{}",
        report.join("\n")
    );
    // The open failures: each must still fail (so that the list stays true), and is reported.
    let open = |message: &str| OPEN_FAILURES.iter().position(|(technique, case, _)| message.starts_with(&format!("{technique} / {case}:")));
    let mut still_failing = vec![false; OPEN_FAILURES.len()];
    let mut unexpected = Vec::new();
    for message in failures {
        match open(&message) {
            Some(index) => {
                still_failing[index] = true;
                println!("open failure ({}): {message}", OPEN_FAILURES[index].2);
            }
            None => unexpected.push(message),
        }
    }
    for ((technique, case, _), failing) in OPEN_FAILURES.iter().zip(still_failing) {
        if !failing {
            unexpected.push(format!("{technique} / {case}: listed in OPEN_FAILURES but passes: remove its line"));
        }
    }
    assert!(unexpected.is_empty(), "{}", unexpected.join("\n"));
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
