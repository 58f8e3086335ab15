//! Forest et al., Figs. 1 and 2: the plain penumbra wedges of Akenine-Möller
//! and Assarsson (`blending=none silhouette_buffers=1`: one visibility buffer)
//! against the blending (`forest` with `--buffers` silhouette buffers) and the
//! ground truth, measured as the mean signed error over the ground truth's
//! penumbra (negative: over-darkened), split into its too-light and too-dark
//! parts, and the penumbra MAE. A third row, `none` with `--buffers` buffers,
//! is a per-buffer sum (each buffer clamped, then added): not a published
//! method, shown for what the buffers alone do.
//!
//! ```sh
//! cargo run --release -p ssm-bench --example wedges_fig1 -- [--scene sphere-cube] [--size 320x240] [--buffers 16] [--samples 16]
//! ```
//!
//! `--scene` takes a built-in name or a manifest (the paper's spheres:
//! `sphere-cube:spheres=5,segments=20,rings=20`).

use anyhow::{Context, Result, bail};
use ssm_bench::measure::measure;
use ssm_core::metrics::{ShadowClass, classify, compare};
use ssm_core::{GpuContext, Renderer, Requirements};

fn main() -> Result<()> {
    let (mut scene_name, mut size, mut buffers, mut samples) =
        ("sphere-cube".to_owned(), (320u32, 240u32), "16".to_owned(), "16".to_owned());
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().with_context(|| format!("{arg} needs a value"));
        match arg.as_str() {
            "--scene" => scene_name = value()?,
            "--size" => {
                let text = value()?;
                let (w, h) = text.split_once('x').with_context(|| format!("--size {text}: expected WxH"))?;
                size = (w.parse()?, h.parse()?);
            }
            "--buffers" => buffers = value()?,
            "--samples" => samples = value()?,
            other => bail!("unknown argument {other}"),
        }
    }
    let (scene, _) = ssm_scene::Scene::load(&scene_name)?;
    let gpu = GpuContext::new()?;
    let info = &ssm_wedges::INFO;
    let needs = (info.requirements)(&info.default_params())?.union(Requirements { gbuffer: true, ..Requirements::NONE });
    let mut renderer = Renderer::new(&gpu, &scene, size.0, size.1, &needs)?;
    let truth = measure(
        &mut renderer,
        &ssm_core::reference::INFO,
        &ssm_core::reference::INFO.params_from([("samples", samples.as_str())])?,
        1,
        &[],
    )?
    .visibility
    .swap_remove(0);
    let covered: Vec<bool> = renderer.read_positions()?.iter().map(|p| p[3] > 0.5).collect();
    let classes = classify(&truth, &covered);
    println!(
        "{scene_name}, {}x{}, {} ({} penumbra pixels in the ground truth)",
        size.0,
        size.1,
        gpu.describe(),
        classes.iter().filter(|c| **c == ShadowClass::Penumbra).count()
    );
    let runs = [
        ("plain (none, 1 buffer)", "none", "1"),
        ("forest", "forest", buffers.as_str()),
        ("per-buffer sum (none)", "none", buffers.as_str()),
    ];
    for (label, blending, count) in runs {
        let params = info.params_from([("blending", blending), ("silhouette_buffers", count)])?;
        let measured = measure(&mut renderer, info, &params, 3, &[])?;
        let image = &measured.visibility[0];
        let signed: Vec<f64> = classes
            .iter()
            .zip(image)
            .zip(&truth)
            .filter(|((class, _), _)| **class == ShadowClass::Penumbra)
            .map(|((_, v), r)| f64::from(v - r))
            .collect();
        let pixels = signed.len().max(1) as f64;
        let metrics = compare(&truth, image, &covered, size.0 as usize, size.1 as usize);
        println!(
            "{label:22} (blending={blending}, silhouette_buffers={count}): mean signed penumbra error {:+.4} ({:+.4} too light, {:+.4} too dark), penumbra MAE {:.4}, mean signed error (all pixels) {:+.4}, GPU {:.1} ms",
            signed.iter().sum::<f64>() / pixels,
            signed.iter().filter(|e| **e > 0.0).sum::<f64>() / pixels,
            signed.iter().filter(|e| **e < 0.0).sum::<f64>() / pixels,
            metrics.mae_penumbra,
            metrics.mean_signed,
            measured.gpu_ms_median().unwrap_or(f64::NAN)
        );
    }
    Ok(())
}
