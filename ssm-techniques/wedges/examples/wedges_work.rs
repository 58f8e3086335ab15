//! Forest et al.'s cost claim in counted work (issue #40): the plain penumbra wedges
//! (`blending=none silhouette_buffers=1`, Akenine-Möller and Assarsson's one visibility buffer)
//! against the blending (`forest`, 16 silhouette buffers), per pixel of the view: the wedge
//! fragments (as their shader counts them, depth-tested first), the shadow-volume passes'
//! fragment invocations (lavapipe's pipeline statistics: the volumes and each buffer's full-screen
//! umbra mask), the blend's threads, and the frame's texel reads, atomics, storage bytes and
//! bytes stored to render targets (each buffer's eight silhouette targets are written back), from
//! one counting frame (`Renderer::count_work`).
//!
//! ```sh
//! cargo run --release -p ssm-wedges --example wedges_work -- [--size 320x240] \
//!     [--scene forest] [--scene models/dragon.toml] ...
//! ```

use std::path::Path;

use ssm_core::work::FrameWork;
use ssm_scene::{Manifest, Scene};
use ssm_testing::{gpu, render};

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// A built-in scene by name, or a manifest file (its models relative to it).
fn scene(name: &str) -> Result<Scene> {
    if name.ends_with(".toml") {
        let path = Path::new(name);
        Ok(Manifest::read(path)?.build(path, path.parent().unwrap_or(Path::new(".")))?)
    } else {
        Ok(ssm_scene::parse_builtin(name).ok_or(format!("no built-in scene {name}"))??.1)
    }
}

fn pass_sum(work: &FrameWork, name: &str, count: impl Fn(&ssm_core::work::PassWork) -> u64) -> u64 {
    work.passes.iter().filter(|p| p.name == name).map(count).sum()
}

fn main() -> Result<()> {
    let mut size = (320u32, 240u32);
    let mut scenes: Vec<String> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let value = args.next().ok_or(format!("{arg} needs a value"))?;
        match arg.as_str() {
            "--scene" => scenes.push(value),
            "--size" => {
                let (w, h) = value.split_once('x').ok_or("--size WxH")?;
                size = (w.parse()?, h.parse()?);
            }
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    if scenes.is_empty() {
        scenes = vec!["forest".into(), "models/dragon.toml".into()];
    }
    let gpu = gpu();
    println!("{} at {}x{}, {}", ssm_wedges::NAME, size.0, size.1, gpu.describe());
    println!(
        "scene,triangles,settings,half_edges,wedge_fragments_per_pixel,volume_fragment_invocations_per_pixel,blend_threads_per_pixel,texel_reads_per_pixel,atomics,storage_bytes,target_bytes"
    );
    let pixels = f64::from(size.0 * size.1);
    for name in &scenes {
        let scene = scene(name)?;
        let triangles = scene.world_triangles().count();
        for settings in [[("blending", "none"), ("silhouette_buffers", "1")], [("blending", "forest"), ("silhouette_buffers", "16")]] {
            let mut rendered = render(&gpu, &scene, &ssm_wedges::INFO, &settings, size.0, size.1)?;
            let params = ssm_wedges::INFO.params_from(settings)?;
            let work = rendered.renderer.count_work(&ssm_wedges::INFO, &params)?;
            // Each half-edge's wedge is drawn as 24 vertices (WEDGE_VERTICES).
            let half_edges = pass_sum(&work, "wedges_wedges", |p| p.vertex_invocations) / 24;
            println!(
                "{name},{triangles},{} K={},{half_edges},{:.3},{:.3},{:.3},{:.2},{},{},{}",
                settings[0].1,
                settings[1].1,
                pass_sum(&work, "wedges_wedges", |p| p.counted_invocations) as f64 / pixels,
                pass_sum(&work, "wedges_shadow_volumes", |p| p.fragment_invocations) as f64 / pixels,
                pass_sum(&work, "wedges_blend", |p| p.counted_invocations) as f64 / pixels,
                work.total(|p| p.texel_reads) as f64 / pixels,
                work.total(|p| p.atomics),
                work.total(|p| p.storage_bytes),
                work.total(|p| p.target_bytes),
            );
        }
    }
    Ok(())
}
