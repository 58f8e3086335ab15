//! The ground-truth ray caster against the exact answer of `parallel-square`,
//! with tolerances derived from the sample count N.
//!
//! Seen from a receiver point, the occluder back-projects onto the light as an
//! axis-aligned rectangle, so its edges cut at most 4N of the N×N strata; each
//! cut stratum is off by at most 1/N², hence |error| ≤ 4/N at every pixel. The
//! jitter makes each cut stratum's error zero-mean with variance ≤ 1/(4N⁴), so
//! the error's standard deviation is at most √(4N)/(2N²) = N^-1.5: the mean
//! absolute error over the penumbra stays below that.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::{Vec2, Vec3};
use ssm_core::reference::{GroundTruth, ReferenceCache, SurfacePoint, parallel_rectangle_visibility};
use ssm_scene::builtin;
use ssm_testing::{gpu, render};

const SIZE: (u32, u32) = (128, 96);

/// (max error, mean error over penumbra pixels, penumbra pixel count) of the ray caster at N samples per axis.
fn errors(samples: u32) -> (f32, f32, usize) {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let settings = [("samples", samples.to_string()), ("cache", "false".to_owned())];
    let settings: Vec<(&str, &str)> = settings.iter().map(|(k, v)| (*k, v.as_str())).collect();
    let rendered = render(&gpu, &scene, &ssm_core::reference::INFO, &settings, SIZE.0, SIZE.1).unwrap();
    let positions = rendered.renderer.read_positions().unwrap();
    let light = &scene.lights[0];
    let (mut max, mut sum, mut count) = (0.0f32, 0.0f32, 0usize);
    for (traced, p) in rendered.visibility.iter().zip(&positions) {
        if p[3] < 0.5 {
            continue;
        }
        let exact = parallel_rectangle_visibility(light, Vec3::new(0.0, 2.0, 0.0), Vec2::splat(0.5), Vec3::new(p[0], p[1], p[2]));
        let error = (traced - exact).abs();
        max = max.max(error);
        if exact > 0.0 && exact < 1.0 {
            sum += error;
            count += 1;
        }
    }
    (max, sum / count.max(1) as f32, count)
}

#[test]
fn ray_caster_matches_the_analytic_parallel_square_within_the_sampling_error() {
    let mut means = Vec::new();
    for n in [4u32, 8, 16, 32] {
        let (max, mean, penumbra) = errors(n);
        let n_f = n as f32;
        println!(
            "N = {n}: max error {max:.4} (bound {:.4}), mean penumbra error {mean:.5} (bound {:.5}) over {penumbra} pixels",
            4.0 / n_f,
            n_f.powf(-1.5)
        );
        assert!(penumbra > 500, "the penumbra covers too few pixels ({penumbra}) to measure");
        assert!(max <= 4.0 / n_f + 1e-4, "N = {n}: max error {max} above 4/N");
        assert!(mean <= n_f.powf(-1.5), "N = {n}: mean error {mean} above N^-1.5");
        means.push(mean);
    }
    // The error falls with N (about as N^-1.5: 8x from N = 8 to 32; ask for 3x).
    assert!(means[3] < means[1] / 3.0, "{means:?}");
}

#[test]
fn cached_results_are_identical_and_keyed_by_their_inputs() {
    let scene = builtin("parallel-square").unwrap().build();
    let truth = GroundTruth::new(&scene);
    let points: Vec<Option<SurfacePoint>> = (0..64)
        .map(|i| Some(SurfacePoint { position: Vec3::new(i as f32 * 0.04, 0.0, 0.3), normal: Vec3::Y, footprint: None, closed: false }))
        .chain([None])
        .collect();
    let dir = std::env::temp_dir().join(format!("ssm-reference-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let light = &scene.lights[0];
    let first = truth.trace_cached(light, &points, 8, 1, &dir);
    assert!(!first.cached && first.rays == 64 * 64);
    let again = truth.trace_cached(light, &points, 8, 1, &dir);
    assert!(again.cached && again.rays == 0);
    assert_eq!(first.visibility, again.visibility);
    assert_eq!(*first.visibility.last().unwrap(), 1.0, "a pixel without a surface is lit");
    // The cache alone (no tracer built) finds the same entry, and nothing for other inputs.
    let cache = ReferenceCache::of(&scene);
    assert_eq!(cache.cached(light, &points, 8, 1, &dir).map(|image| image.visibility), Some(first.visibility.clone()));
    assert!(cache.cached(light, &points, 8, 3, &dir).is_none());
    // A different sample count or seed is a different entry.
    assert!(!truth.trace_cached(light, &points, 4, 1, &dir).cached);
    assert!(!truth.trace_cached(light, &points, 8, 2, &dir).cached);
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_point_behind_the_light_or_a_point_light_gives_exact_answers() {
    let scene = builtin("parallel-square").unwrap().build();
    let truth = GroundTruth::new(&scene);
    let mut light = scene.lights[0];
    let mut rng = ssm_core::reference::SplitMix64::for_pixel(1, 0);
    let behind = SurfacePoint { position: Vec3::new(0.0, 5.0, 0.0), normal: Vec3::Y, footprint: None, closed: false };
    assert_eq!(truth.visibility(&light, &behind, 8, &mut rng), 0.0);
    light.half_size = Vec2::ZERO;
    let under = SurfacePoint { position: Vec3::new(0.9, 0.0, 0.0), normal: Vec3::Y, footprint: None, closed: false };
    let beside = SurfacePoint { position: Vec3::new(1.1, 0.0, 0.0), normal: Vec3::Y, footprint: None, closed: false };
    assert_eq!(truth.visibility(&light, &under, 8, &mut rng), 0.0);
    assert_eq!(truth.visibility(&light, &beside, 8, &mut rng), 1.0);
}

/// `footprint = pixel`: each sample starts from its own point of the pixel's footprint on the
/// tangent plane, so the result is the exact visibility averaged over the footprint (here a
/// 1.2 × 1.2 square of the ground across the penumbra's inner edge, where visibility is not
/// linear and the average differs from the centre's value), within the sampling error.
#[test]
fn a_pixel_footprint_averages_the_visibility_over_the_pixel() {
    use ssm_core::reference::PixelFootprint;
    let scene = builtin("parallel-square").unwrap().build();
    let truth = GroundTruth::new(&scene);
    let light = scene.lights[0];
    let exact = |p: Vec3| parallel_rectangle_visibility(&light, Vec3::new(0.0, 2.0, 0.0), Vec2::splat(0.5), p);
    let (centre, half) = (Vec3::new(0.4, 0.0, 0.1), 0.6);
    let eye = centre + Vec3::new(0.0, 10.0, 0.0);
    let footprint = PixelFootprint {
        eye,
        corner: Vec3::new(-half, -10.0, -half),
        across: Vec3::new(2.0 * half, 0.0, 0.0),
        down: Vec3::new(0.0, 0.0, 2.0 * half),
    };
    let dense = 200;
    let mut average = 0.0;
    for j in 0..dense {
        for i in 0..dense {
            let (s, t) = ((i as f32 + 0.5) / dense as f32, (j as f32 + 0.5) / dense as f32);
            average += exact(footprint.on_plane(s, t, centre, Vec3::Y).unwrap());
        }
    }
    average /= (dense * dense) as f32;
    let point = SurfacePoint { position: centre, normal: Vec3::Y, footprint: Some(footprint), closed: false };
    let traced: f32 =
        (0..512).map(|seed| truth.visibility(&light, &point, 32, &mut ssm_core::reference::SplitMix64::for_pixel(seed, 0))).sum::<f32>()
            / 512.0;
    println!("footprint average: exact {average:.4}, traced {traced:.4}, centre {:.4}", exact(centre));
    assert!((exact(centre) - average).abs() > 0.05, "the footprint must matter here");
    assert!((traced - average).abs() < 0.004, "traced {traced} against the exact average {average}");
}

/// The pyramid shortcut (lit with no ray cast when no triangle is in the pyramid from the point
/// to the light, dark when one triangle covers it, else each ray against the few triangles in it)
/// gives what casting every ray through the BVH gives, with the same jitter: on scenes with
/// contact, thin occluders, self-shadowing curved surfaces and a point light, with 8² rays and
/// with 13² and 20² (quarters of odd and uneven sizes, every eighth or so pixel).
#[test]
fn the_pyramid_shortcut_gives_what_every_ray_gives() {
    use ssm_core::reference::SplitMix64;
    let gpu = gpu();
    let mut point_light = builtin("floating-sphere").unwrap().build();
    point_light.lights[0].half_size = Vec2::ZERO;
    let scenes = [
        ("sphere-cube", builtin("sphere-cube").unwrap().build()),
        ("contact", builtin("contact").unwrap().build()),
        ("leaves", builtin("leaves").unwrap().build()),
        ("bar-grid", builtin("bar-grid").unwrap().build()),
        ("floating-sphere, point light", point_light),
    ];
    for (name, scene) in scenes {
        let needs = ssm_core::Requirements { gbuffer: true, ..ssm_core::Requirements::NONE };
        let renderer = ssm_core::Renderer::new(&gpu, &scene, 96, 72, &needs).unwrap();
        let positions = renderer.read_positions().unwrap();
        let normals = renderer.read_normals().unwrap();
        let truth = GroundTruth::new(&scene);
        let light = &scene.lights[0];
        for (samples, stride) in [(8, 1), (13, 3), (20, 5)] {
            let (mut differing, mut covered) = (0, 0);
            for (index, (p, n)) in positions.iter().zip(&normals).enumerate().step_by(stride) {
                if p[3] < 0.5 {
                    continue;
                }
                covered += 1;
                let closed = ssm_core::GBuffer::flags(n[3]) & ssm_core::GBuffer::CLOSED != 0;
                let point =
                    SurfacePoint { position: Vec3::new(p[0], p[1], p[2]), normal: Vec3::new(n[0], n[1], n[2]), footprint: None, closed };
                let fast = truth.visibility(light, &point, samples, &mut SplitMix64::for_pixel(7, index as u64));
                let every_ray = truth.visibility_per_ray(light, &point, samples, &mut SplitMix64::for_pixel(7, index as u64));
                if fast != every_ray {
                    differing += 1;
                    println!("{name}, {samples}² rays: pixel {index}: {fast} with the shortcut, {every_ray} ray by ray");
                }
            }
            println!("{name}, {samples}² rays: {differing} of {covered} pixels differ");
            assert_eq!(differing, 0, "{name}, {samples}² rays");
        }
    }
}

/// `traversal = per_ray` (every ray through the BVH) traces the same image as the shortcuts,
/// pixel for pixel, so timing the two against each other compares like with like.
#[test]
fn per_ray_traversal_traces_the_shortcuts_image() {
    use ssm_core::reference::Traversal;
    let gpu = gpu();
    let scene = builtin("sphere-cube").unwrap().build();
    let needs = ssm_core::Requirements { gbuffer: true, ..ssm_core::Requirements::NONE };
    let renderer = ssm_core::Renderer::new(&gpu, &scene, 64, 48, &needs).unwrap();
    let points = ssm_core::reference::surface_points(
        &renderer.read_positions().unwrap(),
        &renderer.read_normals().unwrap(),
        &renderer.scene.camera,
        false,
    );
    let light = &scene.lights[0];
    let shortcuts = GroundTruth::new(&scene).trace(light, &points, 8, 3);
    let per_ray = GroundTruth::new(&scene).with_traversal(Traversal::PerRay).trace(light, &points, 8, 3);
    let shadowed = shortcuts.visibility.iter().filter(|v| **v < 1.0).count();
    assert!(shadowed > 100, "the view must hold shadow to compare: {shadowed} pixels");
    let differing = shortcuts.visibility.iter().zip(&per_ray.visibility).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{differing} of {} pixels differ between the traversals", points.len());
}

/// A closed mesh is the boundary of an opaque solid: the side the camera sees gets no light from
/// behind its tangent plane. A light sealed inside a box resting on the ground: the ground
/// outside and the box's outer walls read 0 exactly: every ray from them to the light crosses a
/// wall, or leaves the seen side of a wall from behind (before the rule, the walls below the
/// light's plane saw it through themselves).
#[test]
fn a_light_sealed_in_a_closed_box_lights_nothing_outside_it() {
    let gpu = gpu();
    let sealed = ssm_testing::scene_from_manifest(
        "[camera]\nposition = [0.0, 5.0, 7.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[light]]\ncentre = [0.0, 0.8, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [0.5, 0.5]\n\
         [[object]]\nprimitive = \"box\"\nsize = [2.0, 1.0, 2.0]\ntranslate = [0.0, 0.5, 0.0]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [10.0, 10.0]\nrole = \"receiver\"\n",
    );
    let rendered = render(&gpu, &sealed, &ssm_core::reference::INFO, &[("samples", "4"), ("cache", "false")], 96, 72).unwrap();
    let normals = rendered.renderer.read_normals().unwrap();
    let covered = rendered.coverage();
    let on_box = normals.iter().filter(|n| ssm_core::GBuffer::flags(n[3]) & ssm_core::GBuffer::CLOSED != 0).count();
    assert!(on_box > 200, "the box must be in view: {on_box} pixels");
    let lit = rendered.visibility.iter().zip(&covered).filter(|(v, c)| **c && **v > 0.0).count();
    assert_eq!(lit, 0, "{lit} pixels see the sealed light");
}
