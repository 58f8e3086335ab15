//! Criterion benches: one group per built-in scene, one benchmark per
//! registered real-time technique, discovered from the registry, so a new
//! technique crate linked into ssm-bench is benchmarked without editing this
//! file. Each iteration is one frame; its time is the GPU time of the
//! technique's passes (timestamp queries), or the CPU wall time up to the GPU
//! going idle where the adapter has no timestamps.
//!
//! `SSM_BENCH_SIZE=WxH` sets the image size (default 256x192, small enough for
//! lavapipe); `SSM_BENCH_SIZE=full` is 1280x720. Compare techniques as ratios
//! within one run: absolute times on a shared machine are noisy.

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use ssm_bench::bench::bench_size;
use ssm_bench::measure::needs::output_requirements;
use ssm_bench::registry;
use ssm_core::{GpuContext, Renderer, TechniqueKind};
use ssm_scene::BUILTIN_SCENES;

fn techniques(c: &mut Criterion) {
    let registry = registry().unwrap_or_else(|e| panic!("{e}"));
    let gpu = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let (width, height) = bench_size().unwrap_or_else(|e| panic!("{e}"));
    let realtime: Vec<_> = registry.iter().filter(|i| i.kind == TechniqueKind::Realtime).collect();
    for scene_entry in BUILTIN_SCENES {
        let scene = scene_entry.build();
        let mut needs = output_requirements();
        let mut runnable = Vec::new();
        for info in &realtime {
            let params = info.default_params();
            match (info.requirements)(&params).and_then(|r| r.check_device(info.name, &gpu).map(|()| r)) {
                Ok(requirements) => {
                    needs = needs.union(requirements);
                    runnable.push((*info, params));
                }
                Err(e) => eprintln!("{}: {} not benchmarked: {e}", scene_entry.name, info.name),
            }
        }
        let mut renderer = Renderer::new(&gpu, &scene, width, height, &needs).unwrap_or_else(|e| panic!("{}: {e}", scene_entry.name));
        let mut group = c.benchmark_group(format!("{}/{width}x{height}", scene_entry.name));
        group.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
        for (info, params) in &runnable {
            let mut technique = renderer.create_technique(info, params).unwrap_or_else(|e| panic!("{}: {e}", info.name));
            group.bench_function(info.name, |b| {
                b.iter_custom(|iterations| {
                    let mut total = Duration::ZERO;
                    for _ in 0..iterations {
                        let timings = renderer.render(technique.as_mut(), info.name).unwrap_or_else(|e| panic!("{}: {e}", info.name));
                        total += Duration::from_secs_f64(timings.frame_ms() * 1e-3);
                    }
                    total
                });
            });
        }
        group.finish();
    }
}

criterion_group!(benches, techniques);
criterion_main!(benches);
