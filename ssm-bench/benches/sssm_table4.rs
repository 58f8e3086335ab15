//! Buades et al. 2015, Table 4, as a criterion bench: PCSS and SSSM with the
//! kernel pairs 7/15, 11/21 and 29/41 (SSSM at α = β = 0.01 and 0.05 of the
//! scene's diagonal) on `leaves`, the nearest built-in scene to the paper's
//! plant, timed by GPU timestamps in one run so that their ratios compare.
//! `SSM_BENCH_SIZE=WxH` or `full` sets the image size (default 256x192).

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use ssm_bench::{output_requirements, registry};
use ssm_core::{GpuContext, Renderer};
use ssm_scene::builtin;

fn bench_size() -> (u32, u32) {
    match std::env::var("SSM_BENCH_SIZE").as_deref() {
        Ok("full") => (1280, 960),
        Ok(text) => text
            .split_once('x')
            .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
            .unwrap_or_else(|| panic!("SSM_BENCH_SIZE={text}: expected WxH or full")),
        Err(_) => (256, 192),
    }
}

/// (technique, benchmark label, parameter assignments).
type Configuration = (&'static str, String, Vec<(&'static str, String)>);

fn table4(c: &mut Criterion) {
    let registry = registry().unwrap_or_else(|e| panic!("{e}"));
    let gpu = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let scene = builtin("leaves").unwrap_or_else(|e| panic!("{e}")).build();
    let (width, height) = bench_size();
    let needs = output_requirements();
    let mut renderer = Renderer::new(&gpu, &scene, width, height, &needs).unwrap_or_else(|e| panic!("{e}"));
    let mut group = c.benchmark_group(format!("sssm-table4/leaves/{width}x{height}"));
    group.sample_size(10).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    let mut configurations: Vec<Configuration> = Vec::new();
    for (n, m) in [(7, 15), (11, 21), (29, 41)] {
        configurations.push(("pcss", format!("pcss/{n}x{m}"), vec![("blocker_kernel", n.to_string()), ("pcf_kernel", m.to_string())]));
        for threshold in ["0.01", "0.05"] {
            configurations.push((
                "sssm",
                format!("sssm/{n}x{m}/alpha=beta={threshold}"),
                vec![
                    ("blocker_kernel", n.to_string()),
                    ("blur_kernel", m.to_string()),
                    ("alpha", threshold.into()),
                    ("beta", threshold.into()),
                ],
            ));
        }
    }
    for (technique, label, settings) in configurations {
        let info = registry.get(technique).unwrap_or_else(|e| panic!("{e}"));
        let params = info.params_from(settings.iter().map(|(k, v)| (*k, v.as_str()))).unwrap_or_else(|e| panic!("{e}"));
        let mut instance = renderer.create_technique(info, &params).unwrap_or_else(|e| panic!("{label}: {e}"));
        group.bench_function(label.as_str(), |b| {
            b.iter_custom(|iterations| {
                let mut total = Duration::ZERO;
                for _ in 0..iterations {
                    let timings = renderer.render(instance.as_mut(), technique).unwrap_or_else(|e| panic!("{label}: {e}"));
                    total += Duration::from_secs_f64(timings.gpu_ms.unwrap_or(timings.cpu_wall_ms) * 1e-3);
                }
                total
            });
        });
    }
    group.finish();
}

criterion_group!(benches, table4);
criterion_main!(benches);
