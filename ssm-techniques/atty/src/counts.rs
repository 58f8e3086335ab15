//! Counted work (`--count-work`; `shaders/atty/atty_counts.wgsl`), no step of the paper: the
//! counters every counting pass binds, in the units of the paper's cost argument (Atty et al.
//! 2006, Sec. 6.1, counts micro-patches; here also accumulation fragments, texel reads and bytes).

use ssm_core::read_counts::{READ_COUNT_BUCKETS, ReadCounts};

use crate::occluder_map::Side;
use crate::projection::PROJECT_LABEL;
use crate::receiver_bounds::RECEIVER_BOUNDS;
use crate::{AttySettings, PenumbraBound};

/// Bytes of one [`ReadCounts`] counter: [`READ_COUNT_BUCKETS`] (invocations, amount) pairs of u32.
/// A multiple of 256, the largest `min_storage_buffer_offset_alignment` WebGPU allows, so every
/// counter can start a binding.
const COUNTER_BYTES: u64 = READ_COUNT_BUCKETS as u64 * 8;

/// The counters of `--count-work` (issue #40;
/// [`TechniqueSetup::count_work`](ssm_core::TechniqueSetup::count_work)), one slice of
/// consecutive counters per pass that counts, each bound to its pass's shader as its own
/// `read_counts` (`atty_counts.wgsl`): the list pass and the accumulation run once per side with
/// one pipeline, and the pyramids share their shaders, so a slice, not an index, tells them apart.
/// Only the passes that run have counters (a counter of a pass never recorded would be work of a
/// pass that did not run).
pub(crate) struct CounterPlan {
    pub(crate) counters: Vec<(&'static str, &'static str)>,
    /// The receiver map's max-pyramid: reads, their bytes, storage bytes (when it runs).
    pub(crate) receiver_bounds: Option<u32>,
    /// Per side: its occluder map's min-max pyramid (reads, their bytes, storage bytes; when
    /// merging), its list pass (reads, their bytes, atomics, storage bytes) and its accumulation
    /// (reads, their bytes).
    pub(crate) sides: Vec<SideCounters>,
    /// The projection: reads, their bytes.
    pub(crate) project: u32,
}

/// The first counter of each of one side's counting passes ([`CounterPlan`]).
pub(crate) struct SideCounters {
    pub(crate) patch_merge: Option<u32>,
    pub(crate) patches: u32,
    pub(crate) accumulate: u32,
}

/// Counters of a pyramid pass, a list pass and an accumulation or projection pass, in their
/// shaders' order: every pass that counts its texel reads counts the bytes they fetched beside
/// them (each read its texture's texel size, from the formats: [`texel_bytes`]).
pub(crate) const PYRAMID_UNITS: &[&str] = &["reads", "read_bytes", "storage_bytes"];
pub(crate) const PATCHES_UNITS: &[&str] = &["reads", "read_bytes", "atomics", "storage_bytes"];
pub(crate) const READS: &[&str] = &["reads", "read_bytes"];

/// Bytes of one texel of `format`: what a read of it fetches, as the shaders count it (their
/// `*_TEXEL_BYTES` overrides, set from the textures' formats since the receiver map and the soft
/// shadow maps change format with the settings).
pub(crate) fn texel_bytes(format: wgpu::TextureFormat) -> f64 {
    f64::from(format.block_copy_size(None).unwrap_or(0))
}

impl CounterPlan {
    pub(crate) fn new(settings: &AttySettings, sides: &[Side]) -> Self {
        let mut counters = Vec::new();
        let mut add = |pass: &'static str, units: &[&'static str]| {
            let first = counters.len() as u32;
            counters.extend(units.iter().map(|unit| (pass, *unit)));
            first
        };
        let receiver_bounds = (settings.penumbra_bound == PenumbraBound::Receivers).then(|| add(RECEIVER_BOUNDS.label, PYRAMID_UNITS));
        let sides = sides
            .iter()
            .map(|side| SideCounters {
                patch_merge: (settings.merge_tolerance > 0.0).then(|| add(side.patch_merge, PYRAMID_UNITS)),
                patches: add(side.patches, PATCHES_UNITS),
                accumulate: add(side.accumulate, READS),
            })
            .collect();
        let project = add(PROJECT_LABEL, READS);
        Self { counters, receiver_bounds, sides, project }
    }
}

/// `count` counters of `read_counts` from counter `first`, as one binding.
pub(crate) fn counter_slice(read_counts: &ReadCounts, first: u32, count: usize) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer: read_counts.buffer(),
        offset: u64::from(first) * COUNTER_BYTES,
        size: wgpu::BufferSize::new(count as u64 * COUNTER_BYTES),
    })
}

#[cfg(test)]
mod tests {
    use ssm_core::LightDepthMap;

    use super::*;
    use crate::Accumulation;
    use crate::patch_merge::PATCH_MERGE;
    use crate::receiver_bounds::RECEIVER_BOUNDS;
    use crate::receiver_map::ReceiverPlaneMap;

    /// The bytes a read fetches are its texture's texel size: the projection counts the G-buffer's
    /// normal at its position's, which is the same format; the receiver map and the soft shadow
    /// maps follow the settings.
    #[test]
    fn the_texel_sizes_are_the_formats() {
        assert_eq!(ssm_core::GBuffer::POSITION_FORMAT, ssm_core::GBuffer::NORMAL_FORMAT);
        assert_eq!(texel_bytes(ssm_core::GBuffer::POSITION_FORMAT), 16.0);
        assert_eq!((texel_bytes(Accumulation::F32.format()), texel_bytes(Accumulation::F16.format())), (4.0, 2.0));
        assert_eq!((texel_bytes(LightDepthMap::FORMAT), texel_bytes(ReceiverPlaneMap::FORMAT)), (4.0, 16.0));
        assert_eq!((texel_bytes(RECEIVER_BOUNDS.format), texel_bytes(PATCH_MERGE.format)), (4.0, 8.0));
    }

    /// Every pass that counts its texel reads counts their bytes, in the order its shader
    /// records them (reads first, their bytes next).
    #[test]
    fn every_counter_of_reads_has_one_of_bytes_after_it() {
        for units in [PYRAMID_UNITS, PATCHES_UNITS, READS] {
            assert_eq!(&units[..2], ["reads", "read_bytes"], "{units:?}");
        }
    }
}
