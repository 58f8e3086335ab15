//! Measuring techniques against the ground truth, and writing what was
//! measured: `results.csv`, `report.md` and an offline `index.html` with the
//! images side by side.

use std::fmt::Write as _;
use std::path::Path;

use ssm_core::image_io::{write_exr_gray, write_png_gray16, write_png_rgba8};
use ssm_core::metrics::{ErrorMetrics, compare_with_noise, flip_map, flip_mean, heat_map};
use ssm_core::{Error, FrameTimings, FrameWork, GBuffer, ParamValues, Renderer, Result, TechniqueInfo, TimingSource};

use crate::median;

/// One technique rendered and timed: its frames, outputs and diagnostics.
pub struct Measured {
    /// The technique.
    pub info: &'static TechniqueInfo,
    /// Its parameters.
    pub params: ParamValues,
    /// Timings of each measured frame (after one warm-up frame).
    pub frames: Vec<FrameTimings>,
    /// Diagnostics after the last frame.
    pub diagnostics: Vec<(String, f64)>,
    /// Visibility per light, row-major.
    pub visibility: Vec<Vec<f32>>,
    /// The shaded image, RGBA8 sRGB.
    pub shaded: Vec<u8>,
    /// The debug outputs asked of the technique.
    pub extra_images: Vec<ssm_core::ExtraImage>,
    /// The work of one extra, untimed frame, when counted ([`MeasureJob::count_work`]; never for
    /// the ground truth: [`crate::work::GROUND_TRUTH_NOT_COUNTED`]).
    pub work: Option<FrameWork>,
    /// Why the work was not counted although asked: [`crate::work::GROUND_TRUTH_NOT_COUNTED`].
    pub work_note: Option<&'static str>,
    /// For the ground truth with its noise images: the noise floor of FLIP, the larger mean FLIP
    /// of its shaded image against the same shading of its visibility moved down or up by its own
    /// noise at every pixel (what the truth's uncertainty alone can show); `None` otherwise.
    pub flip_noise: Option<f64>,
}

impl Measured {
    /// Median over frames of the frame's time on the GPU: the sum of the technique's timed passes,
    /// plus any CPU work inside the frame that the GPU waits for (a mid-frame readback's stall, a
    /// paper's CPU step): [`FrameTimings::frame_ms`]. `None` without timestamps.
    #[must_use]
    pub fn gpu_ms_median(&self) -> Option<f64> {
        median(&self.frames.iter().filter(|f| f.gpu_ms.is_some()).map(FrameTimings::frame_ms).collect::<Vec<_>>())
    }

    /// Median over frames of the GPU time of the passes recorded for `light`.
    #[must_use]
    pub fn gpu_ms_median_for_light(&self, light: usize) -> Option<f64> {
        let per_frame: Vec<f64> = self
            .frames
            .iter()
            .filter(|f| f.gpu_ms.is_some())
            .map(|f| f.passes.iter().chain(&f.cpu_scopes).filter(|p| p.light == light).map(|p| p.ms).sum())
            .collect();
        median(&per_frame)
    }

    /// First and third quartiles of the frame time over frames (as [`Measured::gpu_ms_median`]):
    /// the spread tables print beside the median.
    #[must_use]
    pub fn gpu_ms_quartiles(&self) -> Option<(f64, f64)> {
        crate::quartiles(&self.frames.iter().filter(|f| f.gpu_ms.is_some()).map(FrameTimings::frame_ms).collect::<Vec<_>>())
    }

    /// Median over frames of the CPU work inside the frame (the frame's CPU scopes: a paper's CPU
    /// step, such as PVSM's kd-tree, and mid-frame read-backs' mapping), already part of
    /// [`FrameTimings::frame_ms`]; `None` for a technique with no CPU work in its frame.
    #[must_use]
    pub fn cpu_step_ms_median(&self) -> Option<f64> {
        if self.frames.iter().all(|f| f.cpu_scopes.is_empty()) {
            return None;
        }
        median(&self.frames.iter().map(|f| f.cpu_scopes.iter().map(|s| s.ms).sum()).collect::<Vec<_>>())
    }

    /// Smallest frame time over frames (as [`Measured::gpu_ms_median`]).
    #[must_use]
    pub fn gpu_ms_min(&self) -> Option<f64> {
        self.frames.iter().filter(|f| f.gpu_ms.is_some()).map(FrameTimings::frame_ms).reduce(f64::min)
    }

    /// Median CPU wall time from recording to the GPU going idle.
    #[must_use]
    pub fn cpu_ms_median(&self) -> f64 {
        median(&self.frames.iter().map(|f| f.cpu_wall_ms).collect::<Vec<_>>()).unwrap_or(f64::NAN)
    }

    /// Median over frames of each pass's time, passes of one name summed within a frame, in first-seen order.
    #[must_use]
    pub fn pass_medians(&self) -> Vec<(String, f64)> {
        self.pass_medians_where(|_| true)
    }

    /// As [`Measured::pass_medians`], over the passes recorded for `light` only.
    #[must_use]
    pub fn pass_medians_for_light(&self, light: usize) -> Vec<(String, f64)> {
        self.pass_medians_where(|pass| pass.light == light)
    }

    fn pass_medians_where(&self, keep: impl Fn(&ssm_core::PassTiming) -> bool) -> Vec<(String, f64)> {
        // GPU passes by name, then CPU work inside the frame (readback stalls, a paper's CPU step) marked `(cpu)`.
        let timed = |frame: &FrameTimings| -> Vec<(String, f64)> {
            frame
                .passes
                .iter()
                .filter(|p| keep(p))
                .map(|p| (p.name.clone(), p.ms))
                .chain(frame.cpu_scopes.iter().filter(|p| keep(p)).map(|p| (format!("{} (cpu)", p.name), p.ms)))
                .collect()
        };
        let mut names: Vec<String> = Vec::new();
        for (name, _) in self.frames.iter().flat_map(timed) {
            if !names.contains(&name) {
                names.push(name);
            }
        }
        names
            .into_iter()
            .map(|name| {
                let per_frame: Vec<f64> =
                    self.frames.iter().map(|f| timed(f).into_iter().filter(|(n, _)| *n == name).map(|(_, ms)| ms).sum()).collect();
                let ms = median(&per_frame).unwrap_or(f64::NAN);
                (name, ms)
            })
            .collect()
    }
}

/// The diagnostic every technique gets: the GPU memory (MiB) its buffers and textures hold after
/// its frames, measured by wgpu's allocation counters.
pub const MEMORY_DIAGNOSTIC: &str = "memory_mib";

/// Renders `info` with `params`: one warm-up frame, then `frames` timed frames; reads every
/// light's visibility, the shaded image and the debug outputs named in `debug` (those of
/// [`TechniqueInfo::debug_outputs`]; others are ignored).
///
/// # Errors
/// Technique or GPU errors, visibility outside [0, 1], or a debug output the technique returned
/// under a name it does not declare.
pub fn measure(
    renderer: &mut Renderer,
    info: &'static TechniqueInfo,
    params: &ParamValues,
    frames: u32,
    debug: &[&str],
) -> Result<Measured> {
    let job = MeasureJob { info, params, debug, count_work: false };
    let mut measured = measure_all(renderer, &[job], frames, FrameOrder::Sequential, || {})?;
    Ok(measured.remove(0))
}

/// One technique for [`measure_all`] to measure: what [`measure`] takes.
#[derive(Clone, Copy)]
pub struct MeasureJob<'a> {
    /// The technique.
    pub info: &'static TechniqueInfo,
    /// Its parameters.
    pub params: &'a ParamValues,
    /// The debug outputs to read after its frames.
    pub debug: &'a [&'a str],
    /// Count its work ([`crate::work::count`]) in one extra, untimed frame after its timed
    /// frames and outputs (`--count-work`), so that its times are unaffected.
    pub count_work: bool,
}

/// In what order [`measure_all`] renders the timed frames of several techniques.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FrameOrder {
    /// In turns: every technique's first frame, then every technique's second, and so on, each
    /// timed frame right after an untimed one of the same technique, so that it finds the caches
    /// as its own frame left them, as in a block. A slow spell of the machine (another process, a
    /// clock change) then falls on each technique alike and their ratio holds, where a block of
    /// frames each would charge it to one. Every technique exists until the last turn.
    #[default]
    Interleaved,
    /// Each technique's frames in one block, one technique existing at a time: for sets that do
    /// not fit in memory together.
    Sequential,
}

/// Measures each of `jobs` as [`measure`] does (one warm-up frame, `frames` timed frames, then its
/// outputs read), its timed frames in `order`; `timed` is called after each timed frame (for a
/// progress bar: `jobs.len() × frames` calls in all).
/// Each job's `memory_mib` counts what its own creation and frames allocated, whatever the order.
///
/// # Errors
/// As [`measure`], for the first job that fails.
pub fn measure_all(
    renderer: &mut Renderer,
    jobs: &[MeasureJob<'_>],
    frames: u32,
    order: FrameOrder,
    mut timed: impl FnMut(),
) -> Result<Vec<Measured>> {
    let frames = frames.max(1);
    let mut results = Vec::with_capacity(jobs.len());
    match order {
        FrameOrder::Sequential => {
            for job in jobs {
                let mut running = Running::start(renderer, job)?;
                for _ in 0..frames {
                    running.frame(renderer, job, false)?;
                    timed();
                }
                results.push(running.finish(renderer, job)?);
            }
        }
        FrameOrder::Interleaved => {
            let mut running = jobs.iter().map(|job| Running::start(renderer, job)).collect::<Result<Vec<_>>>()?;
            for _ in 1..frames {
                for (run, job) in running.iter_mut().zip(jobs) {
                    run.frame(renderer, job, true)?;
                    timed();
                }
            }
            // The last turn: each technique's outputs are read right after its own frame, before
            // the next technique renders into the shared visibility targets.
            for (mut run, job) in running.into_iter().zip(jobs) {
                run.frame(renderer, job, true)?;
                timed();
                results.push(run.finish(renderer, job)?);
            }
        }
    }
    Ok(results)
}

/// A technique being measured: created, warmed up, its frames so far and what it allocated.
struct Running {
    technique: Box<dyn ssm_core::ShadowTechnique>,
    timings: Vec<FrameTimings>,
    /// Bytes its creation and frames allocated (less what they freed).
    allocated: i64,
}

impl Running {
    /// Creates the technique and renders its warm-up frame: pipeline compilation and first-use
    /// allocation are not its cost.
    fn start(renderer: &mut Renderer, job: &MeasureJob<'_>) -> Result<Self> {
        let before = renderer.gpu.allocated_bytes();
        let mut technique = renderer.create_technique(job.info, job.params)?;
        renderer.render(technique.as_mut(), job.info.name)?;
        let allocated = renderer.gpu.allocated_bytes() - before;
        Ok(Self { technique, timings: Vec::new(), allocated })
    }

    /// One timed frame, after an untimed one with `warm`.
    fn frame(&mut self, renderer: &mut Renderer, job: &MeasureJob<'_>, warm: bool) -> Result<()> {
        let before = renderer.gpu.allocated_bytes();
        if warm {
            renderer.render(self.technique.as_mut(), job.info.name)?;
        }
        self.timings.push(renderer.render(self.technique.as_mut(), job.info.name)?);
        self.allocated += renderer.gpu.allocated_bytes() - before;
        Ok(())
    }

    /// Reads the outputs of its last frame.
    fn finish(mut self, renderer: &mut Renderer, job: &MeasureJob<'_>) -> Result<Measured> {
        let info = job.info;
        // What the technique holds after its frames, lazily allocated maps included.
        let memory_mib = self.allocated as f64 / f64::from(1u32 << 20);
        let visibility =
            (0..renderer.scene.light_count()).map(|light| renderer.read_visibility(light, info.name)).collect::<Result<Vec<_>>>()?;
        let shaded = renderer.shade()?;
        let mut diagnostics = self.technique.diagnostics(&renderer.gpu);
        diagnostics.push((MEMORY_DIAGNOSTIC.to_owned(), memory_mib));
        let requested: Vec<&str> = info.debug_outputs.iter().map(|o| o.name).filter(|name| job.debug.contains(name)).collect();
        let extra_images = if requested.is_empty() { Vec::new() } else { self.technique.debug_outputs(&renderer.gpu, &requested)? };
        for image in &extra_images {
            // Light k's image of an output may be named `<name>-light<k>`.
            let declared = |o: &&ssm_core::DebugOutput| {
                image.name == o.name
                    || image
                        .name
                        .strip_prefix(o.name)
                        .and_then(|rest| rest.strip_prefix("-light"))
                        .is_some_and(|k| k.parse::<usize>().is_ok())
            };
            if !info.debug_outputs.iter().filter(declared).any(|o| o.overlay == image.overlay) {
                return Err(ssm_core::Error::Technique {
                    technique: info.name.to_owned(),
                    message: format!("debug output `{}` is not declared in its TechniqueInfo::debug_outputs as returned", image.name),
                });
            }
        }
        // The counting frame builds an instance of its own: the timed one goes first, so that the
        // two are not held at once.
        drop(self.technique);
        let flip_noise = flip_noise_floor(renderer, &visibility, &shaded, &extra_images)?;
        let work = if job.count_work { crate::work::count(renderer, info, job.params)? } else { None };
        let work_note = (job.count_work && work.is_none()).then_some(crate::work::GROUND_TRUTH_NOT_COUNTED);
        // The counting build's diagnostics that the timed one cannot give (per-pass counts and
        // what a technique sets them against) join the row's.
        for (key, value) in work.iter().flat_map(|w| &w.diagnostics) {
            if !diagnostics.iter().any(|(known, _)| known == key) {
                diagnostics.push((key.clone(), *value));
            }
        }
        Ok(Measured {
            info,
            params: job.params.clone(),
            frames: self.timings,
            diagnostics,
            visibility,
            shaded,
            extra_images,
            work,
            work_note,
            flip_noise,
        })
    }
}

/// [`Measured::flip_noise`]: with the truth's noise images (one per light, `truth_noise` and
/// `truth_noise-light<k>`), the larger mean FLIP of `shaded` against the shading of `visibility`
/// moved down, then up, by the noise at each pixel; `None` without them (not the ground truth, or
/// its noise not asked for). Overwrites the renderer's visibility targets.
fn flip_noise_floor(
    renderer: &mut Renderer,
    visibility: &[Vec<f32>],
    shaded: &[u8],
    extra_images: &[ssm_core::ExtraImage],
) -> Result<Option<f64>> {
    let noise: Option<Vec<&[f32]>> = (0..visibility.len())
        .map(|light| {
            let name = if light == 0 {
                ssm_core::reference::NOISE_OUTPUT.to_owned()
            } else {
                format!("{}-light{light}", ssm_core::reference::NOISE_OUTPUT)
            };
            extra_images.iter().find(|image| image.name == name).map(|image| image.values.as_slice())
        })
        .collect();
    let Some(noise) = noise else { return Ok(None) };
    let mut floor = 0.0f64;
    for sign in [-1.0f32, 1.0] {
        let moved: Vec<Vec<f32>> =
            visibility.iter().zip(&noise).map(|(image, noise)| image.iter().zip(*noise).map(|(v, n)| v + sign * n).collect()).collect();
        let moved_shaded = renderer.shade_visibility(&moved)?;
        floor = floor.max(flip_mean(shaded, &moved_shaded, renderer.width(), renderer.height()));
    }
    Ok(Some(floor))
}

/// The stem of light `light`'s image files: `visibility` for light 0, `visibility-light<k>` for the others.
#[must_use]
pub fn visibility_stem(light: usize) -> String {
    if light == 0 { "visibility".to_owned() } else { format!("visibility-light{light}") }
}

/// Writes a measured technique's images under `dir`: `visibility.exr`/`.png`
/// (light 0; `visibility-light<k>.*` for the others; the EXR's `A` channel is
/// `coverage`) and `shaded.png`; with a reference, also `heatmap.png` (light
/// 0; `heatmap-light<k>.png` for the others) over the pixels it marks.
///
/// # Errors
/// File errors.
pub fn write_images(
    dir: &Path,
    measured: &Measured,
    (width, height): (u32, u32),
    coverage: &[bool],
    reference: Option<(&Measured, &[bool])>,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::write(dir, e))?;
    for (light, visibility) in measured.visibility.iter().enumerate() {
        let stem = visibility_stem(light);
        write_exr_gray(&dir.join(format!("{stem}.exr")), width, height, visibility, coverage)?;
        write_png_gray16(&dir.join(format!("{stem}.png")), width, height, visibility)?;
    }
    write_png_rgba8(&dir.join("shaded.png"), width, height, &measured.shaded)?;
    for extra in &measured.extra_images {
        let extra_coverage: &[bool] =
            if (extra.width, extra.height) == (width, height) { coverage } else { &vec![true; extra.values.len()] };
        write_exr_gray(&dir.join(format!("{}.exr", extra.name)), extra.width, extra.height, &extra.values, extra_coverage)?;
        write_png_gray16(&dir.join(format!("{}.png", extra.name)), extra.width, extra.height, &extra.values)?;
    }
    if let Some((reference, covered)) = reference {
        for (light, (truth, image)) in reference.visibility.iter().zip(&measured.visibility).enumerate() {
            let file = dir.join(if light == 0 { "heatmap.png".to_owned() } else { format!("heatmap-light{light}.png") });
            let rgb = heat_map(truth, image, covered, 0.5);
            let picture =
                image::RgbImage::from_raw(width, height, rgb).ok_or_else(|| Error::write(&file, ssm_core::Reason("buffer size".into())))?;
            picture.save(&file).map_err(|e| Error::write(&file, e))?;
        }
        let file = dir.join("flip.png");
        let rgb = flip_map(&reference.shaded, &measured.shaded, width, height);
        let picture =
            image::RgbImage::from_raw(width, height, rgb).ok_or_else(|| Error::write(&file, ssm_core::Reason("buffer size".into())))?;
        picture.save(&file).map_err(|e| Error::write(&file, e))?;
    }
    Ok(())
}

/// Which pixels the error metrics cover.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PixelSet {
    /// Every pixel a surface covers.
    All,
    /// Only pixels of receivers (role `receiver` or `both`): what techniques that split roles shadow.
    Receivers,
}

/// The pixels `set` selects, from the renderer's G-buffer.
///
/// # Errors
/// A readback error.
pub fn pixel_mask(renderer: &Renderer, set: PixelSet) -> Result<Vec<bool>> {
    // Coverage is the position's w channel: 1 where geometry was drawn.
    let positions = renderer.read_positions()?;
    Ok(match set {
        PixelSet::All => positions.iter().map(|p| p[3] > 0.5).collect(),
        PixelSet::Receivers => positions
            .iter()
            .zip(renderer.read_normals()?)
            .map(|(p, n)| p[3] > 0.5 && GBuffer::flags(n[3]) & GBuffer::RECEIVES != 0)
            .collect(),
    })
}

/// One row of `results.csv` / `sweep.csv`.
#[derive(Clone, Debug)]
pub struct Row {
    /// Scene name as given.
    pub scene: String,
    /// Technique name.
    pub technique: String,
    /// The light this row measures, or `None` for all lights together (errors
    /// averaged over lights, time summed).
    pub light: Option<usize>,
    /// Parameters, `name=value;...`.
    pub params: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Median GPU ms per frame (sum of passes; of this light's passes in a per-light row), when timestamps exist.
    pub gpu_ms_median: Option<f64>,
    /// Minimum GPU ms per frame.
    pub gpu_ms_min: Option<f64>,
    /// First and third quartiles of the GPU ms per frame: the spread printed beside the median
    /// (`None` in per-light rows and without timestamps).
    pub gpu_ms_quartiles: Option<(f64, f64)>,
    /// Median CPU ms per frame of the work inside the frame that a paper puts on the CPU (and
    /// mid-frame read-backs' mapping), part of the frame's time; `None` where there is none.
    pub cpu_step_ms: Option<f64>,
    /// Median CPU wall ms per frame.
    pub cpu_ms: f64,
    /// Error metrics against the reference, averaged over lights.
    pub metrics: ErrorMetrics,
    /// Mean FLIP of the shaded image against the shaded reference.
    pub flip: f64,
    /// FLIP's noise floor on these pixels: what the reference's own noise alone shows
    /// ([`Measured::flip_noise`]); `None` without the reference's noise.
    pub flip_noise: Option<f64>,
    /// Adapter description.
    pub adapter: String,
    /// GPU timestamps or CPU wall time only.
    pub timing_source: TimingSource,
    /// Median ms per pass name.
    pub passes: Vec<(String, f64)>,
    /// Technique diagnostics.
    pub diagnostics: Vec<(String, f64)>,
    /// Names of the technique's extra images (`<name>.png` beside its visibility).
    pub extra_images: Vec<String>,
    /// Those of them the HTML report draws over the visibility image.
    pub overlays: Vec<String>,
    /// The frame's counted work (every light; `--count-work`), in the `all` row only: `None`
    /// when not counted, and in per-light rows.
    pub work: Option<FrameWork>,
}

/// The leading columns of `results.csv`, in order; more follow.
pub const CSV_COLUMNS: &[&str] = &[
    "scene",
    "technique",
    "params",
    "width",
    "height",
    "gpu_ms_median",
    "gpu_ms_min",
    "cpu_ms",
    "mae_penumbra",
    "rmse",
    "max_abs",
    "psnr",
    "ssim",
    "frac_over_0_05",
    "adapter",
    "light",
    "flip_mean",
    "mean_signed_error",
    "umbra_leak",
    "penumbra_pixels",
    "umbra_pixels",
    "timing_source",
    "passes_ms",
    "diagnostics",
    "vertex_invocations",
    "fragment_invocations",
    "compute_invocations",
    "texel_reads",
    "passes_work",
    "mae",
    "truth_noise",
    "truth_noise_penumbra",
    "shadowed_pixels",
    "gpu_ms_q1",
    "gpu_ms_q3",
    "cpu_step_ms",
    "read_bytes",
    "flip_noise",
];

/// Builds the row of `measured` against `reference` over all lights (same
/// pixels; `covered` marks the pixels the metrics cover): errors averaged over
/// lights, FLIP of the shaded image (all lights), GPU time of the whole frame.
#[must_use]
pub fn row(scene: &str, renderer: &Renderer, measured: &Measured, reference: &Measured, covered: &[bool]) -> Row {
    let (width, height) = (renderer.width(), renderer.height());
    let per_light: Vec<ErrorMetrics> = measured
        .visibility
        .iter()
        .zip(&reference.visibility)
        .enumerate()
        .map(|(light, (image, truth))| {
            compare_with_noise(truth, truth_noise(reference, light), image, covered, width as usize, height as usize)
        })
        .collect();
    Row {
        scene: scene.to_owned(),
        technique: measured.info.name.to_owned(),
        light: None,
        params: measured.params.to_string(),
        width,
        height,
        gpu_ms_median: measured.gpu_ms_median(),
        gpu_ms_min: measured.gpu_ms_min(),
        gpu_ms_quartiles: measured.gpu_ms_quartiles(),
        cpu_step_ms: measured.cpu_step_ms_median(),
        cpu_ms: measured.cpu_ms_median(),
        metrics: average(&per_light),
        flip: flip_mean(&reference.shaded, &measured.shaded, width, height),
        flip_noise: reference.flip_noise,
        adapter: renderer.gpu.describe(),
        timing_source: measured.frames.first().map_or(TimingSource::CpuWallOnly, |f| f.source),
        passes: measured.pass_medians(),
        diagnostics: measured.diagnostics.clone(),
        extra_images: measured.extra_images.iter().map(|e| e.name.clone()).collect(),
        overlays: measured.extra_images.iter().filter(|e| e.overlay).map(|e| e.name.clone()).collect(),
        work: measured.work.clone(),
    }
}

/// The total row (as [`row`]) followed, when the scene has more than one
/// light, by one row per light: that light's errors and the GPU time of the
/// passes recorded for it. The shaded image combines all lights, so per-light
/// rows repeat the total's FLIP.
#[must_use]
pub fn rows_per_light(scene: &str, renderer: &Renderer, measured: &Measured, reference: &Measured, covered: &[bool]) -> Vec<Row> {
    let total = row(scene, renderer, measured, reference, covered);
    let (width, height) = (renderer.width() as usize, renderer.height() as usize);
    let mut rows = Vec::new();
    if measured.visibility.len() > 1 {
        for (light, (image, truth)) in measured.visibility.iter().zip(&reference.visibility).enumerate() {
            rows.push(Row {
                light: Some(light),
                gpu_ms_median: measured.gpu_ms_median_for_light(light),
                gpu_ms_min: None,
                gpu_ms_quartiles: None,
                cpu_step_ms: None,
                metrics: compare_with_noise(truth, truth_noise(reference, light), image, covered, width, height),
                passes: measured.pass_medians_for_light(light),
                // Counted over the whole frame: the `all` row holds it.
                work: None,
                ..total.clone()
            });
        }
    }
    rows.insert(0, total);
    rows
}

/// The ground truth's noise image of light `light`, when the reference was measured with its
/// noise output ([`ssm_core::reference::NOISE_OUTPUT`]).
#[must_use]
pub fn truth_noise(reference: &Measured, light: usize) -> Option<&[f32]> {
    let name = if light == 0 {
        ssm_core::reference::NOISE_OUTPUT.to_owned()
    } else {
        format!("{}-light{light}", ssm_core::reference::NOISE_OUTPUT)
    };
    reference.extra_images.iter().find(|image| image.name == name).map(|image| image.values.as_slice())
}

/// The errors of several lights as one: means of the per-pixel measures, the largest error, the pixel counts summed (the `all` row).
#[must_use]
pub fn average(all: &[ErrorMetrics]) -> ErrorMetrics {
    let n = all.len().max(1) as f64;
    let mean = |f: &dyn Fn(&ErrorMetrics) -> f64| all.iter().map(f).sum::<f64>() / n;
    let mean_noise = |f: &dyn Fn(&ErrorMetrics) -> Option<f64>| all.iter().map(f).sum::<Option<f64>>().map(|sum| sum / n);
    ErrorMetrics {
        mae: mean(&|m| m.mae),
        mae_penumbra: mean(&|m| m.mae_penumbra),
        truth_noise: mean_noise(&|m| m.truth_noise),
        truth_noise_penumbra: mean_noise(&|m| m.truth_noise_penumbra),
        shadowed_pixels: all.iter().map(|m| m.shadowed_pixels).sum(),
        rmse: mean(&|m| m.rmse),
        max_abs: all.iter().map(|m| m.max_abs).fold(0.0, f64::max),
        psnr: mean(&|m| m.psnr),
        ssim: mean(&|m| m.ssim),
        frac_over_0_05: mean(&|m| m.frac_over_0_05),
        mean_signed: mean(&|m| m.mean_signed),
        umbra_leak: mean(&|m| m.umbra_leak),
        pixels: all.iter().map(|m| m.pixels).sum(),
        penumbra_pixels: all.iter().map(|m| m.penumbra_pixels).sum(),
        umbra_pixels: all.iter().map(|m| m.umbra_pixels).sum(),
    }
}

fn number(value: Option<f64>, decimals: usize) -> String {
    match value {
        Some(v) if v.is_infinite() => "inf".into(),
        Some(v) if v.is_finite() => format!("{v:.decimals$}"),
        _ => String::new(),
    }
}

fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_owned() }
}

fn pairs(items: &[(String, f64)]) -> String {
    items.iter().map(|(k, v)| format!("{k}={v:.4}")).collect::<Vec<_>>().join(";")
}

impl Row {
    fn csv_fields(&self) -> Vec<String> {
        let m = &self.metrics;
        vec![
            csv_field(&self.scene),
            csv_field(&self.technique),
            csv_field(&self.params),
            self.width.to_string(),
            self.height.to_string(),
            number(self.gpu_ms_median, 4),
            number(self.gpu_ms_min, 4),
            number(Some(self.cpu_ms), 4),
            number(Some(m.mae_penumbra), 6),
            number(Some(m.rmse), 6),
            number(Some(m.max_abs), 6),
            number(Some(m.psnr), 4),
            number(Some(m.ssim), 6),
            number(Some(m.frac_over_0_05), 6),
            csv_field(&self.adapter),
            self.light.map_or_else(|| "all".to_owned(), |light| light.to_string()),
            number(Some(self.flip), 6),
            number(Some(m.mean_signed), 6),
            number(Some(m.umbra_leak), 6),
            m.penumbra_pixels.to_string(),
            m.umbra_pixels.to_string(),
            match self.timing_source {
                TimingSource::GpuTimestamps => "gpu_timestamps".into(),
                TimingSource::CpuWallOnly => "cpu_wall_only".into(),
            },
            csv_field(&pairs(&self.passes)),
            csv_field(&pairs(&self.diagnostics)),
        ]
        .into_iter()
        .chain(self.work_fields())
        .chain([number(Some(m.mae), 6), number(m.truth_noise, 6), number(m.truth_noise_penumbra, 6), m.shadowed_pixels.to_string()])
        .chain([number(self.gpu_ms_quartiles.map(|q| q.0), 4), number(self.gpu_ms_quartiles.map(|q| q.1), 4), number(self.cpu_step_ms, 4)])
        // Derived from `passes_work` (each pass's `read_bytes`), which the CSV reads back.
        .chain([self.work.as_ref().map_or_else(String::new, |work| crate::work::field(crate::work::Totals::of(work).read_bytes))])
        .chain([number(self.flip_noise, 6)])
        .collect()
    }

    /// The work columns: per frame (every light) vertex, fragment and compute invocations and
    /// texel reads, then `passes_work`; empty where not counted.
    fn work_fields(&self) -> [String; 5] {
        match &self.work {
            None => Default::default(),
            Some(work) => {
                let totals = crate::work::Totals::of(work);
                [
                    crate::work::field(totals.vertex_invocations),
                    crate::work::field(totals.fragment_invocations),
                    crate::work::field(totals.compute_invocations),
                    crate::work::field(totals.texel_reads),
                    csv_field(&work.passes_column()),
                ]
            }
        }
    }
}

/// The CSV text of `rows`, header first.
#[must_use]
pub fn csv(rows: &[Row]) -> String {
    let mut out = CSV_COLUMNS.join(",") + "\n";
    for row in rows {
        out += &row.csv_fields().join(",");
        out.push('\n');
    }
    out
}

/// One row as JSON (`--format json`): the CSV's columns, typed; the errors under `metrics`,
/// passes and diagnostics as objects; infinite or missing numbers as `null`.
#[must_use]
pub fn row_json(row: &Row) -> serde_json::Value {
    let object = |items: &[(String, f64)]| items.iter().map(|(k, v)| (k.clone(), finite(*v))).collect::<serde_json::Map<_, _>>();
    let m = &row.metrics;
    let totals = row.work.as_ref().map(crate::work::Totals::of);
    serde_json::json!({
        "scene": row.scene,
        "technique": row.technique,
        "light": row.light,
        "params": row.params,
        "width": row.width,
        "height": row.height,
        "gpu_ms_median": row.gpu_ms_median.map(finite),
        "gpu_ms_min": row.gpu_ms_min.map(finite),
        "gpu_ms_iqr": row.gpu_ms_quartiles.map(|(q1, q3)| [finite(q1), finite(q3)]),
        "cpu_step_ms": row.cpu_step_ms.map(finite),
        "flip_noise": row.flip_noise.map(finite),
        "cpu_ms": finite(row.cpu_ms),
        "metrics": {
            "mae": finite(m.mae),
            "truth_noise": m.truth_noise.map(finite),
            "mae_penumbra": finite(m.mae_penumbra),
            "truth_noise_penumbra": m.truth_noise_penumbra.map(finite),
            "shadowed_pixels": m.shadowed_pixels,
            "rmse": finite(m.rmse),
            "max_abs": finite(m.max_abs),
            "psnr": finite(m.psnr),
            "ssim": finite(m.ssim),
            "frac_over_0_05": finite(m.frac_over_0_05),
            "mean_signed_error": finite(m.mean_signed),
            "umbra_leak": finite(m.umbra_leak),
            "penumbra_pixels": m.penumbra_pixels,
            "umbra_pixels": m.umbra_pixels,
        },
        "flip_mean": finite(row.flip),
        "adapter": row.adapter,
        "timing_source": match row.timing_source {
            TimingSource::GpuTimestamps => "gpu_timestamps",
            TimingSource::CpuWallOnly => "cpu_wall_only",
        },
        "passes_ms": object(&row.passes),
        "diagnostics": object(&row.diagnostics),
        "vertex_invocations": totals.and_then(|t| t.vertex_invocations),
        "fragment_invocations": totals.and_then(|t| t.fragment_invocations),
        "compute_invocations": totals.and_then(|t| t.compute_invocations),
        "texel_reads": totals.and_then(|t| t.texel_reads),
        "read_bytes": totals.and_then(|t| t.read_bytes),
        "passes_work": row.work.as_ref().map(FrameWork::passes_column),
        // Every pass's counts, and whether the invocations (pipeline_statistics) and the texel
        // reads (shader_counts) were counted at all.
        "work": row.work.as_ref().map(|work| serde_json::to_value(work).unwrap_or(serde_json::Value::Null)),
    })
}

/// Rows from the text of a `results.csv` or `sweep.csv` that [`csv`] wrote (what `ssm merge`
/// reads back). The CSV does not hold the image names or the count of compared pixels: they come
/// back empty. Numbers come back as printed, so that writing the rows again gives the same text.
///
/// # Errors
/// A header other than [`CSV_COLUMNS`], a row with another number of fields, or a field that
/// does not parse, naming the line and the column.
pub fn parse_csv(text: &str) -> anyhow::Result<Vec<Row>> {
    use anyhow::Context as _;
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    if header != CSV_COLUMNS.join(",") {
        anyhow::bail!("the header is not ssm's CSV header ({})", CSV_COLUMNS.join(","));
    }
    lines
        .enumerate()
        .filter(|(_, line)| !line.is_empty())
        .map(|(index, line)| {
            let line_number = index + 2;
            let fields = split_csv_line(line).with_context(|| format!("line {line_number}"))?;
            if fields.len() != CSV_COLUMNS.len() {
                anyhow::bail!("line {line_number}: {} fields, expected {}", fields.len(), CSV_COLUMNS.len());
            }
            let field = |name: &str| -> &str {
                let column = CSV_COLUMNS.iter().position(|c| *c == name).unwrap_or(0);
                fields[column].as_str()
            };
            let float = |name: &str| -> anyhow::Result<f64> {
                match field(name) {
                    "" => Ok(f64::NAN),
                    text => text.parse().with_context(|| format!("line {line_number}, {name}: `{text}` is not a number")),
                }
            };
            let optional =
                |name: &str| -> anyhow::Result<Option<f64>> { if field(name).is_empty() { Ok(None) } else { float(name).map(Some) } };
            let whole = |name: &str| -> anyhow::Result<usize> {
                field(name).parse().with_context(|| format!("line {line_number}, {name}: `{}` is not a whole number", field(name)))
            };
            let pairs = |name: &str| -> anyhow::Result<Vec<(String, f64)>> {
                field(name)
                    .split(';')
                    .filter(|p| !p.is_empty())
                    .map(|pair| {
                        let (key, value) =
                            pair.split_once('=').with_context(|| format!("line {line_number}, {name}: `{pair}` is not key=value"))?;
                        Ok((
                            key.to_owned(),
                            value.parse().with_context(|| format!("line {line_number}, {name}: `{value}` is not a number"))?,
                        ))
                    })
                    .collect()
            };
            Ok(Row {
                scene: field("scene").to_owned(),
                technique: field("technique").to_owned(),
                light: match field("light") {
                    "all" => None,
                    _ => Some(whole("light")?),
                },
                params: field("params").to_owned(),
                width: u32::try_from(whole("width")?).context("width")?,
                height: u32::try_from(whole("height")?).context("height")?,
                gpu_ms_median: optional("gpu_ms_median")?,
                gpu_ms_min: optional("gpu_ms_min")?,
                gpu_ms_quartiles: optional("gpu_ms_q1")?.zip(optional("gpu_ms_q3")?),
                cpu_step_ms: optional("cpu_step_ms")?,
                flip_noise: optional("flip_noise")?,
                cpu_ms: float("cpu_ms")?,
                metrics: ErrorMetrics {
                    mae: float("mae")?,
                    mae_penumbra: float("mae_penumbra")?,
                    truth_noise: optional("truth_noise")?,
                    truth_noise_penumbra: optional("truth_noise_penumbra")?,
                    shadowed_pixels: whole("shadowed_pixels")?,
                    rmse: float("rmse")?,
                    max_abs: float("max_abs")?,
                    psnr: float("psnr")?,
                    ssim: float("ssim")?,
                    frac_over_0_05: float("frac_over_0_05")?,
                    mean_signed: float("mean_signed_error")?,
                    umbra_leak: float("umbra_leak")?,
                    pixels: 0,
                    penumbra_pixels: whole("penumbra_pixels")?,
                    umbra_pixels: whole("umbra_pixels")?,
                },
                flip: float("flip_mean")?,
                adapter: field("adapter").to_owned(),
                timing_source: match field("timing_source") {
                    "gpu_timestamps" => TimingSource::GpuTimestamps,
                    "cpu_wall_only" => TimingSource::CpuWallOnly,
                    other => anyhow::bail!("line {line_number}, timing_source: `{other}` is neither gpu_timestamps nor cpu_wall_only"),
                },
                passes: pairs("passes_ms")?,
                diagnostics: pairs("diagnostics")?,
                extra_images: Vec::new(),
                overlays: Vec::new(),
                work: {
                    let columns = ["vertex_invocations", "fragment_invocations", "compute_invocations", "texel_reads", "passes_work"];
                    if columns.iter().all(|c| field(c).is_empty()) {
                        None
                    } else {
                        Some(FrameWork {
                            pipeline_statistics: !field("vertex_invocations").is_empty(),
                            shader_counts: !field("texel_reads").is_empty(),
                            passes: crate::work::parse_passes_column(field("passes_work"))
                                .with_context(|| format!("line {line_number}"))?,
                            uncounted_passes: 0,
                            // Already among the row's diagnostics column.
                            diagnostics: Vec::new(),
                        })
                    }
                },
            })
        })
        .collect()
}

/// The fields of one CSV line: separated by commas, a field in double quotes may hold commas and
/// doubled quotes (as [`csv_field`] writes them).
fn split_csv_line(line: &str) -> anyhow::Result<Vec<String>> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut chars = line.chars().peekable();
    let mut quoted = false;
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', false) if field.is_empty() => quoted = true,
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', true) => quoted = false,
            (',', false) => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    if quoted {
        anyhow::bail!("a quoted field is not closed");
    }
    fields.push(field);
    Ok(fields)
}

/// The columns of the report tables (Markdown and HTML).
const TABLE_HEADER: [&str; 12] = [
    "technique",
    "params",
    "GPU ms (median)",
    "GPU ms (IQR)",
    "MAE (± truth)",
    "MAE penumbra (± truth)",
    "RMSE",
    "max",
    "PSNR dB",
    "SSIM",
    "> 0.05",
    "FLIP",
];

/// An error with the ground truth's own error over the same pixels beside it: `0.0123 ± 0.0015`.
#[must_use]
pub fn with_noise(error: f64, noise: Option<f64>) -> String {
    match noise {
        Some(noise) => format!("{error:.4} ± {noise:.4}"),
        None => format!("{error:.4}"),
    }
}

/// One row of the report tables, as text (the technique name without markup).
fn table_cells(r: &Row) -> [String; 12] {
    let m = &r.metrics;
    [
        r.technique.clone(),
        r.params.replace(';', "; "),
        number(r.gpu_ms_median, 3),
        r.gpu_ms_quartiles.map_or_else(String::new, |(q1, q3)| format!("{q1:.3}–{q3:.3}")),
        with_noise(m.mae, m.truth_noise),
        with_noise(m.mae_penumbra, m.truth_noise_penumbra),
        format!("{:.4}", m.rmse),
        format!("{:.3}", m.max_abs),
        number(Some(m.psnr), 2),
        format!("{:.4}", m.ssim),
        format!("{:.2}%", m.frac_over_0_05 * 100.0),
        with_noise(r.flip, r.flip_noise),
    ]
}

/// What follows the technique's name in a per-light row: ` · light <k>`.
fn light_suffix(row: &Row) -> String {
    row.light.map(|light| format!(" · light {light}")).unwrap_or_default()
}

/// The Markdown table of `rows`.
#[must_use]
pub fn markdown_table(rows: &[Row]) -> String {
    let mut out = format!("| {} |\n|---|---|{}\n", TABLE_HEADER.join(" | "), "---:|".repeat(TABLE_HEADER.len() - 2));
    for r in rows {
        let mut cells = table_cells(r);
        cells[0] = format!("`{}`{}", cells[0], light_suffix(r));
        let _ = writeln!(out, "| {} |", cells.join(" | "));
    }
    out
}

/// What the report header says about the run.
pub struct ReportContext<'a> {
    /// Scene as given.
    pub scene: &'a str,
    /// Adapter description.
    pub adapter: &'a str,
    /// Image size.
    pub size: (u32, u32),
    /// Timed frames per technique.
    pub frames: u32,
    /// The reference's parameters.
    pub reference_params: &'a str,
    /// What the reference's tracing cost (or that it came from the cache).
    pub reference_cost: &'a str,
    /// Techniques not run, with the reason.
    pub skipped: &'a [(String, String)],
    /// The per-pass time chart beside the report (`passes.svg`), when one was drawn.
    pub pass_chart: Option<&'a str>,
    /// Whether the work was counted (`--count-work`): the reports then have a section on it.
    pub count_work: bool,
    /// The per-pass work charts beside the report, when drawn: (what they count, `passes-reads.svg`).
    pub work_charts: &'a [(&'a str, &'a str)],
}

/// The counted techniques of `rows` (their `all` rows), in order.
fn counted(rows: &[Row]) -> Vec<(&str, &FrameWork)> {
    rows.iter().filter(|r| r.light.is_none()).filter_map(|r| r.work.as_ref().map(|w| (r.technique.as_str(), w))).collect()
}

/// The pixels of the rows' images (for texel reads per pixel).
fn pixels_of(rows: &[Row]) -> u64 {
    rows.first().map_or(1, |r| u64::from(r.width) * u64::from(r.height))
}

/// `report.md`'s section on the counted work: how it is counted, the frame's totals per
/// technique, each pass's counts, what `-` means, and the ground truth's.
fn markdown_work(context: &ReportContext<'_>, rows: &[Row]) -> String {
    use crate::work::{FRAME_HEADER, HOW_COUNTED, PASS_HEADER, frame_table, notes, pass_table};
    if !context.count_work {
        return String::new();
    }
    let techniques = counted(rows);
    let table = |header: &[&str], cells: Vec<[String; 13]>| {
        let mut out = format!("| {} |\n|---|{}\n", header.join(" | "), "---:|".repeat(header.len() - 1));
        for row in cells {
            let _ = writeln!(out, "| {} |", row.join(" | "));
        }
        out
    };
    let mut out = format!("\n## Counted work\n\n{HOW_COUNTED}\n\nPer frame:\n\n");
    out += &table(&FRAME_HEADER, frame_table(&techniques, pixels_of(rows)));
    out += "\nPer pass:\n\n";
    out += &table(&PASS_HEADER, pass_table(&techniques));
    for note in notes(&techniques) {
        let _ = writeln!(out, "\n{note}");
    }
    let _ = writeln!(out, "\nGround truth (`reference`): {}.", crate::work::GROUND_TRUTH_NOT_COUNTED);
    out
}

/// `index.html`'s section on the counted work: [`markdown_work`]'s tables and notes, and the
/// per-pass work charts.
fn html_work(context: &ReportContext<'_>, rows: &[Row]) -> String {
    use crate::work::{FRAME_HEADER, HOW_COUNTED, PASS_HEADER, frame_table, notes, pass_table};
    if !context.count_work {
        return String::new();
    }
    let techniques = counted(rows);
    let table = |id: &str, header: &[&str], cells: Vec<[String; 13]>| {
        let mut out = format!("<table id=\"{id}\">\n<tr>");
        for name in header {
            let _ = write!(out, "<th>{}</th>", escape(name));
        }
        out += "</tr>\n";
        for row in cells {
            out += "<tr>";
            for cell in row {
                let _ = write!(out, "<td>{}</td>", escape(&cell));
            }
            out += "</tr>\n";
        }
        out + "</table>\n"
    };
    let mut out =
        format!("<h2 id=\"counted-work\">Counted work</h2>\n<p class=\"legend\">{}</p>\n<p>Per frame:</p>\n", escape(HOW_COUNTED));
    out += &table("work-frames", &FRAME_HEADER, frame_table(&techniques, pixels_of(rows)));
    out += "<p>Per pass:</p>\n";
    out += &table("work-passes", &PASS_HEADER, pass_table(&techniques));
    for note in notes(&techniques) {
        let _ = writeln!(out, "<p>{}</p>", escape(&note));
    }
    let _ = writeln!(out, "<p>Ground truth (<code>reference</code>): {}.</p>", crate::work::GROUND_TRUTH_NOT_COUNTED);
    out
}

/// `report.md`: the context and the table.
#[must_use]
pub fn markdown_report(context: &ReportContext<'_>, rows: &[Row]) -> String {
    let mut out = format!(
        "# ssm compare: `{}`\n\n{}×{}, median of {} frames after one warm-up, on {}.\nGround truth: `reference` [{}]: {}. Errors are against it, on the same pixels; MAE covers the pixels that either the truth or the technique shadows, MAE penumbra the truth's umbra and penumbra; ± is the ground truth's own error over the same pixels (two errors closer than their two ± are a tie). GPU time is the sum of each technique's timed passes.\n\n",
        context.scene, context.size.0, context.size.1, context.frames, context.adapter, context.reference_params, context.reference_cost
    );
    out += &markdown_table(rows);
    if let Some(note) = beyond_frame_note(rows) {
        let _ = writeln!(out, "\n{note}");
    }
    for (name, why) in context.skipped {
        let _ = writeln!(out, "\nNot run: `{name}`: {why}");
    }
    out += &markdown_work(context, rows);
    out
}

/// The pixels the framework answered past the light frame's widest angle, per technique
/// ([`ssm_core::BEYOND_FRAME_DIAGNOSTIC`]), as one sentence; `None` when it answered none.
#[must_use]
pub fn beyond_frame_note(rows: &[Row]) -> Option<String> {
    let answered: Vec<String> = rows
        .iter()
        .filter(|r| r.light.is_none())
        .filter_map(|r| {
            let pixels = r.diagnostics.iter().find(|(key, _)| key == ssm_core::BEYOND_FRAME_DIAGNOSTIC).map(|(_, v)| *v)?;
            (pixels > 0.0).then(|| format!("`{}` {pixels:.0}", r.technique))
        })
        .collect();
    (!answered.is_empty()).then(|| {
        format!(
            "Past the light frame's widest angle (about 84° off the light's normal) these techniques' maps have no texel: the framework answered those pixels with a hard shadow from the light's centre (pixels, summed over lights: {}).",
            answered.join(", ")
        )
    })
}

/// A number for JSON: `null` when not finite (JSON has no infinity; PSNR of identical images is one).
fn finite(value: f64) -> serde_json::Value {
    if value.is_finite() { serde_json::json!(value) } else { serde_json::Value::Null }
}

/// The interactive viewer's script (`ssm-bench/assets/viewer.js`), written beside `index.html` as `viewer.js`.
pub const VIEWER_SCRIPT: &str = include_str!("../assets/viewer.js");

/// One image set the interactive viewer shows: a technique (or the ground truth) and its visibility per light.
pub struct ViewerImages<'a> {
    /// The technique's name (its folder in the report).
    pub technique: &'a str,
    /// Visibility per light, row-major, in `[0, 1]`.
    pub visibility: &'a [Vec<f32>],
    /// Whether `<technique>/flip.png` was written (every technique but the ground truth).
    pub has_flip: bool,
}

/// `viewer-data.js`: what the interactive viewer of `index.html` reads, as
/// one script that sets `window.SSM_DATA` (a page opened from disk may load
/// scripts, but not read back the pixels of its own images): the size, the
/// covered pixels, each technique's visibility per light as 16-bit values
/// (base64, little-endian), the paths of its shaded and FLIP images, and the
/// metrics table's rows. `images` starts with the ground truth.
#[must_use]
pub fn viewer_data(
    reference_name: &str,
    (width, height): (u32, u32),
    coverage: &[bool],
    images: &[ViewerImages<'_>],
    rows: &[Row],
) -> String {
    use base64::Engine as _;
    let encode = |bytes: &[u8]| base64::engine::general_purpose::STANDARD.encode(bytes);
    let quantised =
        |values: &[f32]| -> Vec<u8> { values.iter().flat_map(|v| ((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_le_bytes()).collect() };
    let covered: Vec<u8> = coverage.iter().map(|&c| u8::from(c)).collect();
    let mut image_sets = serde_json::Map::new();
    for set in images {
        image_sets.insert(
            set.technique.to_owned(),
            serde_json::json!({
                "visibility": set.visibility.iter().map(|v| encode(&quantised(v))).collect::<Vec<_>>(),
                "shaded": format!("{}/shaded.png", set.technique),
                "flip": set.has_flip.then(|| format!("{}/flip.png", set.technique)),
            }),
        );
    }
    let table: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            let m = &r.metrics;
            let mut row = serde_json::json!({
                "technique": r.technique,
                "light": r.light.map_or_else(|| "all".to_owned(), |l| l.to_string()),
                "gpu_ms": r.gpu_ms_median.map_or(serde_json::Value::Null, finite),
                "mae": finite(m.mae),
                "truth_noise": m.truth_noise.map_or(serde_json::Value::Null, finite),
                "mae_penumbra": finite(m.mae_penumbra),
                "rmse": finite(m.rmse),
                "ssim": finite(m.ssim),
                "psnr": finite(m.psnr),
                "umbra_leak": finite(m.umbra_leak),
                "frac_over_0_05": finite(m.frac_over_0_05),
                "flip": finite(r.flip),
                "passes": r.passes.iter().map(|(name, ms)| format!("{name} {ms:.2}")).collect::<Vec<_>>().join(", "),
            });
            if let Some(work) = &r.work {
                let totals = crate::work::Totals::of(work);
                let counts = [
                    ("vertex_invocations", totals.vertex_invocations),
                    ("fragment_invocations", totals.fragment_invocations),
                    ("compute_invocations", totals.compute_invocations),
                    ("texel_reads", totals.texel_reads),
                    ("read_bytes", totals.read_bytes),
                    ("atomics", totals.atomics),
                    ("target_bytes", Some(totals.target_bytes)),
                    ("storage_bytes", totals.storage_bytes),
                ];
                for (key, count) in counts {
                    row[key] = count.map_or(serde_json::Value::Null, |n| serde_json::json!(n));
                }
                row["passes_work"] = serde_json::json!(pass_work_summary(work));
            }
            row
        })
        .collect();
    let lights = images.first().map_or(1, |set| set.visibility.len());
    let data = serde_json::json!({
        "width": width,
        "height": height,
        "lights": lights,
        "reference": reference_name,
        "techniques": images.iter().map(|set| set.technique).collect::<Vec<_>>(),
        "covered": encode(&covered),
        "images": image_sets,
        "rows": table,
        "columns": [
            ["technique", "technique"], ["light", "light"], ["gpu_ms", "GPU ms"], ["mae", "MAE"],
            ["truth_noise", "± truth"], ["mae_penumbra", "MAE pen."], ["rmse", "RMSE"], ["ssim", "SSIM"], ["psnr", "PSNR dB"], ["umbra_leak", "umbra leak"],
            ["frac_over_0_05", "> 0.05"], ["flip", "FLIP"], ["passes", "passes, ms"],
        ],
        // The table's columns when it shows counted work instead of milliseconds (`null`: not counted).
        "work_columns": rows.iter().any(|r| r.work.is_some()).then(|| serde_json::json!([
            ["technique", "technique"], ["light", "light"], ["vertex_invocations", "vertex inv."],
            ["fragment_invocations", "fragment inv."], ["compute_invocations", "compute inv."], ["texel_reads", "texel reads"],
            ["read_bytes", "bytes read"], ["atomics", "atomics"], ["target_bytes", "target bytes"], ["storage_bytes", "storage bytes"],
            ["mae", "MAE"], ["passes_work", "passes: reads, invocations"],
        ])),
    });
    format!("// Written by ssm compare: the data of index.html's viewer (viewer.js).\nwindow.SSM_DATA = {data};\n")
}

/// Each pass of `work` in a few words for the viewer's table: its texel reads (`?` where the
/// shaders do not count) and its invocations (vertex, fragment and compute).
fn pass_work_summary(work: &FrameWork) -> String {
    work.passes
        .iter()
        .map(|pass| {
            let totals = crate::work::Totals::of_passes(work, std::slice::from_ref(pass));
            let count = |n: Option<u64>| n.map_or_else(|| "?".to_owned(), |n| crate::work::short(n as f64));
            format!("{} {} reads, {} inv.", pass.name, count(totals.texel_reads), count(totals.invocations()))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The interactive viewer's part of `index.html`: controls, canvas, readout and table (filled by `viewer.js`).
fn viewer_section((width, height): (u32, u32)) -> String {
    // The readout wraps within the image's width (and its border), so that the table fits beside it.
    let frame = width + 2;
    format!(
        "<section id=\"viewer\">\n<h2>Compare</h2>\n<p class=\"legend\">Keys: <kbd>1</kbd>–<kbd>9</kbd> a technique (or click it), hold <kbd>R</kbd> (or hover its button) for the ground truth; views <kbd>S</kbd> shaded, <kbd>V</kbd> visibility, <kbd>E</kbd> signed error, <kbd>A</kbd> absolute error, <kbd>F</kbd> FLIP; wheel: zoom to the pixel, drag: pan, <kbd>0</kbd>: reset; <kbd>W</kbd>: the table and the per-pass chart in milliseconds or counted work (with <code>--count-work</code>). Click a column to sort, a row to show it.</p>\n<div id=\"viewer-techniques\" class=\"bar\"></div>\n<div id=\"viewer-modes\" class=\"bar\"></div>\n<div id=\"viewer-units\" class=\"bar\"></div>\n<div class=\"bar\"><label>light <select id=\"viewer-light\"></select></label> <label>exposure (shaded) <input id=\"viewer-exposure\" type=\"range\" min=\"-4\" max=\"4\" step=\"0.1\" value=\"0\"> <span id=\"viewer-exposure-value\">+0.0 EV</span></label></div>\n<div class=\"viewer-row\">\n<div style=\"width: {frame}px\">\n<canvas id=\"viewer-canvas\" width=\"{width}\" height=\"{height}\"></canvas>\n<div id=\"viewer-scale\" class=\"legend\"></div>\n<div id=\"readout\">move the pointer over the image for every technique's value at that pixel</div>\n</div>\n<table id=\"metrics\"></table>\n</div>\n</section>\n"
    )
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// `index.html`: the interactive viewer (`viewer.js` over `viewer-data.js`,
/// both beside it: every technique and the ground truth in one zoomable
/// frame, switched by keys, with several views, a per-pixel readout and a
/// sortable metrics table), then the table and, per technique, the shaded
/// image, the visibility and the error heat map side by side; readable
/// offline (images and scripts by relative path, nothing from elsewhere). A
/// small script records on `<body data-images-loaded>` how many images
/// loaded, for tests.
#[must_use]
pub fn html_report(context: &ReportContext<'_>, rows: &[Row], reference_name: &str) -> String {
    let mut out = String::from(
        "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>ssm compare</title>\n<style>\nbody { font-family: sans-serif; margin: 1.5em; color: #222; }\ntable { border-collapse: collapse; font-size: 0.9em; }\nth, td { border: 1px solid #ccc; padding: 0.3em 0.6em; text-align: right; }\nth:first-child, th:nth-child(2), td:first-child, td:nth-child(2) { text-align: left; }\nfigure { margin: 1.2em 0; }\nfigure img { width: 32%; image-rendering: pixelated; border: 1px solid #ddd; vertical-align: top; }\n.overlay { position: relative; display: inline-block; width: 32%; vertical-align: top; }\n.overlay img { width: 100%; }\n.overlay img + img { position: absolute; left: 0; top: 0; opacity: 0.5; }\n.legend { font-size: 0.9em; color: #555; }\n.bar { margin: 0.3em 0; }\n.bar button { margin-right: 0.3em; }\nbutton.selected, #metrics tr.selected { background: #1d5fa0; color: white; }\n#viewer-canvas { display: block; image-rendering: pixelated; cursor: crosshair; border: 1px solid #888; }\n#readout { font-family: monospace; margin: 0.4em 0; min-height: 2.6em; }\n#readout .selected { font-weight: bold; }\n#metrics th { cursor: pointer; }\n#metrics th[data-sorted=\"ascending\"]::after { content: \" ▲\"; }\n#metrics th[data-sorted=\"descending\"]::after { content: \" ▼\"; }\n#metrics tbody tr { cursor: pointer; }\n#metrics td:last-child { text-align: left; font-size: 0.85em; }\n.viewer-row { display: flex; gap: 1.5em; align-items: flex-start; flex-wrap: wrap; }\n.viewer-row > div { max-width: 100%; flex: none; }\n.viewer-row > table { flex: 1 1 24em; }\n</style>\n</head>\n<body data-images-loaded=\"0\">\n",
    );
    let _ = writeln!(
        out,
        "<h1>ssm compare: <code>{}</code></h1>\n<p>{}×{}, median of {} frames after one warm-up, on {}. Ground truth: <code>{}</code> [{}]: {}.</p>",
        escape(context.scene),
        context.size.0,
        context.size.1,
        context.frames,
        escape(context.adapter),
        escape(reference_name),
        escape(context.reference_params),
        escape(context.reference_cost)
    );
    if let Some(note) = beyond_frame_note(rows) {
        let _ = writeln!(out, "<p>{}</p>", escape(&note));
    }
    out += &viewer_section(context.size);
    out += "<h2>All images</h2>\n<table>\n<tr>";
    for header in TABLE_HEADER {
        let _ = write!(out, "<th>{}</th>", escape(header));
    }
    out += "</tr>\n";
    for r in rows {
        let cells = table_cells(r);
        let _ = write!(out, "<tr><td><code>{}</code>{}</td>", escape(&cells[0]), escape(&light_suffix(r)));
        for cell in &cells[1..] {
            let _ = write!(out, "<td>{}</td>", escape(cell));
        }
        out += "</tr>\n";
    }
    out += "</table>\n";
    for (name, why) in context.skipped {
        let _ = writeln!(out, "<p>Not run: <code>{}</code>: {}</p>", escape(name), escape(why));
    }
    // The viewer's milliseconds/work switch changes this image's source to a work chart's
    // (`data-reads`, `data-invocations`); without timestamps only the work charts exist.
    if let Some(chart) = context.pass_chart.or_else(|| context.work_charts.first().map(|(_, file)| *file)) {
        let sources: String = context
            .pass_chart
            .map(|ms| ("ms", ms))
            .into_iter()
            .chain(context.work_charts.iter().copied())
            .map(|(unit, file)| format!(" data-{}=\"{}\"", escape(unit), escape(file)))
            .collect();
        let _ = writeln!(
            out,
            "<h2>Where the time goes</h2>\n<p class=\"legend\" id=\"pass-chart-legend\">Each technique's frame split into its passes, as shares of the frame: of its GPU time (medians; the frame's milliseconds beside its name), or with the viewer's switch on work, of its counted texel reads or invocations.</p>\n<img src=\"{}\" id=\"pass-chart\"{sources} alt=\"per-pass chart\" style=\"max-width: 100%\">",
            escape(chart)
        );
    }
    out += &html_work(context, rows);
    out += "<p class=\"legend\">Each row: shaded image, visibility, and the error against the ground truth (red: darker than the reference, over-shadowing; blue: lighter, under-shadowing; full colour at an error of 0.5).</p>\n";
    let _ = writeln!(
        out,
        "<figure><figcaption><code>{0}</code> (ground truth)</figcaption><img src=\"{0}/shaded.png\" alt=\"{0} shaded\"><img src=\"{0}/visibility.png\" alt=\"{0} visibility\"></figure>",
        escape(reference_name)
    );
    let lights = rows.iter().filter_map(|r| r.light).max().map_or(1, |last| last + 1);
    for light in 1..lights {
        let _ = writeln!(
            out,
            "<figure><figcaption><code>{0}</code> (ground truth) · light {light}</figcaption><img src=\"{0}/{1}.png\" alt=\"{0} visibility of light {light}\"></figure>",
            escape(reference_name),
            visibility_stem(light)
        );
    }
    for r in rows {
        match r.light {
            None => {
                let extras: String = r
                    .extra_images
                    .iter()
                    .map(|name| {
                        let image = format!("<img src=\"{0}/{1}.png\" alt=\"{0} {1}\" title=\"{1}\">", escape(&r.technique), escape(name));
                        if r.overlays.contains(name) {
                            // Over the visibility, half transparent (Shen et al.'s Fig. 10 inset).
                            format!(
                                "<span class=\"overlay\" title=\"{1} over the visibility\"><img src=\"{0}/visibility.png\" alt=\"{0} visibility\">{image}</span>",
                                escape(&r.technique),
                                escape(name)
                            )
                        } else {
                            image
                        }
                    })
                    .collect();
                let _ = writeln!(
                    out,
                    "<figure><figcaption><code>{0}</code></figcaption><img src=\"{0}/shaded.png\" alt=\"{0} shaded\"><img src=\"{0}/visibility.png\" alt=\"{0} visibility\"><img src=\"{0}/heatmap.png\" alt=\"{0} error\">{extras}</figure>",
                    escape(&r.technique)
                );
            }
            // Light 0's images are in the total's figure.
            Some(0) => {}
            Some(light) => {
                let _ = writeln!(
                    out,
                    "<figure><figcaption><code>{0}</code> · light {light}</figcaption><img src=\"{0}/{1}.png\" alt=\"{0} visibility of light {light}\"><img src=\"{0}/heatmap-light{light}.png\" alt=\"{0} error for light {light}\"></figure>",
                    escape(&r.technique),
                    visibility_stem(light)
                );
            }
        }
    }
    out += "<script>\nwindow.addEventListener('load', () => {\n  const images = Array.from(document.images);\n  const loaded = images.filter((i) => i.complete && i.naturalWidth > 0).length;\n  document.body.dataset.imagesLoaded = loaded + '/' + images.length;\n});\n</script>\n<script src=\"viewer-data.js\"></script>\n<script src=\"viewer.js\"></script>\n</body>\n</html>\n";
    out
}

/// A sentence on what tracing the ground truth cost, from its diagnostics.
#[must_use]
pub fn reference_cost(diagnostics: &[(String, f64)]) -> String {
    let get = |key: &str| diagnostics.iter().find(|(k, _)| k == key).map(|(_, v)| *v);
    match (get("reference_rays"), get("reference_trace_ms"), get("reference_rays_per_second")) {
        (Some(rays), Some(ms), Some(rate)) if rays > 0.0 => {
            format!(
                "{:.1} M light samples evaluated on the CPU in {:.0} ms ({:.1} M samples/s, exact shares of the light included)",
                rays / 1e6,
                ms,
                rate / 1e6
            )
        }
        _ => "read from the cache".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(csv_field("q\",x"), "\"q\"\",x\"");
        assert_eq!(number(Some(f64::INFINITY), 2), "inf");
        assert_eq!(number(None, 2), "");
    }

    /// A row of every column, for the tests: `gpu` None is a row timed on the CPU alone.
    fn sample_row(technique: &str, light: Option<usize>, gpu: Option<f64>) -> Row {
        Row {
            scene: "parallel-square[light_scale=0.5]".into(),
            technique: technique.into(),
            light,
            params: "a=1;b=x,y".into(),
            width: 96,
            height: 72,
            gpu_ms_median: gpu,
            gpu_ms_min: gpu,
            gpu_ms_quartiles: gpu.map(|ms| (ms * 0.9, ms * 1.1)),
            cpu_step_ms: gpu.map(|ms| ms * 0.25),
            flip_noise: gpu.map(|_| 0.0012),
            cpu_ms: 12.5,
            metrics: ErrorMetrics {
                mae: 0.0234567,
                mae_penumbra: 0.0123456,
                truth_noise: gpu.map(|_| 0.0012345),
                truth_noise_penumbra: Some(0.0023456),
                shadowed_pixels: 25,
                rmse: 0.5,
                max_abs: 1.0,
                psnr: f64::INFINITY,
                ssim: 0.987654321,
                frac_over_0_05: 0.25,
                mean_signed: -0.001,
                umbra_leak: 0.02,
                pixels: 0,
                penumbra_pixels: 17,
                umbra_pixels: 3,
            },
            flip: 0.1,
            adapter: "llvmpipe \"x\", y".into(),
            timing_source: if gpu.is_some() { TimingSource::GpuTimestamps } else { TimingSource::CpuWallOnly },
            passes: vec![("hard_shadow_map".into(), 1.25), ("hard_filter".into(), 2.0)],
            diagnostics: vec![("memory_mib".into(), 4.0)],
            extra_images: Vec::new(),
            overlays: Vec::new(),
            work: None,
        }
    }

    #[test]
    fn the_beyond_frame_note_names_each_technique_the_framework_answered_for() {
        let with = |technique: &str, light: Option<usize>, pixels: f64| {
            let mut row = sample_row(technique, light, Some(1.0));
            row.diagnostics.push((ssm_core::BEYOND_FRAME_DIAGNOSTIC.to_owned(), pixels));
            row
        };
        let rows =
            vec![with("hard", None, 1234.0), with("pcss", Some(0), 99.0), with("vssm", None, 0.0), sample_row("wedges", None, Some(1.0))];
        let note = beyond_frame_note(&rows).unwrap();
        assert!(note.contains("`hard` 1234"), "{note}");
        // Per-light rows repeat the frame's; a technique that answered none, or has no such pass, is not named.
        assert!(!note.contains("pcss") && !note.contains("vssm") && !note.contains("wedges"), "{note}");
        assert_eq!(beyond_frame_note(&rows[2..]), None);
    }

    #[test]
    fn rows_read_back_from_their_csv_give_the_same_csv() {
        let row = sample_row;
        let mut rows = vec![row("hard", None, Some(3.25)), row("pcss", Some(1), None), row("pcss", None, None)];
        // Counted with pipeline statistics but not in the shaders: its reads are unknown, not 0.
        rows[0].work = Some(FrameWork {
            pipeline_statistics: true,
            shader_counts: false,
            passes: vec![ssm_core::PassWork {
                name: "hard_lookup".into(),
                runs: 1,
                vertex_invocations: 3,
                fragment_invocations: 3456,
                target_bytes: 12288,
                ..ssm_core::PassWork::default()
            }],
            uncounted_passes: 0,
            diagnostics: Vec::new(),
        });
        rows[2].work = Some(FrameWork { shader_counts: true, pipeline_statistics: false, ..rows[0].work.clone().unwrap() });
        let text = csv(&rows);
        let back = parse_csv(&text).unwrap();
        assert_eq!(csv(&back), text);
        assert_eq!(back[0].work, rows[0].work);
        assert_eq!((back[1].work.as_ref(), back[2].work.as_ref()), (None, rows[2].work.as_ref()));
        let first = CSV_COLUMNS.iter().position(|c| *c == "vertex_invocations").unwrap();
        let work_columns = |line: &str| -> Vec<String> { split_csv_line(line).unwrap()[first..first + 5].to_vec() };
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            work_columns(lines[1]),
            ["3", "3456", "0", "", "hard_lookup:runs=1,vertex_invocations=3,fragment_invocations=3456,target_bytes=12288"]
        );
        assert_eq!(work_columns(lines[2]), ["", "", "", "", ""], "not counted: every work column empty");
        assert_eq!(&work_columns(lines[3])[..4], ["", "", "", "0"], "no statistics: invocations unknown; shaders counted no read");
        assert_eq!((back[1].light, back[0].metrics.penumbra_pixels, back[0].adapter.as_str()), (Some(1), 17, "llvmpipe \"x\", y"));
        assert!(parse_csv("scene,technique\n").is_err(), "another header");
        assert!(parse_csv(&text.replace("96,72", "96")).is_err(), "a field missing");
    }

    #[test]
    fn the_leading_columns_are_the_documented_ones() {
        assert_eq!(
            CSV_COLUMNS[..15].join(","),
            "scene,technique,params,width,height,gpu_ms_median,gpu_ms_min,cpu_ms,mae_penumbra,rmse,max_abs,psnr,ssim,frac_over_0_05,adapter"
        );
    }
}
