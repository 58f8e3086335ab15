//! Counting work (`--count-work`, issue 40): one extra, untimed frame of a technique after its
//! timed frames ([`count`], through [`Renderer::count_work`]), and how many this process has
//! rendered ([`counting_frames`]). The totals are [`crate::data::work`]'s, the tables
//! [`crate::present::work`]'s.
//!
//! What is counted and how: invocations and primitives from pipeline statistics (where the
//! adapter has them: [`FrameWork::pipeline_statistics`]), bytes stored to render targets from the
//! attachments' sizes, and texel reads, atomics and storage bytes as the technique's own shaders
//! count them (where it does: [`FrameWork::shader_counts`]; a load or a nearest sample is one
//! texel, a bilinear sample or a gather four). A count that was not made is shown as unknown
//! (`-` in tables, an empty CSV field, `null` in JSON), never as 0.

use std::sync::atomic::{AtomicU64, Ordering};

use ssm_core::{FrameWork, ParamValues, Renderer, Result, TechniqueInfo, TechniqueKind};

/// Counting frames this process has rendered (see [`counting_frames`]).
static COUNTING_FRAMES: AtomicU64 = AtomicU64::new(0);

/// How many counting frames ([`Renderer::count_work`]) this process has rendered through
/// [`count`]: a run without `--count-work` renders none, which tests check.
#[must_use]
pub fn counting_frames() -> u64 {
    COUNTING_FRAMES.load(Ordering::Relaxed)
}

/// Counts the work of one frame of `info` with `params` (every light) in an extra, untimed frame
/// of a technique built for counting; `None` for the ground truth, which traces rays on the CPU
/// ([`crate::data::work::GROUND_TRUTH_NOT_COUNTED`]). Call it after the timed frames: it builds another instance.
///
/// # Errors
/// As [`Renderer::count_work`].
pub fn count(renderer: &mut Renderer, info: &TechniqueInfo, params: &ParamValues) -> Result<Option<FrameWork>> {
    if info.kind == TechniqueKind::GroundTruth {
        return Ok(None);
    }
    COUNTING_FRAMES.fetch_add(1, Ordering::Relaxed);
    renderer.count_work(info, params).map(Some)
}
