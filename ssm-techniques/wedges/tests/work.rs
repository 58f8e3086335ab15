//! The wedges' counted work (`--count-work`, issue #40) against counts made by hand on
//! `parallel-square`, whose casting mesh is one open quad, so that every step of the silhouette
//! pass can be followed by hand. Conventions (`shaders/wedges/wedges_counts.wgsl`): a textureLoad or one
//! element of a per-pixel storage array read is one texel read, of its format's or type's bytes,
//! every atomic built-in one atomic, a plain store its type's bytes.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_core::work::{FrameWork, PassWork};
use ssm_scene::builtin;
use ssm_testing::{Rendered, gpu, render};

const SIZE: (u32, u32) = (96, 72);

/// Renders `wedges` with `settings` on parallel-square and counts one frame's work.
fn counted(settings: &[(&str, &str)]) -> (Rendered, FrameWork) {
    let scene = builtin("parallel-square").unwrap().build();
    let mut rendered = render(&gpu(), &scene, &ssm_wedges::INFO, settings, SIZE.0, SIZE.1).unwrap();
    let params = ssm_wedges::INFO.params_from(settings.iter().copied()).unwrap();
    let work = rendered.renderer.count_work(&ssm_wedges::INFO, &params).unwrap();
    println!("{}", work.passes_column());
    assert!(work.shader_counts && work.pipeline_statistics);
    (rendered, work)
}

fn pass<'a>(work: &'a FrameWork, name: &str) -> &'a PassWork {
    work.passes.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no {name} in {}", work.passes_column()))
}

/// The silhouette pass step by hand. parallel-square's casting mesh is its occluder, one open quad
/// (the ground only receives): two faces, five edge records (four boundary edges and the
/// diagonal), one region. Both faces take part (open: two-sided, and no winding number is taken),
/// and the labels settle in two rounds:
/// - reset: 3 atomic stores and 5 per buffer (64 buffers), 4 + 8 u32s and 2 per buffer stored;
/// - classify: per face an atomic label store and a 4-byte state;
/// - round 1: the diagonal joins the two faces (2 loads, a min and a store), each face's jump
///   loads its label and its root's and stores it (3), control 3 atomics (it saw a change) and 2
///   u32s of arguments; round 2: the diagonal's 2 loads, the jumps, control 2 atomics and 2 u32s;
///   14 more controls with nothing to dispatch, 2 atomics and 2 u32s each;
/// - ranking: a label load per face twice (blocks, faces), one block sum, its scan, the region
///   count and the one region's rank stored;
/// - counting and scattering the 4 boundary half-edges (a group load and an add each, twice) and
///   the diagonal (2 label loads, twice); each half-edge's 96-byte wedge record;
/// - caps: per face a group load, an add and a stencil-level add (an open face is not convex),
///   then a group load, an add and a 4-byte face index;
/// - offsets: 2 atomic loads and 18 u32s per buffer, then 3 u32s.
const SILHOUETTE_ATOMICS: u64 =
    (3 + 5 * 64) + 2 + (4 + 2 * 3 + 3) + (2 + 2 * 3 + 2) + 14 * 2 + 2 + 2 + (4 * 2 + 2) * 2 + 2 * 3 + 2 * 2 + 2 * 64;
const SILHOUETTE_STORAGE_BYTES: u64 = (16 + 32 + 8 * 64) + 2 * 4 + 16 * 8 + (4 + 4 + 4 + 4) + 4 * 96 + 2 * 4 + (18 * 4 * 64 + 12);
/// Threads of the silhouette pass, every one of which records once: one workgroup of 256 threads
/// for each dispatch over the faces or the records (winding, classify, two rounds of hook and jump,
/// the three ranking steps, the two counts and the two scatters), one thread for each of reset,
/// the 16 controls and offsets. (lavapipe's pipeline statistics report 32 more compute
/// invocations for the same pass, and 7,681 for the blend's 7,680 threads: not a count to check
/// against.)
const SILHOUETTE_THREADS: u64 = 256 * (2 + 4 + 3 + 2 + 2) + 1 + 16 + 1;

/// The plain penumbra wedges (one buffer), every pass against its count by hand: the depth copy
/// reads the depth and the position at every pixel and the normal at covered ones; the resolve the
/// G-buffer's two texels at every pixel and the final areas at covered ones (none is left to the
/// shared rules on parallel-square: nothing is closed, every surface is in front of the light);
/// the blend runs one thread per pixel for the one buffer and reads at least the shaded count,
/// the umbra mask, the areas and the two pairs of inner maxima; each wedge fragment reads the
/// position, and the normal where a surface covers it; the silhouette pass as
/// [`SILHOUETTE_ATOMICS`] says. The bytes those reads fetched: the G-buffer's depth
/// (Depth32Float) 4, its position and normal (Rgba32Float) 16 each, a final-buffer element
/// (vec4<f32>) 16; the blend's shaded count (R32Float) 4, umbra mask (R8Unorm) 1, parameter
/// targets (Rgba32Float) 16 each and fragment count (u32) 4.
#[test]
fn every_pass_counts_what_the_case_says_by_hand() {
    let (rendered, work) = counted(&[("blending", "none"), ("silhouette_buffers", "1")]);
    let pixels = u64::from(SIZE.0 * SIZE.1);
    let covered = rendered.coverage().iter().filter(|c| **c).count() as u64;
    assert!(covered > 0 && covered < pixels, "{covered} of {pixels}");
    let depth_copy = pass(&work, "wedges_depth_copy");
    assert_eq!(
        (depth_copy.counted_invocations, depth_copy.texel_reads, depth_copy.read_bytes),
        (pixels, 2 * pixels + covered, (4 + 16) * pixels + 16 * covered)
    );
    let resolve = pass(&work, "wedges_resolve");
    assert_eq!(
        (resolve.counted_invocations, resolve.texel_reads, resolve.read_bytes),
        (pixels, 2 * pixels + covered, 2 * 16 * pixels + 16 * covered)
    );
    assert_eq!((resolve.atomics, resolve.storage_bytes), (0, 0));
    let blend = pass(&work, "wedges_blend");
    assert_eq!(blend.counted_invocations, pixels, "one thread per pixel, one buffer");
    assert!(blend.texel_reads >= 5 * pixels, "{}", blend.texel_reads);
    // Per thread the shaded count and the umbra mask (4 + 1 bytes), and 16 bytes for every other
    // read but the fragment count's (4) at the s pixels that shaded a wedge fragment: the bytes
    // are 16 r - 27 n - 12 s for r reads over n threads, with 0 < s <= n (the wedges shade some).
    let (reads, threads) = (blend.texel_reads, blend.counted_invocations);
    let shortfall = (16 * reads - 27 * threads).checked_sub(blend.read_bytes).unwrap();
    assert!(
        shortfall % 12 == 0 && (1..=threads).contains(&(shortfall / 12)),
        "blend: {} bytes for {reads} reads over {threads} threads",
        blend.read_bytes
    );
    let wedges = pass(&work, "wedges_wedges");
    assert!(wedges.counted_invocations > 0, "the wedges shade fragments");
    assert!(
        (wedges.counted_invocations..=2 * wedges.counted_invocations).contains(&wedges.texel_reads),
        "one or two texels per fragment: {} for {}",
        wedges.texel_reads,
        wedges.counted_invocations
    );
    assert_eq!(wedges.read_bytes, 16 * wedges.texel_reads, "the G-buffer's position and normal, Rgba32Float");
    let silhouettes = pass(&work, "wedges_silhouettes");
    assert_eq!(silhouettes.counted_invocations, SILHOUETTE_THREADS, "every thread records once");
    assert_eq!((silhouettes.atomics, silhouettes.storage_bytes), (SILHOUETTE_ATOMICS, SILHOUETTE_STORAGE_BYTES));
    assert_eq!((silhouettes.texel_reads, silhouettes.read_bytes), (0, 0), "the mesh is geometry, not texels");
    // Every pass that reads counts its bytes (the framework's own-surface share after it too), so
    // the frame's bytes read are known.
    for pass in work.passes.iter().filter(|p| p.texel_reads > 0) {
        assert!(pass.read_bytes > 0, "{} reads {} texels but counts no bytes", pass.name, pass.texel_reads);
    }
}

/// Forest et al.'s blending against the plain wedges, in work (Sec. 5.2: "more GPU intensive"):
/// the silhouette half-edges are the same whichever buffer holds them, and each one's wedge is
/// drawn once, against the same depth, so the wedge fragments and their reads are the same with
/// one buffer or sixteen; what the blending adds is per buffer in use and per pixel, one blend
/// thread per pixel for each (and one full-screen umbra mask). The buffers in use come from the
/// technique's own diagnostics (its counters buffer, not the counts).
#[test]
fn blending_adds_a_blend_per_buffer_and_pixel_and_no_wedge_fragment() {
    let scene = ssm_wedges::scenes::sphere_cube(2, 8, 6);
    let pixels = u64::from(SIZE.0 * SIZE.1);
    let gpu = gpu();
    let mut wedge_work = Vec::new();
    for settings in [[("blending", "none"), ("silhouette_buffers", "1")], [("blending", "forest"), ("silhouette_buffers", "16")]] {
        let params = ssm_wedges::INFO.params_from(settings).unwrap();
        let needs = (ssm_wedges::INFO.requirements)(&params).unwrap();
        let mut renderer = ssm_core::Renderer::new(&gpu, &scene, SIZE.0, SIZE.1, &needs).unwrap();
        let mut technique = renderer.create_technique(&ssm_wedges::INFO, &params).unwrap();
        renderer.render(technique.as_mut(), ssm_wedges::NAME).unwrap();
        let used = technique.diagnostics(&gpu).into_iter().find(|(name, _)| name == "silhouette_buffers_used").unwrap().1 as u64;
        let work = renderer.count_work(&ssm_wedges::INFO, &params).unwrap();
        println!("{settings:?}: {used} buffers used; {}", work.passes_column());
        assert_eq!(pass(&work, "wedges_blend").counted_invocations, used * pixels, "{settings:?}");
        let wedges = pass(&work, "wedges_wedges");
        wedge_work.push((wedges.counted_invocations, wedges.texel_reads, used));
    }
    let [(plain_fragments, plain_reads, one), (blended_fragments, blended_reads, many)] = wedge_work[..] else { unreachable!() };
    assert_eq!((one, many > 1), (1, true), "eight spheres fill more than one of sixteen buffers");
    assert!(plain_fragments > 0);
    assert_eq!((blended_fragments, blended_reads), (plain_fragments, plain_reads), "the same wedges, shaded once each");
}
