//! `multi-sm` converges to the ground truth as K grows.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_scene::builtin;
use ssm_testing::error_against_reference;

#[test]
fn the_error_falls_as_k_grows() {
    let scene = builtin("sphere-cube").unwrap().build();
    let errors: Vec<f64> = ["1", "4", "16", "64"]
        .iter()
        .map(|k| {
            let m = error_against_reference(&scene, &ssm_multi_sm::INFO, &[("samples", k)], 16, (128, 96));
            println!("multi-sm K = {k}: mae_penumbra {:.4}, rmse {:.4}, ssim {:.4}", m.mae_penumbra, m.rmse, m.ssim);
            m.mae_penumbra
        })
        .collect();
    for pair in errors.windows(2) {
        assert!(pair[1] < pair[0], "the error must fall with K: {errors:?}");
    }
    // From one map (a hard shadow) to 64 the penumbra error falls several-fold.
    assert!(errors[3] < errors[0] / 3.0, "{errors:?}");
}

#[test]
fn samples_must_be_a_perfect_square() {
    let scene = builtin("parallel-square").unwrap().build();
    let error = ssm_testing::render(&ssm_testing::gpu(), &scene, &ssm_multi_sm::INFO, &[("samples", "5")], 32, 24).err().unwrap();
    assert!(error.to_string().contains("perfect square"), "{error}");
}

/// On `parallel-square` (light, occluder and receiver parallel) K maps from the centres of a √K×√K
/// grid of strata compute exactly the midpoint rule of the light's visibility: from a receiver
/// point (x, 0, z), the sample at (u, 4, v) of the light is hidden when the occluder [-0.5, 0.5]²
/// at height 2 covers the segment's midpoint, |x + u| ≤ 1 and |z + v| ≤ 1, so the visibility is
/// 1 − a_K(x)·b_K(z) with a_K(x) the share of the √K sample columns u_i with |x + u_i| ≤ 1.
/// Rendered and computed here at each penumbra pixel's point, the two differ only where a pixel's
/// point lies within a texel (1024² over the light frame) or the normal offset of a step: the
/// mean difference over the penumbra stays below 0.01 (measured 0.003; with the samples at the
/// strata's corners instead of their centres, 0.23 at K = 4).
#[test]
fn on_parallel_planes_k_maps_compute_the_midpoint_rule() {
    let gpu = ssm_testing::gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let light = scene.lights[0];
    for k in [4u32, 16, 64] {
        let rendered = ssm_testing::render(&gpu, &scene, &ssm_multi_sm::INFO, &[("samples", &k.to_string())], 160, 120).unwrap();
        let n = f64::from(k).sqrt() as u32;
        let hidden_share = |c: f32| {
            let columns = (0..n).filter(|i| {
                let u = ((f64::from(*i) + 0.5) / f64::from(n) * 2.0 - 1.0) * f64::from(light.half_size.x);
                (f64::from(c) + u).abs() <= 1.0
            });
            columns.count() as f32 / n as f32
        };
        let positions = rendered.renderer.read_positions().unwrap();
        let exact = rendered.parallel_square_exact();
        let penumbra = ssm_testing::penumbra_mask(&exact);
        let midpoint: Vec<f32> = positions
            .iter()
            .map(|p| if p[3] > 0.5 && p[1].abs() < 1e-3 { 1.0 - hidden_share(p[0]) * hidden_share(p[2]) } else { 1.0 })
            .collect();
        let difference = ssm_testing::mean_abs_difference(&rendered.visibility, &midpoint, &penumbra);
        println!("K = {k}: mean difference from the midpoint rule over the penumbra {difference:.4}");
        assert!(difference < 0.01, "K = {k}: {difference}");
    }
}

/// The accumulation's counts in a counting frame (`--count-work`) against the count by hand
/// (shaders/multi-sm/multi_sm.wgsl's convention: a textureLoad is one texel, an r32float store 4
/// bytes): each of the K dispatches runs one invocation per pixel, which loads its two G-buffer
/// texels and the visibility's running sum, and stores the sum; a covered pixel also loads one
/// shadow-map texel, as none is left to the shared rules on `parallel-square` (no closed mesh,
/// every surface in front of every sample). The K shadow-map passes read no texel. In bytes, each
/// texel costs its format's size (ssm-core's formats, not the shader's constants): with G the
/// G-buffer's position and normal texels together (`Rgba32Float` each, 32 bytes), V the
/// visibility's (`R32Float`, 4) and D a shadow-map depth (`R32Float`, 4), K·((G + V)·P + D·C)
/// bytes read, exactly.
#[test]
fn the_accumulation_counts_k_times_its_reads_and_stores_per_pixel() {
    let (width, height) = (96u32, 72u32);
    let settings = [("samples", "4"), ("shadow_map_size", "256")];
    let gpu = ssm_testing::gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let mut rendered = ssm_testing::render(&gpu, &scene, &ssm_multi_sm::INFO, &settings, width, height).unwrap();
    let pixels = u64::from(width * height);
    let covered = rendered.coverage().iter().filter(|covered| **covered).count() as u64;
    assert!(covered > 0 && covered < pixels, "{covered} of {pixels} pixels covered: the case must have both");
    let params = ssm_multi_sm::INFO.params_from(settings).unwrap();
    let work = rendered.renderer.count_work(&ssm_multi_sm::INFO, &params).unwrap();
    println!("{}", work.passes_column());
    let pass = |name: &str| work.passes.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no {name} in {}", work.passes_column()));
    let accumulate = pass("multi_sm_accumulate");
    let k = 4;
    assert_eq!(accumulate.runs, k, "one dispatch per sample");
    assert_eq!(
        (accumulate.counted_invocations, accumulate.texel_reads, accumulate.storage_bytes),
        (k * pixels, k * (3 * pixels + covered), k * 4 * pixels)
    );
    assert_eq!(accumulate.atomics, 0);
    let size = |format: Option<u32>| u64::from(format.expect("a format with a texel size"));
    let gbuffer =
        size(ssm_core::GBuffer::POSITION_FORMAT.block_copy_size(None)) + size(ssm_core::GBuffer::NORMAL_FORMAT.block_copy_size(None));
    let visibility = size(ssm_core::VISIBILITY_FORMAT.block_copy_size(None));
    let depth = size(ssm_core::LightDepthMap::FORMAT.block_copy_size(None));
    assert_eq!(accumulate.read_bytes, k * ((gbuffer + visibility) * pixels + depth * covered), "bytes read");
    // Every pass of multi-sm's that reads counts its bytes.
    for pass in work.passes.iter().filter(|pass| pass.texel_reads > 0) {
        assert!(pass.read_bytes > 0, "{} reads {} texels and counts no bytes", pass.name, pass.texel_reads);
    }
    assert_eq!(pass("multi_sm_shadow_map").texel_reads, 0);
}

/// On a closed surface whose tangent plane cuts the light, each sample weighs its shadow test by
/// the share of its stratum in front of the plane (exact for a rectangle): on the side faces of a
/// lone box under a large light, which nothing else shadows, multi-sm gives the share of the
/// light in front of each face (`RectLight::share_in_front_of_plane`, the ground truth's answer
/// there) within 0.01 on average over the faces' pixels whose plane cuts the light, at K = 16
/// (measured 0.0000; with each sample deciding its whole stratum, 0.024).
#[test]
fn a_face_whose_plane_cuts_the_light_gets_the_share_in_front() {
    let gpu = ssm_testing::gpu();
    let scene = ssm_testing::scene_from_manifest(
        "[camera]\nposition = [2.5, 1.8, 3.0]\ntarget = [0.0, 0.4, 0.0]\n\
         [[light]]\ncentre = [0.1, 3.0, -0.05]\nnormal = [0.0, -1.0, 0.0]\nsize = [1.6, 1.2]\n\
         [[object]]\nprimitive = \"plane\"\nsize = [10.0, 10.0]\nrole = \"receiver\"\n\
         [[object]]\nprimitive = \"box\"\nsize = [1.0, 0.8, 1.0]\ntranslate = [0.0, 0.4, 0.0]\nrole = \"both\"\n",
    );
    let light = scene.lights[0];
    let rendered = ssm_testing::render(&gpu, &scene, &ssm_multi_sm::INFO, &[("samples", "16")], 160, 120).unwrap();
    let positions = rendered.renderer.read_positions().unwrap();
    let normals = rendered.renderer.read_normals().unwrap();
    let (mut difference, mut count) = (0.0f64, 0usize);
    for ((p, n), visibility) in positions.iter().zip(&normals).zip(&rendered.visibility) {
        let closed = ssm_core::GBuffer::flags(n[3]) & ssm_core::GBuffer::CLOSED != 0;
        let normal = glam::Vec3::new(n[0], n[1], n[2]);
        // The box's side faces (horizontal normals), away from the ground's contact shadow.
        if p[3] < 0.5 || !closed || normal.y.abs() > 0.1 || p[1] < 0.3 {
            continue;
        }
        let share = light.share_in_front_of_plane(glam::Vec3::new(p[0], p[1], p[2]), normal);
        if share > 0.0 && share < 1.0 {
            difference += f64::from((visibility - share).abs());
            count += 1;
        }
    }
    assert!(count > 300, "too few side-face pixels whose plane cuts the light: {count}");
    let difference = difference / count as f64;
    println!("multi-sm, K = 16: mean |visibility − share in front| {difference:.4} over {count} side-face pixels");
    assert!(difference < 0.01, "mean difference {difference} from the share in front");
}
