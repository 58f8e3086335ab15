//! Atty's counted work (`--count-work`, issue #40) against counts made by hand on
//! `parallel-square`, where every quantity is known: the occluder square's texels in the
//! occluder map, the pyramids' sizes, and which pixels show the receiver. Conventions
//! (`shaders/atty/atty_counts.wgsl`): a textureLoad is one texel read, which fetches its format's
//! texel size (bytes read: the G-buffer's Rgba32Float 16; the occluder map's and the plain receiver
//! map's R32Float 4, the receiver planes' Rgba32Float 16; the receiver bounds' R32Float 4, the merge
//! pyramid's Rg32Float 8; the soft shadow maps' R32Float 4, or R16Float 2 with f16 accumulation), a
//! storage-texture store its format's texel size, a listed micro-patch one atomic and a 32-byte
//! record.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_core::LightFrame;
use ssm_core::work::{FrameWork, PassWork};
use ssm_scene::builtin;
use ssm_testing::{Rendered, gpu, render};

const SIZE: (u32, u32) = (96, 72);

/// Renders `atty` with `settings` on parallel-square and counts one frame's work.
fn counted(settings: &[(&str, &str)]) -> (Rendered, FrameWork) {
    let scene = builtin("parallel-square").unwrap().build();
    let mut rendered = render(&gpu(), &scene, &ssm_atty::INFO, settings, SIZE.0, SIZE.1).unwrap();
    let params = ssm_atty::INFO.params_from(settings.iter().copied()).unwrap();
    let work = rendered.renderer.count_work(&ssm_atty::INFO, &params).unwrap();
    println!("{}", work.passes_column());
    assert!(work.shader_counts && work.pipeline_statistics, "atty counts in its shaders, and lavapipe has pipeline statistics");
    // Every pass that reads counts the bytes it read, so the frame's bytes read are known
    // (ssm-bench's Totals::read_bytes: only where every reading pass counts them).
    for p in work.passes.iter().filter(|p| p.texel_reads > 0) {
        assert!(p.read_bytes > 0, "{} reads {} texels and counts no bytes", p.name, p.texel_reads);
    }
    (rendered, work)
}

/// One frame's work in the paper's mode (one micro-patch per occluder texel, the receiver's depth
/// alone, rectangles to the far plane) with an `n`² occluder map and an `s`² soft shadow map.
fn counted_paper_mode(n: u32, s: u32) -> FrameWork {
    let (n, s) = (n.to_string(), s.to_string());
    counted(&[
        ("occluder_map_size", &n),
        ("ssm_size", &s),
        ("merge_tolerance", "0"),
        ("receiver_plane", "false"),
        ("penumbra_bound", "far_plane"),
    ])
    .1
}

fn pass<'a>(work: &'a FrameWork, name: &str) -> &'a PassWork {
    work.passes.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no {name} in {}", work.passes_column()))
}

/// Parallel-square's light frame: (its half-angle tangent, the same along u and v; its far depth).
fn parallel_square_frame() -> (f32, f32) {
    let scene = builtin("parallel-square").unwrap().build();
    let frame = LightFrame::fit(&scene.lights[0], &scene.bounds());
    (frame.tan_half.x, frame.far)
}

/// The ndc of the centres of texels 0..`n` of a map along one axis.
fn texel_centres(n: u32) -> impl Iterator<Item = f32> {
    (0..n).map(move |t| (t as f32 + 0.5) / n as f32 * 2.0 - 1.0)
}

/// The centres of `n` texels per axis inside [low, high]: what the rasteriser covers along one
/// axis of an axis-aligned rectangle (a texel is covered by its centre). Panics when a centre lies
/// within 1e-4 ndc of an edge, where rounding could go either way: the cases avoid them.
fn covered_texels(n: u32, (low, high): (f32, f32)) -> u64 {
    texel_centres(n)
        .filter(|c| {
            assert!((c - low).abs() > 1e-4 && (c - high).abs() > 1e-4, "a texel centre {c} on an edge of [{low}, {high}]");
            low < *c && *c < high
        })
        .count() as u64
}

/// The occluder texels along one axis of an `n`² occluder map: parallel-square's occluder is a
/// unit square at depth 2 under the light's centre, so |ndc| < 0.5 / (2 tan).
fn occluder_centres(n: u32) -> Vec<f32> {
    let (tan_half, _) = parallel_square_frame();
    let half = 0.5 / (2.0 * tan_half);
    texel_centres(n).filter(|c| c.abs() < half).collect()
}

/// Texels of an `n`² occluder map on the occluder.
fn occluder_texels(n: u32) -> u64 {
    (occluder_centres(n).len() as u64).pow(2)
}

/// The accumulation's fragments by hand, in the paper's mode: one micro-patch per occluder texel
/// at depth 2, of half size 2·tan/n, whose penumbra rectangle on the `s`² soft shadow map is
/// centred on the texel with the half extent of Sec. 3.3 at the far plane
/// (`ssm_atty::geometry::penumbra_half_ndc`, the shader's twin); a rectangle's fragments are the
/// product of its texels along each axis, so the total is the square of one axis's sum (the map
/// is symmetric about the light's centre, so the accumulation's flip of rows changes nothing).
fn accumulation_fragments(n: u32, s: u32) -> u64 {
    let (tan_half, far) = parallel_square_frame();
    let tan = glam::Vec2::splat(tan_half);
    let patch = |centre: f32| ssm_atty::geometry::MicroPatch {
        centre: glam::Vec2::splat(centre * 2.0 * tan_half),
        half_size: glam::Vec2::splat(2.0 * tan_half / n as f32),
        depth: 2.0,
    };
    let per_axis: u64 = occluder_centres(n)
        .iter()
        .map(|c| {
            let half = ssm_atty::geometry::penumbra_half_ndc(glam::Vec2::splat(0.5), tan, &patch(*c), far).x;
            covered_texels(s, (c - half, c + half))
        })
        .sum();
    per_axis * per_axis
}

/// Invocations of a pyramid's reduce levels over an `n`² map (`n` a power of two): each level
/// halves the side, down to 1.
fn reduce_texels(n: u32) -> u64 {
    (1..u32::BITS - n.leading_zeros()).map(|level| u64::from(n >> level).pow(2)).sum()
}

/// The paper's mode (no merging, no receiver planes, rectangles to the far plane): the list pass
/// reads one occluder texel per texel and lists one patch per occluder texel, which the
/// accumulation draws as a 4-vertex strip (two primitives, by the pipeline statistics: a count
/// independent of the shader's) covering its penumbra rectangle ([`accumulation_fragments`]);
/// each accumulation fragment reads one receiver texel; every read here is of an R32Float texel, 4
/// bytes (the occluder map, the plain receiver map). (lavapipe's pipeline statistics count
/// more fragment invocations than that, 4,352 against 1,024 here: it counts helper invocations of
/// partly covered quads, many for rectangles a few texels wide.)
#[test]
fn the_paper_mode_lists_one_patch_per_occluder_texel_and_reads_one_texel_per_fragment() {
    let (n, s) = (50, 64);
    let work = counted_paper_mode(n, s);
    let texels = occluder_texels(n);
    assert!(texels > 0 && texels < u64::from(n * n), "{texels} occluder texels of {}", n * n);
    let patches = pass(&work, "atty_accumulate_patches");
    assert_eq!(patches.counted_invocations, u64::from(n * n), "one invocation per occluder-map texel");
    assert_eq!(patches.texel_reads, u64::from(n * n), "each reads its own texel only");
    assert_eq!(patches.read_bytes, 4 * u64::from(n * n), "an R32Float texel each");
    assert_eq!((patches.atomics, patches.storage_bytes), (texels, 32 * texels), "one patch per occluder texel");
    let accumulate = pass(&work, "atty_accumulate");
    assert_eq!((accumulate.primitives, accumulate.vertex_invocations), (2 * texels, 4 * texels), "one strip per patch");
    let fragments = accumulation_fragments(n, s);
    assert_eq!((accumulate.counted_invocations, accumulate.texel_reads), (fragments, fragments), "one receiver texel per fragment");
    assert_eq!(accumulate.read_bytes, 4 * fragments, "the receiver map's R32Float texels");
    assert!(fragments <= accumulate.fragment_invocations, "the pipeline statistics count helper invocations too");
    for unbuilt in ["atty_patch_merge", "atty_receiver_bounds"] {
        assert!(work.passes.iter().all(|p| p.name != unbuilt), "{unbuilt} does not run in this mode");
    }
}

/// The default mode with the penumbra bounded by the receivers, both maps powers of two: each
/// pyramid's base reads one texel and stores one per texel, each reduce level four and one; the
/// projection reads the G-buffer's two texels at every pixel, and at each pixel showing the
/// receiver (none left to the shared rules here: nothing is closed, everything is in front of the
/// light and inside its frame, and no receiver lies behind another) one receiver-map texel for
/// the hidden test and, for each of the four bilinear texels, its plane and both soft shadow maps.
/// In bytes: the merge pyramid's base reads the occluder map (R32Float, 4) and its reduce levels
/// Rg32Float texels (8); the bounds' base reads the receiver planes (Rgba32Float, 16) and its reduce
/// levels R32Float texels (4); the projection's P pixels 2·16 and its R receiver pixels 16 + 4·(16 +
/// 2·4) with f32 soft shadow maps: 32·P + 112·R; each accumulation fragment one plane, 16.
#[test]
fn the_pyramids_and_the_projection_read_what_their_sizes_and_the_receiver_pixels_say() {
    let (n, s) = (64u32, 128u32);
    let (rendered, work) = counted(&[("occluder_map_size", &n.to_string()), ("ssm_size", &s.to_string()), ("penumbra_bound", "receivers")]);
    let merge = pass(&work, "atty_patch_merge");
    let merge_texels = u64::from(n * n) + reduce_texels(n);
    assert_eq!(merge.counted_invocations, merge_texels);
    assert_eq!(merge.texel_reads, u64::from(n * n) + 4 * reduce_texels(n));
    assert_eq!(merge.storage_bytes, 8 * merge_texels, "one Rg32Float texel per pyramid texel");
    assert_eq!(merge.read_bytes, 4 * u64::from(n * n) + 8 * 4 * reduce_texels(n));
    let bounds = pass(&work, "atty_receiver_bounds");
    let bounds_texels = u64::from(s * s) + reduce_texels(s);
    assert_eq!(bounds.counted_invocations, bounds_texels);
    assert_eq!(bounds.texel_reads, u64::from(s * s) + 4 * reduce_texels(s));
    assert_eq!(bounds.storage_bytes, 4 * bounds_texels, "one R32Float texel per pyramid texel");
    assert_eq!(bounds.read_bytes, 16 * u64::from(s * s) + 4 * 4 * reduce_texels(s), "planes at the base");

    let pixels = u64::from(SIZE.0 * SIZE.1);
    let receiver_pixels =
        rendered.coverage().iter().zip(rendered.receivers()).filter(|(covered, receives)| **covered && *receives).count() as u64;
    assert!(receiver_pixels > 0 && receiver_pixels < pixels, "{receiver_pixels} receiver pixels of {pixels}");
    let project = pass(&work, "atty_project");
    assert_eq!(project.counted_invocations, pixels);
    assert_eq!(project.texel_reads, 2 * pixels + (1 + 4 * 3) * receiver_pixels);
    assert_eq!(project.read_bytes, 2 * 16 * pixels + (16 + 4 * (16 + 2 * 4)) * receiver_pixels);
    assert_eq!((project.atomics, project.storage_bytes), (0, 0), "the projection writes its render target only");

    // Merged patches are fewer than the occluder's texels, and still one strip each.
    let patches = pass(&work, "atty_accumulate_patches");
    let listed = patches.atomics;
    assert!(listed > 0 && listed < occluder_texels(n), "{listed} merged patches for {} texels", occluder_texels(n));
    let accumulate = pass(&work, "atty_accumulate");
    assert_eq!(accumulate.primitives, 2 * listed);
    assert_eq!(accumulate.read_bytes, 16 * accumulate.texel_reads, "one receiver plane per fragment");
}

/// The bytes follow the formats the settings choose. With f16 accumulation the projection reads
/// R16Float soft shadow maps (2 bytes a texel): 32·P + (16 + 4·(16 + 2·2))·R. Without receiver
/// planes the receiver map is R32Float: the bounds' base reads 4 bytes a texel, each accumulation
/// fragment 4, and the projection at a receiver pixel its receiver texel and, for each soft shadow
/// map, four receiver texels and four soft shadow texels (and one more soft shadow texel where no
/// receiver texel of the four is the point's): 32·P + (4 + 2·4·(4 + 2))·R + 2·(reads − 2P − 17·R).
#[test]
fn the_bytes_follow_the_formats_the_settings_choose() {
    let (n, s) = (64u32, 128u32);
    let sizes = [("occluder_map_size", n.to_string()), ("ssm_size", s.to_string())];
    let with = |more: &[(&str, &str)]| {
        let mut settings: Vec<(&str, &str)> = sizes.iter().map(|(k, v)| (*k, v.as_str())).collect();
        settings.extend_from_slice(more);
        counted(&settings)
    };
    let (rendered, f16) = with(&[("accumulation", "f16")]);
    let pixels = u64::from(SIZE.0 * SIZE.1);
    let receiver_pixels =
        rendered.coverage().iter().zip(rendered.receivers()).filter(|(covered, receives)| **covered && *receives).count() as u64;
    let project = pass(&f16, "atty_project");
    assert_eq!(project.texel_reads, 2 * pixels + 13 * receiver_pixels);
    assert_eq!(project.read_bytes, 2 * 16 * pixels + (16 + 4 * (16 + 2 * 2)) * receiver_pixels, "R16Float soft shadow maps");

    let (_, depth) = with(&[("accumulation", "f16"), ("receiver_plane", "false"), ("penumbra_bound", "receivers")]);
    let bounds = pass(&depth, "atty_receiver_bounds");
    assert_eq!(bounds.read_bytes, 4 * u64::from(s * s) + 4 * 4 * reduce_texels(s), "an R32Float receiver map");
    let accumulate = pass(&depth, "atty_accumulate");
    assert_eq!(accumulate.read_bytes, 4 * accumulate.texel_reads);
    let project = pass(&depth, "atty_project");
    let fallbacks = project.texel_reads - 2 * pixels - 17 * receiver_pixels;
    assert!(fallbacks <= 2 * receiver_pixels, "{fallbacks} fallback reads");
    assert_eq!(project.read_bytes, 2 * 16 * pixels + (4 + 2 * 4 * (4 + 2)) * receiver_pixels + 2 * fallbacks);
}

/// Two-sided (Sec. 3.5): each side has its own list, accumulation and merge pyramid, counted
/// under its own pass; the one-sided names do not appear.
#[test]
fn two_sided_counts_each_side_under_its_own_passes() {
    let (_, work) = counted(&[("occluder_map_size", "64"), ("ssm_size", "64"), ("two_sided", "true")]);
    for side in ["front", "back"] {
        let patches = pass(&work, &format!("atty_accumulate_{side}_patches"));
        assert_eq!(patches.counted_invocations, 64 * 64, "{side}");
        let accumulate = pass(&work, &format!("atty_accumulate_{side}"));
        assert_eq!(accumulate.primitives, 2 * patches.atomics, "{side}: one strip per listed patch");
        assert_eq!(accumulate.texel_reads, accumulate.counted_invocations, "{side}");
    }
    assert_eq!(pass(&work, "atty_patch_merge_back").counted_invocations, 64 * 64 + reduce_texels(64));
    assert!(work.passes.iter().all(|p| p.name != "atty_accumulate" && p.name != "atty_accumulate_patches"));
}

/// Fig. 17's trade in work (Sec. 6.1: the accumulation's cost is the occluder's texels times the
/// texels of each one's penumbra extent): in the paper's mode each micro-patch's rectangle has the
/// half extent 1/n + l(1/z_P − 1/z_R)/tan in ndc (Sec. 3.3 with a patch half size z_P·tan/n), so
/// as the occluder map grows each patch covers fewer fragments, falling towards the footprint of
/// a point occluder, while the patches grow as n² and the accumulation's fragments with them.
#[test]
fn fragments_per_micro_patch_fall_towards_a_point_occluders_footprint_as_the_map_grows() {
    let s = 256u32;
    let (tan_half, far) = parallel_square_frame();
    // The point occluder's rectangle, 2·l(1/z_P − 1/z_R)/tan ndc wide, in texels of the SSM (2/s ndc each).
    let point_width = 2.0 * 0.5 * (1.0 / 2.0 - 1.0 / far) / tan_half * s as f32 / 2.0;
    let mut per_patch = Vec::new();
    let mut totals = Vec::new();
    for n in [40u32, 80, 160] {
        let work = counted_paper_mode(n, s);
        let patches = pass(&work, "atty_accumulate_patches").atomics;
        let fragments = pass(&work, "atty_accumulate").counted_invocations;
        println!("n = {n}: {patches} patches, {fragments} fragments, {:.1} per patch", fragments as f64 / patches as f64);
        per_patch.push(fragments as f64 / patches as f64);
        totals.push(fragments);
    }
    let floor = f64::from(point_width.floor()).powi(2);
    assert!(per_patch.windows(2).all(|w| w[1] < w[0]), "fragments per patch fall as n grows: {per_patch:?}");
    assert!(per_patch[2] >= floor, "no patch covers less than a point occluder's {floor} texels: {per_patch:?}");
    assert!(totals.windows(2).all(|w| w[1] > 3 * w[0]), "the accumulation's fragments grow about as n²: {totals:?}");
}
