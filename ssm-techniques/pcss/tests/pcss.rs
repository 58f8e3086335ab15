//! `pcss` on the analytic case, against `hard` (its limit with a point light)
//! and the ground truth, with and without the receiver plane.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::Vec3;
use ssm_scene::builtin;
use ssm_testing::{at, error_against_reference, gpu, parallel_square_exact, pixel_of, render};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

#[test]
fn parallel_square_umbra_and_lit_region() {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let rendered = render(&gpu, &scene, &ssm_pcss::INFO, &[], WIDTH, HEIGHT).unwrap();
    let umbra = at(&rendered, pixel_of(&scene, WIDTH, HEIGHT, Vec3::ZERO));
    let lit = at(&rendered, pixel_of(&scene, WIDTH, HEIGHT, Vec3::new(2.5, 0.0, 0.0)));
    assert!(umbra < 0.05, "umbra centre reads {umbra}");
    assert!(lit > 0.95, "lit receiver reads {lit}");
}

#[test]
fn pcss_follows_the_analytic_penumbra_and_hard_does_not() {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let hard = render(&gpu, &scene, &ssm_hard::INFO, &[], WIDTH, HEIGHT).unwrap();
    let pcss = render(&gpu, &scene, &ssm_pcss::INFO, &[("pcf_kernel", "24"), ("blocker_kernel", "12")], WIDTH, HEIGHT).unwrap();
    // Along the x axis through the penumbra: the exact visibility rises from 0 at x = 0.5 to 1 at x = 1.5.
    let (mut hard_error, mut pcss_error, mut samples) = (0.0, 0.0, 0);
    for step in 0..=20 {
        let x = 0.5 + step as f32 * 0.05;
        let pixel = pixel_of(&scene, WIDTH, HEIGHT, Vec3::new(x, 0.0, 0.0));
        let exact = parallel_square_exact(x, 0.0);
        hard_error += (at(&hard, pixel) - exact).abs();
        pcss_error += (at(&pcss, pixel) - exact).abs();
        samples += 1;
    }
    let (hard_error, pcss_error) = (hard_error / samples as f32, pcss_error / samples as f32);
    // Hard shadows are off by 0.25 on average across a linear ramp; PCSS on parallel planes is close to exact,
    // up to the pixel footprint (about 0.05 world units here) and the regular-grid quantisation.
    assert!(pcss_error < 0.08, "pcss penumbra error {pcss_error}");
    assert!(pcss_error < hard_error * 0.5, "pcss {pcss_error} vs hard {hard_error}");
    // Half-way through the penumbra, half the light is visible.
    let middle = at(&pcss, pixel_of(&scene, WIDTH, HEIGHT, Vec3::new(1.0, 0.0, 0.0)));
    assert!((middle - 0.5).abs() < 0.1, "pcss at the middle of the penumbra reads {middle}");
}

#[test]
fn pcss_has_lower_penumbra_error_than_hard_on_parallel_square() {
    let scene = builtin("parallel-square").unwrap().build();
    let hard = error_against_reference(&scene, &ssm_hard::INFO, &[], 16, (128, 96));
    let pcss = error_against_reference(&scene, &ssm_pcss::INFO, &[], 16, (128, 96));
    println!("parallel-square: hard mae_penumbra {:.4}, pcss {:.4}", hard.mae_penumbra, pcss.mae_penumbra);
    assert!(pcss.mae_penumbra < hard.mae_penumbra * 0.6, "pcss {} vs hard {}", pcss.mae_penumbra, hard.mae_penumbra);
    assert!(pcss.ssim > hard.ssim);
}

#[test]
fn every_builtin_scene_casts_a_shadow_on_a_lit_receiver() {
    ssm_testing::every_builtin_scene_casts_a_shadow(&gpu(), &ssm_pcss::INFO, WIDTH, HEIGHT);
}

#[test]
fn the_receiver_plane_test_removes_self_shadowing_at_grazing_light() {
    // A light 12 units to the side, 0.25 above a bare receiver: nothing occludes it.
    let gpu = gpu();
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.instances.retain(|i| i.name == "ground");
    scene.lights[0] =
        ssm_scene::RectLight::try_facing(Vec3::new(-12.0, 0.25, 0.0), Vec3::new(1.0, -0.02, 0.0), Vec3::Z, glam::Vec2::ONE, 1.0).unwrap();
    let lit_share = |settings: &[(&str, &str)]| {
        let rendered = render(&gpu, &scene, &ssm_pcss::INFO, settings, WIDTH, HEIGHT).unwrap();
        let covered = rendered.covered_visibility();
        covered.iter().filter(|v| **v > 0.95).count() as f32 / covered.len() as f32
    };
    let with_plane = lit_share(&[]);
    let without_plane = lit_share(&[("receiver_plane", "false")]);
    assert!(with_plane > 0.99, "with the receiver plane, {:.1}% of the bare receiver reads lit", with_plane * 100.0);
    assert!(without_plane < 0.9, "without it, the receiver shadows itself: {:.1}% lit", without_plane * 100.0);
}

/// With a point light the blocker search and the filter have no extent, so PCSS reduces to `hard`
/// (the README's claim): on every built-in scene with its light shrunk to a point, at the same
/// map size, bias and normal offset, the two give the same pixels to the bit. Its soft shadows
/// are checked against the exact penumbra of `parallel-square` above and against the ground
/// truth by the extremes matrix (tests/extremes.rs); this replaces blessed images, which only said
/// that the output had not changed.
#[test]
fn with_a_point_light_pcss_is_hard_on_every_builtin_scene() {
    let gpu = gpu();
    for entry in ssm_scene::BUILTIN_SCENES {
        let mut scene = entry.build();
        for light in &mut scene.lights {
            light.half_size = glam::Vec2::ZERO;
        }
        let hard = render(&gpu, &scene, &ssm_hard::INFO, &[("shadow_map_size", "1024")], 128, 96).unwrap();
        let pcss = render(&gpu, &scene, &ssm_pcss::INFO, &[], 128, 96).unwrap();
        let differing = hard.visibility.iter().zip(&pcss.visibility).filter(|(a, b)| a != b).count();
        let shadowed = hard.visibility.iter().filter(|v| **v == 0.0).count();
        println!("{}: {differing} pixels differ, {shadowed} in shadow", entry.name);
        assert!(shadowed > 50, "{}: too little shadow to compare", entry.name);
        assert_eq!(differing, 0, "{}: {differing} pixels differ from hard's", entry.name);
    }
}

/// A case of the test below: its name, scene, settings and the range of the share of tiled workgroups.
type TileCase = (&'static str, ssm_scene::Scene, &'static [(&'static str, &'static str)], (f64, f64));

/// `tap_source = workgroup_tile` reads every tap's texel from the workgroup's shared tile where
/// the union of its pixels' windows fits, else from the shadow map: the same texels as the
/// fragment pass, so the same pixels. Cases where the tiles fit (a small light; a coarse map) and
/// where they do not (leaves' large windows), at Table 4's smallest and largest kernels.
#[test]
fn workgroup_tiles_give_the_fragment_passes_pixels() {
    use ssm_core::Renderer;
    let gpu = gpu();
    let mut small_light = builtin("parallel-square").unwrap().build();
    small_light.lights[0].half_size *= 0.1;
    let cases: [TileCase; 4] = [
        ("small light", small_light, &[], (0.9, 1.0)),
        (
            "coarse map, 29/41",
            builtin("floating-sphere").unwrap().build(),
            &[("shadow_map_size", "64"), ("blocker_kernel", "29"), ("pcf_kernel", "41")],
            (0.9, 1.0),
        ),
        ("leaves 7/15", builtin("leaves").unwrap().build(), &[], (0.0, 0.5)),
        ("leaves 29/41", builtin("leaves").unwrap().build(), &[("blocker_kernel", "29"), ("pcf_kernel", "41")], (0.0, 0.5)),
    ];
    for (name, scene, settings, (low, high)) in cases {
        let with = |source: &'static str| {
            let mut all = settings.to_vec();
            all.push(("tap_source", source));
            let info = &ssm_pcss::INFO;
            let params = info.params_from(all.iter().copied()).unwrap();
            let needs = (info.requirements)(&params).unwrap();
            let mut renderer = Renderer::new(&gpu, &scene, WIDTH, HEIGHT, &needs).unwrap();
            let mut technique = renderer.create_technique(info, &params).unwrap();
            renderer.render(technique.as_mut(), info.name).unwrap();
            (renderer.read_visibility(0, info.name).unwrap(), technique.diagnostics(&renderer.gpu))
        };
        let ((tiled, diagnostics), (fragment, _)) = (with("workgroup_tile"), with("texture"));
        let share = diagnostics.iter().find(|(k, _)| k == "pcss_tiled_share").map(|(_, v)| *v).expect("no pcss_tiled_share");
        let largest = tiled.iter().zip(&fragment).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        let shadowed = fragment.iter().filter(|v| **v < 0.999).count();
        println!(
            "{name}: {:.0}% of workgroups tiled, largest difference {largest:e}, {shadowed} pixels in shadow or penumbra",
            100.0 * share
        );
        assert!(shadowed > 100, "{name}: the case has too little shadow");
        assert!((low..=high).contains(&share), "{name}: {share} of the workgroups tiled, expected {low} to {high}");
        assert_eq!(largest, 0.0, "{name}: the tiled pass differs from the fragment pass by up to {largest}");
    }
}

/// PCSS's texel reads in a counting frame (`--count-work`) against the count by hand, under a
/// point light on `parallel-square` (shaders/pcss/pcss_common.wgsl's convention: a textureLoad is
/// one texel). Every pixel, the background included, is one invocation and reads its two G-buffer
/// texels; every covered pixel computes (no surface is closed and all lie in front of the light,
/// so the shared rules leave none trivial) and reads the n² taps of its blocker search. With the
/// light a point, both extents are zero: every tap reads the pixel's own texel, so a blocker is
/// found exactly where the filter then reads 0 (tap depth below the receiver's, against at or
/// above it), and only those pixels filter, with one tap: a filter narrower than a texel is the
/// texel at the lookup, not m² taps of it. So, with P pixels, C covered and Z covered at
/// visibility 0: 2P + n²C + Z reads, P invocations, exactly. The tiled pass counts the same
/// invocations (its tile's loads, not its taps, are its reads). In bytes, each texel costs its
/// format's size (ssm-core's formats, not the shader's constants): with G the G-buffer's position
/// and normal texels together (`Rgba32Float` each, 32 bytes) and D a shadow-map depth (`R32Float`,
/// 4), G·P + D·(n²C + Z) bytes; in the tiled pass, whose reads past the G-buffer's 2P are all
/// shadow-map texels (taps or the tile's loads), G·P + D·(R − 2P) for its R reads, exactly.
#[test]
fn reads_are_two_gbuffer_texels_per_pixel_and_n2_plus_one_per_shadowed_pixel_under_a_point_light() {
    let (width, height, n) = (96u32, 72u32, 3u64);
    let gpu = gpu();
    let mut scene = builtin("parallel-square").unwrap().build();
    scene.lights[0].half_size = glam::Vec2::ZERO;
    let work_of = |tap_source: &'static str| {
        let settings = [("shadow_map_size", "256"), ("blocker_kernel", "3"), ("pcf_kernel", "5"), ("tap_source", tap_source)];
        let mut rendered = render(&gpu, &scene, &ssm_pcss::INFO, &settings, width, height).unwrap();
        let params = ssm_pcss::INFO.params_from(settings).unwrap();
        let work = rendered.renderer.count_work(&ssm_pcss::INFO, &params).unwrap();
        println!("{tap_source}: {}", work.passes_column());
        assert!(work.shader_counts, "pcss counts its reads");
        let pass = work.passes.iter().find(|p| p.name == "pcss_blocker_search_and_filter").unwrap().clone();
        (rendered, pass)
    };
    let (rendered, texture) = work_of("texture");
    let pixels = u64::from(width * height);
    let coverage = rendered.coverage();
    let covered = coverage.iter().filter(|c| **c).count() as u64;
    let shadowed = rendered.visibility.iter().zip(&coverage).filter(|(v, c)| **c && **v == 0.0).count() as u64;
    println!("{pixels} pixels, {covered} covered, {shadowed} of them in shadow");
    assert!(covered < pixels && shadowed > 0 && shadowed < covered, "the case must have background, lit and shadowed pixels");
    assert_eq!(
        (texture.counted_invocations, texture.texel_reads),
        (pixels, 2 * pixels + n * n * covered + shadowed),
        "(invocations, texel reads)"
    );
    let (gbuffer, depth) = texel_bytes();
    assert_eq!(texture.read_bytes, gbuffer * pixels + depth * (n * n * covered + shadowed), "bytes read");
    let (_, tiled) = work_of("workgroup_tile");
    assert_eq!(tiled.counted_invocations, pixels, "the tiled pass counts the screen's pixels, not its workgroups' threads");
    assert!(tiled.texel_reads > 2 * pixels, "the G-buffer's texels and the tiles' loads: {}", tiled.texel_reads);
    assert_eq!(tiled.read_bytes, gbuffer * pixels + depth * (tiled.texel_reads - 2 * pixels), "tiled: bytes read");
}

/// The bytes of one texel of the G-buffer's position and normal together, and of a light depth
/// map's (the shadow map's, a side face's), from ssm-core's formats.
fn texel_bytes() -> (u64, u64) {
    let size = |format: Option<u32>| u64::from(format.expect("a format with a texel size"));
    let gbuffer =
        size(ssm_core::GBuffer::POSITION_FORMAT.block_copy_size(None)) + size(ssm_core::GBuffer::NORMAL_FORMAT.block_copy_size(None));
    (gbuffer, size(ssm_core::LightDepthMap::FORMAT.block_copy_size(None)))
}

/// The side-faces pass (`pcss_side_faces`, past the light frame's widest angle: a light resting on
/// the floor) counts its reads' bytes as the frame's pass does: each of its P invocations (one per
/// pixel of the screen) reads the G-buffer's two texels, G bytes together, and each of its other
/// reads is a tap of a face's `R32Float` map, D bytes: G·P + D·(R − 2P) for its R reads, exactly.
/// Every pass that reads counts its bytes, the framework's after pcss's included.
#[test]
fn the_side_faces_count_the_bytes_of_their_reads() {
    let (width, height) = (96u32, 72u32);
    let scene = ssm_testing::scene_from_manifest(
        "[camera]\nposition = [0.0, 4.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[light]]\ncentre = [0.0, 0.01, 0.0]\nnormal = [0.0, -1.0, 0.0]\nsize = [1.0, 1.0]\n\
         [[object]]\nprimitive = \"plane\"\nsize = [10.0, 10.0]\nrole = \"receiver\"\n\
         [[object]]\nprimitive = \"box\"\nsize = [0.4, 0.4, 0.4]\ntranslate = [1.5, 0.2, 0.0]\nrole = \"both\"\n",
    );
    let settings = [("shadow_map_size", "256"), ("blocker_kernel", "3"), ("pcf_kernel", "5")];
    let gpu = gpu();
    let mut rendered = render(&gpu, &scene, &ssm_pcss::INFO, &settings, width, height).unwrap();
    let params = ssm_pcss::INFO.params_from(settings).unwrap();
    let work = rendered.renderer.count_work(&ssm_pcss::INFO, &params).unwrap();
    println!("{}", work.passes_column());
    let pixels = u64::from(width * height);
    let (gbuffer, depth) = texel_bytes();
    let side_faces = work.passes.iter().find(|p| p.name == ssm_pcss::SIDE_FACES_PASS).expect("the case reaches past the frame");
    assert_eq!(side_faces.counted_invocations, pixels);
    assert!(side_faces.texel_reads > 2 * pixels, "no tap of a face: {}", side_faces.texel_reads);
    assert_eq!(side_faces.read_bytes, gbuffer * pixels + depth * (side_faces.texel_reads - 2 * pixels), "side faces: bytes read");
    let reading: Vec<_> = work.passes.iter().filter(|pass| pass.texel_reads > 0).collect();
    assert!(reading.len() >= 2, "the frame's pass and the side faces' read");
    for pass in reading {
        assert!(pass.read_bytes > 0, "{} reads {} texels and counts no bytes", pass.name, pass.texel_reads);
    }
}
