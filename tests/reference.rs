//! The ground-truth ray caster against the exact answer of `parallel-square`,
//! with tolerances derived from the sample count N; the ground truth as traced
//! (two sets, refined, with strata of few triangles decided exactly) against
//! the exact answer, against its own reported noise and across seeds.
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
use ssm_core::reference::{GroundTruth, ReferenceCache, Sampling, SurfacePoint, parallel_rectangle_visibility};
use ssm_scene::builtin;
use ssm_testing::{gpu, render};

const SIZE: (u32, u32) = (128, 96);

/// (max error, mean error over penumbra pixels, penumbra pixel count) against the exact answer,
/// at each pixel of `parallel-square`'s view, of `visibility` (the point, the light, the pixel's index).
fn errors(visibility: impl Fn(&SurfacePoint, &ssm_scene::RectLight, usize) -> f32) -> (f32, f32, usize) {
    let scene = builtin("parallel-square").unwrap().build();
    let points = view_points(&scene, SIZE);
    let light = &scene.lights[0];
    let (mut max, mut sum, mut count) = (0.0f32, 0.0f32, 0usize);
    for (index, point) in points.iter().enumerate() {
        let Some(point) = point else { continue };
        let exact = parallel_rectangle_visibility(light, Vec3::new(0.0, 2.0, 0.0), Vec2::splat(0.5), point.position);
        let error = (visibility(point, light, index) - exact).abs();
        max = max.max(error);
        if exact > 0.0 && exact < 1.0 {
            sum += error;
            count += 1;
        }
    }
    (max, sum / count.max(1) as f32, count)
}

/// The rays alone (one stratified set of N×N, [`GroundTruth::visibility`]) within the sampling
/// error derived above.
#[test]
fn ray_caster_matches_the_analytic_parallel_square_within_the_sampling_error() {
    let mut means = Vec::new();
    let scene = builtin("parallel-square").unwrap().build();
    let truth = GroundTruth::new(&scene);
    for n in [4u32, 8, 16, 32] {
        let (max, mean, penumbra) = errors(|point, light, index| {
            truth.visibility(light, point, n, &mut ssm_core::reference::SplitMix64::for_pixel(1, index as u64))
        });
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

/// The ground truth as traced (`reference` at its defaults, through the renderer): where the
/// visibility varies, the square's two triangles are few enough in a part of the light's pyramid
/// for the part to be decided from the area their projection covers, so the penumbra's error is
/// far below what rays alone reach with more rays (N = 16 above: 0.0048), and within its reported
/// noise.
#[test]
fn the_default_truth_of_parallel_square_is_within_its_noise_of_the_exact_answer() {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let rendered = render(&gpu, &scene, &ssm_core::reference::INFO, &[("cache", "false")], SIZE.0, SIZE.1).unwrap();
    let (max, mean, penumbra) = errors(|_, _, index| rendered.visibility[index]);
    let points = view_points(&scene, SIZE);
    let image = GroundTruth::new(&scene).trace(&scene.lights[0], &points, Sampling::DEFAULT, 1);
    let light = scene.lights[0];
    let (mut noise, mut count) = (0.0f64, 0usize);
    for (index, point) in points.iter().enumerate() {
        let Some(point) = point else { continue };
        let exact = parallel_rectangle_visibility(&light, Vec3::new(0.0, 2.0, 0.0), Vec2::splat(0.5), point.position);
        if exact > 0.0 && exact < 1.0 {
            noise += f64::from(image.noise[index]);
            count += 1;
        }
    }
    let noise = noise / count as f64;
    println!("default truth: max error {max:.2e}, mean penumbra error {mean:.2e} over {penumbra} pixels, reported noise {noise:.2e}");
    assert!(penumbra > 500, "the penumbra covers too few pixels ({penumbra}) to measure");
    assert!(mean < 1e-3, "mean penumbra error {mean}");
    // Where the square's triangles are few enough for whole parts of the light, the truth is exact
    // and reports no noise: its error is then the f32 rounding of the answers (10⁻⁴ allowed).
    assert!((f64::from(mean) - noise).abs() <= 0.5 * noise + 1e-4, "mean penumbra error {mean} against a reported noise of {noise}");
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
    let first = truth.trace_cached(light, &points, Sampling::uniform(8), 1, &dir);
    assert!(!first.cached && first.rays == 64 * 2 * 64, "two sets of 8² rays per point: {}", first.rays);
    let again = truth.trace_cached(light, &points, Sampling::uniform(8), 1, &dir);
    assert!(again.cached && again.rays == 0);
    assert_eq!(first.visibility, again.visibility);
    assert_eq!(first.noise, again.noise, "the noise is cached with the visibility");
    assert_eq!(*first.visibility.last().unwrap(), 1.0, "a pixel without a surface is lit");
    // The cache alone (no tracer built) finds the same entry, and nothing for other inputs.
    let cache = ReferenceCache::of(&scene);
    assert_eq!(cache.cached(light, &points, Sampling::uniform(8), 1, &dir).map(|image| image.visibility), Some(first.visibility.clone()));
    assert!(cache.cached(light, &points, Sampling::uniform(8), 3, &dir).is_none());
    // A different sample count, refinement or seed is a different entry.
    assert!(!truth.trace_cached(light, &points, Sampling::uniform(4), 1, &dir).cached);
    assert!(!truth.trace_cached(light, &points, Sampling { samples_per_axis: 8, refine: 2 }, 1, &dir).cached);
    assert!(!truth.trace_cached(light, &points, Sampling::uniform(8), 2, &dir).cached);
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 4);
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

/// `traversal = per_ray` (every ray through the BVH, every stratum by rays) traces the same image
/// as the shortcuts within the noise each reports (the single-set rays match ray for ray:
/// `the_pyramid_shortcut_gives_what_every_ray_gives`).
#[test]
fn per_ray_traversal_traces_the_shortcuts_image() {
    use ssm_core::reference::Traversal;
    for name in ["sphere-cube", "parallel-square"] {
        let scene = builtin(name).unwrap().build();
        let points = view_points(&scene, (64, 48));
        let light = &scene.lights[0];
        let sampling = Sampling { samples_per_axis: 8, refine: 3 };
        let shortcuts = GroundTruth::new(&scene).trace(light, &points, sampling, 3);
        let per_ray = GroundTruth::new(&scene).with_traversal(Traversal::PerRay).trace(light, &points, sampling, 3);
        let shadowed = shortcuts.visibility.iter().filter(|v| **v < 1.0).count();
        assert!(shadowed > 100, "{name}: the view must hold shadow to compare: {shadowed} pixels");
        traces_agree(name, &shortcuts, &per_ray);
    }
}

/// Two traces of one view agree within the noise each reports, and on where the umbra is.
fn traces_agree(name: &str, shortcuts: &ssm_core::reference::ReferenceImage, per_ray: &ssm_core::reference::ReferenceImage) {
    let points = shortcuts.visibility.len();
    // The shortcuts decide strata with few triangles from the area they cover, which the per-ray
    // definition samples: the two differ by their noise, no more.
    let (mut difference, mut noise, mut count) = (0.0f64, 0.0f64, 0usize);
    for index in 0..points {
        let (a, b) = (shortcuts.visibility[index], per_ray.visibility[index]);
        if a > 0.0 && a < 1.0 || b > 0.0 && b < 1.0 {
            difference += f64::from((a - b).abs());
            noise += f64::from(shortcuts.noise[index] + per_ray.noise[index]);
            count += 1;
        }
    }
    println!(
        "{name}: per ray against shortcuts: mean difference {:.5}, their noise {:.5}, over {count} pixels",
        difference / count as f64,
        noise / count as f64
    );
    assert!(difference <= 1.5 * noise, "{name}: the traversals differ by {difference}, beyond their noise {noise}");
    let umbra = shortcuts.visibility.iter().zip(&per_ray.visibility).filter(|(a, b)| (**a == 0.0) != (**b == 0.0)).count();
    assert!(umbra < points / 100, "{name}: {umbra} pixels are umbra in one and not in the other");
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

/// The points of `scene`'s view at `size`, as the ground truth samples them (pixel centres).
fn view_points(scene: &ssm_scene::Scene, (width, height): (u32, u32)) -> Vec<Option<SurfacePoint>> {
    let gpu = gpu();
    let needs = ssm_core::Requirements { gbuffer: true, ..ssm_core::Requirements::NONE };
    let renderer = ssm_core::Renderer::new(&gpu, scene, width, height, &needs).unwrap();
    ssm_core::reference::surface_points(
        &renderer.read_positions().unwrap(),
        &renderer.read_normals().unwrap(),
        &renderer.scene.camera,
        false,
    )
}

/// The noise the ground truth reports is its actual error: on `sphere-cube` (spheres of many
/// triangles, taken as triangles so that most of the penumbra is sampled by rays), the mean reported noise over the
/// penumbra is within a factor of 1.5 of the mean absolute error against a truth traced with far
/// more rays (whose own error, also reported, is subtracted in quadrature), with and without
/// refinement; refinement lowers it.
#[test]
fn the_reported_noise_is_the_truths_actual_error_within_a_factor_of_one_and_a_half() {
    let scene = builtin("sphere-cube").unwrap().build();
    let light = scene.lights[0];
    let points = view_points(&scene, SIZE);
    // The spheres as triangles: every part of the light that they hide sampled by rays.
    let truth = GroundTruth::new(&scene).with_convex_pieces(false);
    let fine = truth.trace(&light, &points, Sampling { samples_per_axis: 32, refine: 4 }, 99);
    let mut errors = Vec::new();
    for sampling in [Sampling::uniform(6), Sampling::uniform(12), Sampling { samples_per_axis: 6, refine: 3 }, Sampling::DEFAULT] {
        let image = truth.trace(&light, &points, sampling, 5);
        let (mut error, mut noise, mut fine_noise, mut count) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for (index, point) in points.iter().enumerate() {
            let exact = fine.visibility[index];
            if point.is_some() && exact > 0.0 && exact < 1.0 {
                error += f64::from((image.visibility[index] - exact).abs());
                noise += f64::from(image.noise[index]);
                fine_noise += f64::from(fine.noise[index]);
                count += 1;
            }
        }
        assert!(count > 500, "too few penumbra pixels ({count}) to measure");
        let (error, noise, fine_noise) = (error / count as f64, noise / count as f64, fine_noise / count as f64);
        let own_error = (error * error - fine_noise * fine_noise).max(0.0).sqrt();
        let rays = image.rays as f64 / points.iter().flatten().count() as f64;
        println!(
            "{sampling:?}: mean |error| {own_error:.5} (against the fine truth {error:.5}, its noise {fine_noise:.5}), reported noise {noise:.5} (ratio {:.2}), {rays:.0} rays a pixel",
            noise / own_error
        );
        assert!(
            noise > own_error / 1.5 && noise < own_error * 1.5,
            "{sampling:?}: reported noise {noise} against an actual error of {own_error}"
        );
        errors.push(own_error);
    }
    assert!(errors[2] < errors[0] / 2.0, "refining 6² strata 3×3 where the visibility varies must at least halve the error: {errors:?}");
    assert!(errors[3] < errors[1] / 2.0, "the default refinement must at least halve the error of its strata alone: {errors:?}");
}

/// Two seeds of the default ground truth agree within 0.003 over the penumbra of built-in scenes
/// with contact shadows and a large light (`contact`, its box and ball as convex pieces, and as
/// triangles sampled by rays) and with many small non-convex occluders (`forest`), and the noise
/// it reports predicts their difference (√2 times the noise of one, within a factor of 2; both
/// zero where every penumbra pixel is exact).
#[test]
fn two_seeds_of_the_default_truth_agree_within_three_thousandths() {
    for (name, pieces) in [("contact", true), ("contact", false), ("forest", true)] {
        let scene = builtin(name).unwrap().build();
        let light = scene.lights[0];
        let points = view_points(&scene, (160, 120));
        let truth = GroundTruth::new(&scene).with_convex_pieces(pieces);
        let first = truth.trace(&light, &points, Sampling::DEFAULT, 1);
        let second = truth.trace(&light, &points, Sampling::DEFAULT, 2);
        let (mut difference, mut noise, mut count) = (0.0f64, 0.0f64, 0usize);
        for (index, point) in points.iter().enumerate() {
            let (a, b) = (first.visibility[index], second.visibility[index]);
            // The penumbra of either trace.
            if point.is_some() && (a > 0.0 && a < 1.0 || b > 0.0 && b < 1.0) {
                difference += f64::from((a - b).abs());
                noise += f64::from(first.noise[index] + second.noise[index]) / 2.0;
                count += 1;
            }
        }
        assert!(count > 1000, "{name}: too few penumbra pixels ({count})");
        let (difference, noise) = (difference / count as f64, noise / count as f64);
        let predicted = noise * std::f64::consts::SQRT_2;
        println!(
            "{name} 160x120, pieces {pieces}: two seeds differ by {difference:.5} over {count} penumbra pixels; predicted {predicted:.5}"
        );
        assert!(difference <= 0.003, "{name}, pieces {pieces}: two seeds differ by {difference}");
        let exact = difference < 1e-6 && predicted < 1e-6;
        assert!(
            exact || predicted > difference / 2.0 && predicted < difference * 2.0,
            "{name}, pieces {pieces}: predicted {predicted} against {difference}"
        );
    }
}

/// The default estimate is unbiased where its refinement works hardest: at points of the ground
/// in the penumbra of `sphere-cube`'s spheres (each of many triangles, so that refined strata
/// are sampled by rays, the stratum's own ray standing for the sub-stratum it fell in), its mean
/// over many seeds matches the mean of one set of 32² rays per seed (the definition, unbiased),
/// pixel by pixel, within five standard errors. With the spheres as convex pieces, where the
/// estimate is exact, it matches the same mean within the same bound.
#[test]
fn the_default_estimate_is_unbiased_in_a_penumbra_of_many_triangles() {
    let scene = builtin("sphere-cube").unwrap().build();
    let light = scene.lights[0];
    for pieces in [false, true] {
        let truth = GroundTruth::new(&scene).with_convex_pieces(pieces);
        const SEEDS: u64 = 300;
        let mean_and_error = |values: &[f64]| {
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let variance = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (values.len() - 1) as f64;
            (mean, (variance / values.len() as f64).sqrt())
        };
        let (mut tested, mut exact_points) = (0, 0);
        for step in 0..60 {
            let point =
                SurfacePoint { position: Vec3::new(-1.2 + step as f32 * 0.04, 0.0, 0.13), normal: Vec3::Y, closed: false, footprint: None };
            let rough = truth.visibility(&light, &point, 16, &mut ssm_core::reference::SplitMix64::for_pixel(5, step));
            if !(0.1..0.9).contains(&rough) {
                continue;
            }
            let (estimates, definition): (Vec<f64>, Vec<f64>) = (0..SEEDS)
                .map(|seed| {
                    let mut rng = ssm_core::reference::SplitMix64::for_pixel(seed, step);
                    let estimate = f64::from(truth.estimate(&light, &point, Sampling::DEFAULT, &mut rng).visibility);
                    let mut rng = ssm_core::reference::SplitMix64::for_pixel(seed + 10_000, step);
                    (estimate, f64::from(truth.visibility(&light, &point, 32, &mut rng)))
                })
                .unzip();
            let ((estimate, estimate_error), (exact, exact_error)) = (mean_and_error(&estimates), mean_and_error(&definition));
            exact_points += usize::from(estimate_error == 0.0);
            let z = (estimate - exact) / estimate_error.hypot(exact_error);
            println!(
                "pieces {pieces}, x = {:.2}: estimate {estimate:.5} ± {estimate_error:.5}, 32² rays {exact:.5} ± {exact_error:.5}: z = {z:.2}",
                point.position.x
            );
            assert!(
                z.abs() < 5.0,
                "pieces {pieces}, x = {}: the estimate's mean {estimate} is {z:.1} standard errors from {exact}",
                point.position.x
            );
            tested += 1;
        }
        assert!(tested >= 8, "too few penumbra points ({tested}) under the spheres");
        // With pieces, the spheres' shares are exact at every point; without, none is.
        assert_eq!(exact_points, if pieces { tested } else { 0 }, "pieces {pieces}: exact at {exact_points} of {tested} points");
    }
}

/// Convex pieces give the visibility that rays through their triangles give: on scenes of boxes
/// and spheres (points on them, their tangent planes cutting the light), thin quads, a box room
/// holding the light and the camera, quads crossing the light's plane and the points', trees each
/// merged into one mesh, the default estimate (exact where pieces decide) and one of many rays
/// without pieces (32² strata refined 4×4) agree at every pixel within 0.02, and over the
/// penumbra within their noise; and the pieces decide most of the penumbra exactly (no noise).
#[test]
fn convex_pieces_hide_what_their_triangles_hide() {
    let gpu = gpu();
    let room = ssm_testing::scene_from_manifest(
        "[camera]\nposition = [2.5, 1.7, 2.5]\ntarget = [-1.0, 0.5, -1.0]\n\
         [[light]]\ncentre = [-3.9, 2.0, 0.0]\nnormal = [1.0, -0.3, 0.0]\nsize = [0.6, 0.6]\n\
         [[object]]\nprimitive = \"box\"\nsize = [8.0, 3.0, 8.0]\ntranslate = [0.0, 1.5, 0.0]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"box\"\nsize = [0.8, 1.0, 0.8]\ntranslate = [-1.5, 0.5, -0.5]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"sphere\"\nsize = [0.4]\ntranslate = [0.5, 0.4, -1.5]\nrole = \"both\"\n",
    );
    // Tilted quads, one through the light's plane and one reaching below the ground's points'
    // planes, and a ball cut by the light's plane.
    let crossing = ssm_testing::scene_from_manifest(
        "[camera]\nposition = [0.0, 5.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[light]]\ncentre = [0.0, 3.0, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [1.5, 1.5]\n\
         [[object]]\nprimitive = \"plane\"\nsize = [10.0, 10.0]\nrole = \"receiver\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [1.0, 1.0]\nrotate_degrees = [0.0, 0.0, 70.0]\ntranslate = [0.4, 2.8, 0.0]\nrole = \"occluder\"\n\
         [[object]]\nprimitive = \"plane\"\nsize = [2.0, 0.6]\nrotate_degrees = [40.0, 0.0, 0.0]\ntranslate = [-1.0, 0.2, 0.8]\nrole = \"both\"\n\
         [[object]]\nprimitive = \"sphere\"\nsize = [0.3]\ntranslate = [-0.3, 3.1, -0.2]\nrole = \"both\"\n",
    );
    // (name, scene, the least share of the penumbra the pieces must decide exactly).
    let scenes = [
        ("contact", builtin("contact").unwrap().build(), 0.5),
        ("leaves", builtin("leaves").unwrap().build(), 0.5),
        ("sphere-cube", builtin("sphere-cube").unwrap().build(), 0.5),
        ("a box room lit from a wall", room, 0.5),
        ("quads and a ball crossing planes", crossing, 0.5),
        // Trees merged into one mesh each: the trunk and every leaf card a convex part; under a
        // crown, more cards than the pieces are projected for.
        ("forest", builtin("forest").unwrap().build(), 0.2),
    ];
    for (name, scene, least_exact) in scenes {
        let points = {
            let needs = ssm_core::Requirements { gbuffer: true, ..ssm_core::Requirements::NONE };
            let renderer = ssm_core::Renderer::new(&gpu, &scene, 80, 60, &needs).unwrap();
            ssm_core::reference::surface_points(
                &renderer.read_positions().unwrap(),
                &renderer.read_normals().unwrap(),
                &renderer.scene.camera,
                false,
            )
        };
        let light = &scene.lights[0];
        let truth = GroundTruth::new(&scene);
        assert!(truth.convex_piece_count() > 0, "{name}: no convex pieces");
        let exact = truth.trace(light, &points, Sampling::DEFAULT, 11);
        let rays =
            GroundTruth::new(&scene).with_convex_pieces(false).trace(light, &points, Sampling { samples_per_axis: 32, refine: 4 }, 12);
        let (mut difference, mut noise, mut penumbra, mut noiseless, mut worst) = (0.0f64, 0.0f64, 0usize, 0usize, (0.0f32, 0usize));
        for index in 0..points.len() {
            let (a, b) = (exact.visibility[index], rays.visibility[index]);
            if (a - b).abs() > worst.0 {
                worst = ((a - b).abs(), index);
            }
            if a > 0.0 && a < 1.0 || b > 0.0 && b < 1.0 {
                difference += f64::from((a - b).abs());
                noise += f64::from(exact.noise[index] + rays.noise[index]);
                penumbra += 1;
                noiseless += usize::from(exact.noise[index] == 0.0);
            }
        }
        println!(
            "{name}: mean difference {:.5} against a noise of {:.5} over {penumbra} penumbra pixels, {noiseless} of them exact; \
             worst pixel {} by {:.4} ({} against {})",
            difference / penumbra as f64,
            noise / penumbra as f64,
            worst.1,
            worst.0,
            exact.visibility[worst.1],
            rays.visibility[worst.1]
        );
        assert!(penumbra > 100, "{name}: too little penumbra ({penumbra} pixels) to compare");
        assert!(worst.0 < 0.02, "{name}: pixel {} differs by {}", worst.1, worst.0);
        assert!(difference <= 1.5 * noise + 1e-4 * penumbra as f64, "{name}: mean difference {difference} beyond the noise {noise}");
        assert!(
            noiseless as f64 > least_exact * penumbra as f64,
            "{name}: the pieces decide only {noiseless} of {penumbra} penumbra pixels exactly"
        );
    }
}
