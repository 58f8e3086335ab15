//! Measuring techniques against the ground truth: a technique rendered for one warm-up frame and
//! its timed frames, alone ([`measure`]) or several with their frames in turns or one after
//! another ([`measure_all`], [`FrameOrder`]), and its outputs read back ([`Measured`]: visibility,
//! shaded image, debug outputs, diagnostics, the ground truth's FLIP noise floor). Around it: its
//! work counted in one extra, untimed frame ([`work`]), its comparison with the ground truth as
//! rows ([`truth`]), the pixels the errors cover ([`pixels`]), what the renderer must build and
//! which debug outputs are read ([`needs`]), and what a run writes to disk: its images and
//! timings ([`files`]).
//!
//! Measuring hands [`crate::data::Row`]s on; the reports are [`crate::present`]'s.

pub mod files;
pub mod needs;
pub mod pixels;
pub mod truth;
pub mod work;

use ssm_core::metrics::flip_mean;
use ssm_core::{FrameTimings, FrameWork, ParamValues, Renderer, Result, TechniqueInfo};

use crate::stats::median;

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
    /// the ground truth: [`crate::data::work::GROUND_TRUTH_NOT_COUNTED`]).
    pub work: Option<FrameWork>,
    /// Why the work was not counted although asked: [`crate::data::work::GROUND_TRUTH_NOT_COUNTED`].
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
        crate::stats::quartiles(&self.frames.iter().filter(|f| f.gpu_ms.is_some()).map(FrameTimings::frame_ms).collect::<Vec<_>>())
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
    /// Count its work ([`work::count`]) in one extra, untimed frame after its timed
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
        let work = if job.count_work { work::count(renderer, info, job.params)? } else { None };
        let work_note = (job.count_work && work.is_none()).then_some(crate::data::work::GROUND_TRUTH_NOT_COUNTED);
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
