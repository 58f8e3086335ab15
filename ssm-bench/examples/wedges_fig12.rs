//! Forest et al., Fig. 12 (and Atty et al., Fig. 25): frame time against the
//! number of triangles, for the plain penumbra wedges (`wedges` with
//! `blending=none silhouette_buffers=1`, Akenine-Möller and Assarsson's one
//! visibility buffer, the paper's baseline) and the blending (`forest`, 16
//! silhouette buffers), and
//! Atty et al.'s soft shadow maps (two-sided, 210² occluder map, as in their
//! Fig. 25), on cubes of 1 to 343 spheres of 760 triangles.
//!
//! ```sh
//! cargo run --release -p ssm-bench --example wedges_fig12 -- --out out/fig12 [--size 320x240] [--frames 5] \
//!     [--sides 1,2,3,4,5,6,7] [--error]
//! ```
//!
//! The three are timed in turns, frame by frame after a warm-up round, so that
//! a drift of the machine's speed affects them alike. Writes `results.csv`
//! (triangles, technique, median GPU ms, silhouette edges, wedge fragments,
//! the mean time of each pass, and with `--error` the penumbra MAE and mean
//! signed penumbra error against a 16×16-ray ground truth), `time.png`/`.svg`
//! (time against triangles) and `ratio.png`/`.svg` (forest ÷ plain). The
//! scenes are the built-in `sphere-cube:spheres=N,segments=20,rings=20`.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use ssm_bench::measure::measure;
use ssm_bench::present::charts::{PlotAxes, PlotPoint, plot};
use ssm_core::metrics::{ShadowClass, classify, compare};
use ssm_core::{GpuContext, Renderer, Requirements};
use ssm_wedges::scenes::{FIG12_SIDES, PAPER_RINGS, PAPER_SEGMENTS, sphere_cube};

/// One measured series: its label, the technique, and its settings.
type Run = (&'static str, &'static str, &'static [(&'static str, &'static str)]);

struct Options {
    out: PathBuf,
    size: (u32, u32),
    frames: u32,
    sides: Vec<u32>,
    error: bool,
}

fn options() -> Result<Options> {
    let mut options = Options { out: PathBuf::from("out/fig12"), size: (320, 240), frames: 5, sides: FIG12_SIDES.to_vec(), error: false };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().with_context(|| format!("{arg} needs a value"));
        match arg.as_str() {
            "--out" => options.out = PathBuf::from(value()?),
            "--size" => {
                let text = value()?;
                let (w, h) = text.split_once('x').with_context(|| format!("--size {text}: expected WxH"))?;
                options.size = (w.parse()?, h.parse()?);
            }
            "--frames" => options.frames = value()?.parse()?,
            "--sides" => options.sides = value()?.split(',').map(str::parse).collect::<Result<_, _>>()?,
            "--error" => options.error = true,
            other => bail!("unknown argument {other}"),
        }
    }
    Ok(options)
}

/// Mean signed error over the reference's penumbra (negative: too dark), and the penumbra MAE.
fn errors(truth: &[f32], image: &[f32], covered: &[bool], (width, height): (u32, u32)) -> (f64, f64) {
    let classes = classify(truth, covered);
    let signed: Vec<f64> = classes
        .iter()
        .zip(image)
        .zip(truth)
        .filter(|((class, _), _)| **class == ShadowClass::Penumbra)
        .map(|((_, v), r)| f64::from(v - r))
        .collect();
    let mae = compare(truth, image, covered, width as usize, height as usize).mae_penumbra;
    (signed.iter().sum::<f64>() / signed.len().max(1) as f64, mae)
}

fn main() -> Result<()> {
    let options = options()?;
    let registry = ssm_bench::registry()?;
    let gpu = GpuContext::new()?;
    std::fs::create_dir_all(&options.out)?;
    let runs: [Run; 3] = [
        ("wedges plain", "wedges", &[("blending", "none"), ("silhouette_buffers", "1")]),
        ("wedges forest", "wedges", &[("blending", "forest"), ("silhouette_buffers", "16")]),
        ("atty two-sided 210²", "atty", &[("two_sided", "true"), ("occluder_map_size", "210")]),
    ];
    let mut csv = String::from(
        "spheres,triangles,technique,width,height,gpu_ms_median,silhouette_edges,wedge_fragments,mae_penumbra,mean_signed_penumbra,pass_ms_means,adapter\n",
    );
    let mut time_points = Vec::new();
    let mut ratio_points = Vec::new();
    for &side in &options.sides {
        let scene = sphere_cube(side, PAPER_SEGMENTS, PAPER_RINGS);
        let triangles = scene.triangle_count() - 2;
        let spheres = side * side * side;
        let mut needs = Requirements { gbuffer: true, ..Requirements::NONE };
        let mut params = Vec::new();
        for (_, name, settings) in &runs {
            let info = registry.get(name)?;
            let values = info.params_from(settings.iter().copied())?;
            needs = needs.union((info.requirements)(&values)?);
            params.push((info, values));
        }
        let mut renderer = Renderer::new(&gpu, &scene, options.size.0, options.size.1, &needs)?;
        let truth = if options.error {
            let values = ssm_core::reference::INFO.params_from([("samples", "16")])?;
            Some(measure(&mut renderer, &ssm_core::reference::INFO, &values, 1, &[])?.visibility.swap_remove(0))
        } else {
            None
        };

        let covered: Vec<bool> = renderer.read_positions()?.iter().map(|p| p[3] > 0.5).collect();
        // plain, forest and atty alternate frame by frame, so that a drift of the machine's speed
        // affects them alike (the ratio of the first two is the figure's point).
        let mut instances = params.iter().map(|(info, values)| renderer.create_technique(info, values)).collect::<Result<Vec<_>, _>>()?;
        let mut frame_times: Vec<Vec<f64>> = vec![Vec::new(); runs.len()];
        let mut pass_times: Vec<Vec<(String, f64)>> = vec![Vec::new(); runs.len()];
        for round in 0..=options.frames {
            for (k, ((info, _), technique)) in params.iter().zip(&mut instances).enumerate() {
                let timings = renderer.render(technique.as_mut(), info.name)?;
                // The first round is the warm-up: pipelines compile on first use.
                if round > 0 {
                    frame_times[k].push(timings.gpu_ms.unwrap_or(f64::NAN));
                    pass_times[k].extend(timings.passes.iter().map(|p| (p.name.clone(), p.ms)));
                }
            }
        }
        let mut times = Vec::new();
        for (k, ((label, _, _), (info, _))) in runs.iter().zip(&params).enumerate() {
            let technique = &mut instances[k];
            renderer.render(technique.as_mut(), info.name)?;
            let visibility = renderer.read_visibility(0, info.name)?;
            let diagnostics = technique.diagnostics(&gpu);
            let ms = ssm_bench::stats::median(&frame_times[k]).unwrap_or(f64::NAN);
            let diagnostic = |name: &str| diagnostics.iter().find(|(n, _)| n == name).map_or(String::new(), |(_, v)| v.to_string());
            // Without `--error` the errors are not measured: empty in the CSV, said so when printed.
            let measured = truth.as_ref().map(|t| errors(t, &visibility, &covered, options.size));
            let (signed_field, mae_field, error_text) = match measured {
                Some((signed, mae)) => (format!("{signed:.5}"), format!("{mae:.5}"), format!("MAE {mae:.4}  signed {signed:+.4}")),
                None => (String::new(), String::new(), "error not measured (--error)".to_owned()),
            };
            let mut passes: Vec<(String, f64)> = Vec::new();
            for (name, ms) in &pass_times[k] {
                match passes.iter_mut().find(|(n, _)| n == name) {
                    Some((_, total)) => *total += ms,
                    None => passes.push((name.clone(), *ms)),
                }
            }
            let frames = frame_times[k].len().max(1) as f64;
            let passes = passes.iter().map(|(n, t)| format!("{n}={:.1}", t / frames)).collect::<Vec<_>>().join(";");
            let _ = writeln!(
                csv,
                "{spheres},{triangles},{label},{},{},{ms:.3},{},{},{mae_field},{signed_field},{passes},\"{}\"",
                options.size.0,
                options.size.1,
                diagnostic("silhouette_edges"),
                diagnostic("wedge_fragments"),
                gpu.describe()
            );
            println!("{spheres:4} spheres, {triangles:7} triangles, {label:22}: {ms:9.1} ms  {error_text}  ({passes})");
            time_points.push(PlotPoint { series: (*label).to_owned(), x: triangles as f64, y: ms, label: String::new() });
            times.push(ms);
        }
        if let [plain, forest, ..] = times[..] {
            println!("{spheres:4} spheres: forest / plain = {:.3}", forest / plain);
            ratio_points.push(PlotPoint {
                series: "forest / plain".into(),
                x: triangles as f64,
                y: forest / plain,
                label: format!("{:.2}", forest / plain),
            });
        }
        std::fs::write(options.out.join("results.csv"), &csv)?;
    }
    let axes = |y: &str| PlotAxes { x_label: "triangles".into(), y_label: y.into(), log_x: true, pareto: false };
    let title = format!("Forest et al. Fig. 12 / Atty et al. Fig. 25, {}x{}, {}", options.size.0, options.size.1, gpu.info.name);
    plot(&time_points, &axes("GPU ms per frame"), &title, &options.out.join("time.png"), &options.out.join("time.svg"))?;
    plot(&ratio_points, &axes("forest time / plain time"), &title, &options.out.join("ratio.png"), &options.out.join("ratio.svg"))?;
    println!("wrote {}", options.out.display());
    Ok(())
}
