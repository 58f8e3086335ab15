//! Atty et al.'s cost claims in counted work (issue #40): per occluder-map size (the sizes of
//! Fig. 17 and the `atty-map-size` preset), one- and two-sided, the micro-patches listed, the
//! accumulation's fragments (as its shader counts them: one per SSM texel covered by a patch's
//! penumbra rectangle, Sec. 6.1), fragments per micro-patch, the fragment invocations lavapipe's
//! pipeline statistics report for the same passes (helper invocations included), and the frame's
//! texel reads, from one counting frame (`Renderer::count_work`).
//!
//! ```sh
//! cargo run --release -p ssm-atty --example atty_work -- [--scene floating-sphere] [--size 320x240] \
//!     [--sizes 33,63,127,200,255,383,511] [--set merge_tolerance=0 ...]
//! ```

use ssm_core::work::FrameWork;
use ssm_scene::builtin;
use ssm_testing::{gpu, render};

/// Sums `count` over the passes whose names start with `prefix` and do not end with `_patches`
/// (the accumulation passes, one per side), or end with it (the list passes) when `patches`.
fn sum(work: &FrameWork, prefix: &str, patches: bool, count: impl Fn(&ssm_core::work::PassWork) -> u64) -> u64 {
    work.passes.iter().filter(|p| p.name.starts_with(prefix) && p.name.ends_with("_patches") == patches).map(count).sum()
}

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn main() -> Result<()> {
    let mut scene_name = "floating-sphere".to_owned();
    let mut size = (320u32, 240u32);
    let mut sizes: Vec<u32> = vec![33, 63, 127, 200, 255, 383, 511];
    let mut extra: Vec<(String, String)> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let value = args.next().ok_or(format!("{arg} needs a value"))?;
        match arg.as_str() {
            "--scene" => scene_name = value,
            "--size" => {
                let (w, h) = value.split_once('x').ok_or("--size WxH")?;
                size = (w.parse()?, h.parse()?);
            }
            "--sizes" => sizes = value.split(',').map(str::parse).collect::<std::result::Result<_, _>>()?,
            "--set" => {
                let (k, v) = value.split_once('=').ok_or("--set name=value")?;
                extra.push((k.to_owned(), v.to_owned()));
            }
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let gpu = gpu();
    println!("{} on {scene_name} at {}x{}, {}", ssm_atty::NAME, size.0, size.1, gpu.describe());
    println!(
        "occluder_map_size,two_sided,patches,accumulate_fragments,fragments_per_patch,accumulate_fragment_invocations,frame_texel_reads"
    );
    let scene = builtin(&scene_name)?.build();
    for &n in &sizes {
        for two_sided in [false, true] {
            let n_text = n.to_string();
            let mut settings: Vec<(&str, &str)> =
                vec![("occluder_map_size", &n_text), ("two_sided", if two_sided { "true" } else { "false" })];
            settings.extend(extra.iter().map(|(k, v)| (k.as_str(), v.as_str())));
            let mut rendered = render(&gpu, &scene, &ssm_atty::INFO, &settings, size.0, size.1)?;
            let params = ssm_atty::INFO.params_from(settings.iter().copied())?;
            let work = rendered.renderer.count_work(&ssm_atty::INFO, &params)?;
            let patches = sum(&work, "atty_accumulate", true, |p| p.atomics);
            let fragments = sum(&work, "atty_accumulate", false, |p| p.counted_invocations);
            let invocations = sum(&work, "atty_accumulate", false, |p| p.fragment_invocations);
            println!(
                "{n},{two_sided},{patches},{fragments},{:.1},{invocations},{}",
                fragments as f64 / patches.max(1) as f64,
                work.total(|p| p.texel_reads)
            );
        }
    }
    Ok(())
}
