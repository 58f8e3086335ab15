//! Counted work (`--count-work`): for every registered technique, one counting frame
//! ([`Renderer::count_work`]) gives each pass's invocations from pipeline statistics (lavapipe has
//! them, so they must be there) and, for every technique of the workspace, the texel reads its
//! shaders count (the framework's own-surface share pass included, after every technique that
//! samples the light from its centre, with the bytes its reads fetched); and it leaves the same
//! visibility as a timed frame: counting changes no result.
//! Where the work is known by hand it is asserted exactly.

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ssm_core::{Renderer, Requirements, TechniqueKind, own_surface_share_label};
use ssm_integration_tests::{MUST_RUN_ON_LAVAPIPE, missing_must_run, registry, render_or_refusal};
use ssm_scene::builtin;
use ssm_testing::gpu;

const WIDTH: u32 = 64;
const HEIGHT: u32 = 48;
/// How far two renders of the same inputs may differ (tests/multi_light.rs's tolerance).
const RERENDER_TOLERANCE: f32 = 1e-5;
/// The techniques whose every pass that reads texels counts the bytes they fetched, the
/// framework's passes after them included: every technique of the workspace.
const COUNT_READ_BYTES: &[&str] = &["atty", "hard", "multi-sm", "pcss", "pvsm", "sssm", "vssm", "wedges"];

#[test]
fn every_technique_counts_its_passes_and_counting_changes_no_result() {
    assert!(missing_must_run().is_empty(), "not registered: {:?}", missing_must_run());
    let gpu = gpu();
    assert!(gpu.has_pipeline_statistics(), "lavapipe exposes PIPELINE_STATISTICS_QUERY: {}", gpu.describe());
    let scene = builtin("parallel-square").unwrap().build();
    let mut failures = Vec::new();
    for info in registry().iter().filter(|info| info.kind == TechniqueKind::Realtime) {
        let params = info.params_from(std::iter::empty()).unwrap();
        let needs = (info.requirements)(&params).unwrap().union(Requirements { gbuffer: true, ..Requirements::NONE });
        let result = Renderer::new(&gpu, &scene, WIDTH, HEIGHT, &needs).and_then(|mut renderer| {
            let mut timed = renderer.create_technique(info, &params)?;
            renderer.render(timed.as_mut(), info.name)?;
            let visibility = renderer.read_visibility(0, info.name)?;
            let work = renderer.count_work(info, &params)?;
            let counted_visibility = renderer.read_visibility(0, info.name)?;
            Ok((visibility, work, counted_visibility))
        });
        let Some((visibility, work, counted_visibility)) = render_or_refusal(info.name, "parallel-square", result).unwrap() else {
            continue;
        };
        println!("{:<12} {}", info.name, work.passes_column());
        if !work.pipeline_statistics {
            failures.push(format!("{}: no pipeline statistics", info.name));
        }
        let invocations = work.total(|p| p.fragment_invocations + p.compute_invocations);
        if invocations == 0 {
            failures.push(format!("{}: no fragment or compute invocation counted", info.name));
        }
        // Every technique of the workspace counts its texel reads in its shaders (issue 40: "texel
        // reads, for every technique"); one registered from elsewhere may leave them unknown.
        if MUST_RUN_ON_LAVAPIPE.contains(&info.name) && !(work.shader_counts && work.total(|p| p.texel_reads) > 0) {
            failures.push(format!("{}: its shaders count no texel reads", info.name));
        }
        // Techniques whose every pass that reads counts the bytes it read too: the frame's bytes
        // read are known.
        if COUNT_READ_BYTES.contains(&info.name) {
            for pass in work.passes.iter().filter(|p| p.texel_reads > 0 && p.read_bytes == 0) {
                failures.push(format!("{}: {} reads {} texels but counts no bytes", info.name, pass.name, pass.texel_reads));
            }
        }
        // The framework's own-surface share follows every technique that samples the light from
        // its centre, once per light, with its reads counted (two G-buffer texels per pixel at
        // least) and their bytes (parallel-square has no closed mesh: the two Rgba32Float
        // G-buffer texels alone, 16 bytes each), and no other.
        let share = work.passes.iter().find(|p| p.name == own_surface_share_label(info.name));
        match (info.gets_own_surface_share(), share) {
            (true, Some(pass)) => {
                if pass.runs != 1
                    || (work.shader_counts
                        && (pass.texel_reads < 2 * u64::from(WIDTH * HEIGHT) || pass.read_bytes != 16 * pass.texel_reads))
                {
                    failures.push(format!(
                        "{}: own-surface share ran {} times, {} texel reads of {} bytes",
                        info.name, pass.runs, pass.texel_reads, pass.read_bytes
                    ));
                }
            }
            (true, None) => failures.push(format!("{}: no own-surface share pass in {}", info.name, work.passes_column())),
            (false, Some(_)) => failures.push(format!("{}: samples the light per point, yet got the own-surface share", info.name)),
            (false, None) => {}
        }
        if let Some(pass) = work.passes.iter().find(|p| p.runs == 0) {
            failures.push(format!("{}: pass {} counted without running", info.name, pass.name));
        }
        // Counting must change no result; the tolerance is multi_light.rs's for re-rendering the
        // same inputs: atty and wedges append lists with atomics, so the order of their additive
        // blends, and its f32 rounding, varies from frame to frame (1.2e-7 seen between two timed frames).
        let largest = visibility.iter().zip(&counted_visibility).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
        if largest > RERENDER_TOLERANCE {
            failures.push(format!("{}: counting changed a pixel by {largest}", info.name));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// hard's work by hand: its shadow-map pass draws the scene's vertices once per light (4
/// triangles, no index reuse), and its lookup is one full-screen triangle that shades every pixel
/// and stores one R32Float texel per pixel; the shadow map stores one R32Float texel per texel;
/// the framework's own-surface share after it reads two G-buffer texels per pixel (Rgba32Float, 16
/// bytes each).
/// Fragment invocations are at least one per pixel: Vulkan lets an implementation count helper
/// invocations (lavapipe reports 3,456 for 64x48 = 3,072 pixels), so no upper bound is exact.
#[test]
fn hard_shadow_mapping_work_is_counted_exactly() {
    let gpu = gpu();
    let scene = builtin("parallel-square").unwrap().build();
    let info = registry().get("hard").unwrap();
    let params = info.params_from([("shadow_map_size", "256")]).unwrap();
    let needs = (info.requirements)(&params).unwrap().union(Requirements { gbuffer: true, ..Requirements::NONE });
    let mut renderer = Renderer::new(&gpu, &scene, WIDTH, HEIGHT, &needs).unwrap();
    let work = renderer.count_work(info, &params).unwrap();
    println!("{}", work.passes_column());
    let pass = |name: &str| work.passes.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no {name} in {}", work.passes_column()));
    let shadow_map = pass("hard_shadow_map");
    let triangles: u64 = scene.world_triangles().count() as u64;
    assert_eq!((shadow_map.runs, shadow_map.vertex_invocations, shadow_map.primitives), (1, 3 * triangles, triangles));
    // The map is an R32Float linear depth; its depth buffer is only tested against, not stored.
    assert_eq!(shadow_map.target_bytes, 256 * 256 * 4, "one R32Float texel per shadow-map texel");
    let lookup = pass("hard_lookup");
    assert_eq!((lookup.runs, lookup.vertex_invocations, lookup.primitives), (1, 3, 1), "one full-screen triangle");
    assert!(
        lookup.fragment_invocations >= u64::from(WIDTH * HEIGHT),
        "{} fragments for {} pixels",
        lookup.fragment_invocations,
        WIDTH * HEIGHT
    );
    assert_eq!(lookup.target_bytes, u64::from(WIDTH * HEIGHT) * 4, "one R32Float texel per pixel");
    // The framework's own-surface share: one invocation per pixel (64 x 48 is whole 8 x 8 groups),
    // each reading the G-buffer's two texels; parallel-square has no closed mesh, so nothing more
    // is read or stored.
    let share = pass(&own_surface_share_label("hard"));
    let pixels = u64::from(WIDTH * HEIGHT);
    assert_eq!(
        (share.runs, share.compute_invocations, share.texel_reads, share.read_bytes, share.storage_bytes),
        (1, pixels, 2 * pixels, 2 * 16 * pixels, 0)
    );
    assert_eq!(work.uncounted_passes, 0);
}
