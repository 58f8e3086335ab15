//! Criterion benches of every sweep preset (the papers' studies each
//! technique declares, and `trade`), discovered from the registry: a new
//! technique's presets are benchmarked without editing this file. One group
//! per preset, on the preset's first scene; one benchmark per grid point,
//! each iteration one frame timed by GPU timestamps (or the CPU wall time
//! where the adapter has none), so that ratios within a run compare.
//!
//! `SSM_BENCH_SIZE=WxH` or `full` sets the image size (default 256x192);
//! `SSM_BENCH_PRESET=name[,name]` keeps only those presets.

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use ssm_bench::bench::bench_size;
use ssm_bench::measure::needs::output_requirements;
use ssm_bench::registry;
use ssm_bench::sweep::{SweepPlan, presets};
use ssm_core::{GpuContext, Renderer};
use ssm_scene::Scene;

fn preset_benches(c: &mut Criterion) {
    // A preset names scene files relative to the workspace's root (where `ssm sweep --preset` is
    // run); cargo runs benches from this crate's folder.
    std::env::set_current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).unwrap_or_else(|e| panic!("the workspace root: {e}"));
    let registry = registry().unwrap_or_else(|e| panic!("{e}"));
    let gpu = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let (width, height) = bench_size().unwrap_or_else(|e| panic!("{e}"));
    let wanted: Option<Vec<String>> = std::env::var("SSM_BENCH_PRESET").ok().map(|v| v.split(',').map(|s| s.trim().to_owned()).collect());
    for preset in presets(registry).unwrap_or_else(|e| panic!("{e}")) {
        if wanted.as_ref().is_some_and(|names| !names.contains(&preset.name)) {
            continue;
        }
        let Some(scene_spec) = preset.scenes.first() else { continue };
        let (base, _) = Scene::load(scene_spec).unwrap_or_else(|e| panic!("preset {}: {e}", preset.name));
        let plan = SweepPlan::new(registry, &preset.varies, &[]).unwrap_or_else(|e| panic!("preset {}: {e:#}", preset.name));
        let mut needs = output_requirements();
        for (info, params, _) in &plan.points {
            needs = needs.union((info.requirements)(params).unwrap_or_else(|e| panic!("{e}")));
        }
        let mut group = c.benchmark_group(format!("{}/{scene_spec}/{width}x{height}", preset.name));
        group.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1));
        for (scene_point, overrides) in plan.scene_points.iter().zip(&plan.scene_overrides) {
            let scene = overrides.base_scene(scene_spec, &base).and_then(|base| overrides.apply(&base)).unwrap_or_else(|e| panic!("{e:#}"));
            let mut renderer = Renderer::new(&gpu, &scene, width, height, &needs).unwrap_or_else(|e| panic!("{e}"));
            for (info, params, point) in &plan.points {
                let Ok(mut technique) = renderer.create_technique(info, params) else {
                    eprintln!("{}: {} [{params}] cannot run here; not benchmarked", preset.name, info.name);
                    continue;
                };
                let label: Vec<String> = scene_point.iter().chain(point).map(|(k, v)| format!("{k}={v}")).collect();
                group.bench_function(format!("{}/{}", info.name, label.join(";")), |b| {
                    b.iter_custom(|iterations| {
                        (0..iterations)
                            .map(|_| {
                                let timings =
                                    renderer.render(technique.as_mut(), info.name).unwrap_or_else(|e| panic!("{}: {e}", info.name));
                                Duration::from_secs_f64(timings.frame_ms() * 1e-3)
                            })
                            .sum()
                    });
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, preset_benches);
criterion_main!(benches);
