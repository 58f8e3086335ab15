//! Texture reads per pixel, counted on the GPU per pass: where a technique's
//! time goes, in the unit its cost model is written in (Buades et al. count
//! taps: PCSS reads n² + m² texels per pixel, a separable pair n + m).
//!
//! A technique binds one [`ReadCounts`] buffer, read-write, in the passes it
//! profiles; each invocation that does the pass's work adds 1 to its pass's
//! pixel count and the number of textures it read to its read count
//! (`atomicAdd`, which costs time: techniques count only when their
//! `count_reads` parameter asks, and build their pipelines with
//! [`ReadCounts::pipeline_constants`], so that otherwise the counting code is
//! compiled out). Each pass's counts are spread over [`READ_COUNT_BUCKETS`]
//! pairs, chosen by pixel, so that a 32-bit count holds the bytes of a 4K
//! frame's 2,522 four-byte reads per pixel over three lights (about 10⁹ a
//! bucket) and the atomics contend less.
//! Cleared at the first light of each frame, so the figures cover one
//! frame's lights.
//!
//! In WGSL, with `common/read_counts.wgsl` imported: `let word =
//! read_count_word(pass_index, texel);` then `atomicAdd(&counts[word], 1u);
//! atomicAdd(&counts[word + 1u], reads);`.

use crate::work::ShaderWork;
use crate::{Frame, GpuContext};

/// Buckets (pairs of pixel and read counts) per pass.
pub const READ_COUNT_BUCKETS: usize = 256;

/// Per-pass (pixels, reads) counters in one storage buffer: pass `k`, bucket `b` at words
/// `2(k·B + b)` and `2(k·B + b) + 1`, B = [`READ_COUNT_BUCKETS`].
pub struct ReadCounts {
    buffer: wgpu::Buffer,
    /// Each counter's name and the unit of its second word (`reads`, or another a shader counts
    /// the same way, such as `rows`).
    counters: Vec<(&'static str, &'static str)>,
    /// Whether the technique counts (its `count_reads`): otherwise nothing is cleared or read back.
    enabled: bool,
}

impl ReadCounts {
    /// Counters for the passes named `passes`, in the order the shaders index them; `enabled`:
    /// whether the shaders count (the buffer is bound either way).
    #[must_use]
    pub fn new(device: &wgpu::Device, label: &str, passes: &'static [&'static str], enabled: bool) -> Self {
        let counters: Vec<_> = passes.iter().map(|pass| (*pass, "reads")).collect();
        Self::with_units(device, label, &counters, enabled)
    }

    /// As [`ReadCounts::new`], for counters of other things per pixel besides reads: counter `k`
    /// is `(name, unit)`, and its diagnostic `<name>_<unit>_per_pixel` (SSSM counts its rows that
    /// fail the reuse tests, by cause, as `rows` beside its passes' `reads`).
    #[must_use]
    pub fn with_units(device: &wgpu::Device, label: &str, counters: &[(&'static str, &'static str)], enabled: bool) -> Self {
        let buffer = crate::passes::storage_buffer(device, label, (counters.len().max(1) * READ_COUNT_BUCKETS * 8) as u64);
        Self { buffer, counters: counters.to_vec(), enabled }
    }

    /// The pipeline-overridable constant that switches the shaders' counting on or off
    /// (`COUNT_READS` of `common/read_counts.wgsl`): off, the counting code is compiled out.
    #[must_use]
    pub fn pipeline_constants(&self) -> [(&'static str, f64); 1] {
        [("COUNT_READS", f64::from(u8::from(self.enabled)))]
    }

    /// The buffer, to bind as `array<atomic<u32>>`.
    #[must_use]
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// A layout entry for the buffer at `binding`, writable from fragment and compute shaders.
    #[must_use]
    pub const fn layout_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
        wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE),
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }
    }

    /// Zeroes the counters at the first light of a frame, when counting.
    pub fn clear(&self, frame: &mut Frame<'_>, light: usize) {
        if self.enabled && light == 0 {
            frame.clear_buffer("read_counts_clear", &self.buffer, 0, None);
        }
    }

    /// The counters' totals over the last frame as each pass's [`ShaderWork`]: a counter whose
    /// unit is `reads` gives texel reads, `read_bytes` the bytes they fetched, `atomics` atomics,
    /// `storage_bytes` bytes written to storage; counters of other units, such as sssm's `rows`, are diagnostics only and make no
    /// pass. A pass's invocations are the most pixels any of its counters counted. `None` when
    /// not counting.
    ///
    /// # Errors
    /// A readback error.
    pub fn work(&self, gpu: &GpuContext) -> crate::Result<Option<Vec<ShaderWork>>> {
        if !self.enabled {
            return Ok(None);
        }
        let bytes = crate::readback::read_buffer(gpu, &self.buffer, self.buffer.size(), "read counts")?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let mut work: Vec<ShaderWork> = Vec::new();
        for ((name, unit), buckets) in self.counters.iter().zip(words.chunks_exact(2 * READ_COUNT_BUCKETS)) {
            if !matches!(*unit, "reads" | "read_bytes" | "atomics" | "storage_bytes") {
                continue;
            }
            let invocations: u64 = buckets.chunks_exact(2).map(|pair| u64::from(pair[0])).sum();
            let counted: u64 = buckets.chunks_exact(2).map(|pair| u64::from(pair[1])).sum();
            let index = match work.iter().position(|pass| pass.pass == *name) {
                Some(index) => index,
                None => {
                    work.push(ShaderWork { pass: (*name).to_owned(), ..ShaderWork::default() });
                    work.len() - 1
                }
            };
            let pass = &mut work[index];
            pass.invocations = pass.invocations.max(invocations);
            match *unit {
                "reads" => pass.texel_reads += counted,
                "read_bytes" => pass.read_bytes += counted,
                "atomics" => pass.atomics += counted,
                _ => pass.storage_bytes += counted,
            }
        }
        Ok(Some(work))
    }

    /// `<pass>_reads_per_pixel` (`<name>_<unit>_per_pixel`) and `<pass>_pixels` for each counter
    /// with pixels, after a frame; nothing when not counting.
    #[must_use]
    pub fn diagnostics(&self, gpu: &GpuContext) -> Vec<(String, f64)> {
        if !self.enabled {
            return Vec::new();
        }
        let Ok(bytes) = crate::readback::read_buffer(gpu, &self.buffer, self.buffer.size(), "read counts") else {
            return Vec::new();
        };
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        self.counters
            .iter()
            .zip(words.chunks_exact(2 * READ_COUNT_BUCKETS))
            .filter_map(|((name, unit), buckets)| {
                let pixels: u64 = buckets.chunks_exact(2).map(|pair| u64::from(pair[0])).sum();
                let counted: u64 = buckets.chunks_exact(2).map(|pair| u64::from(pair[1])).sum();
                (pixels > 0).then(|| {
                    [(format!("{name}_{unit}_per_pixel"), counted as f64 / pixels as f64), (format!("{name}_pixels"), pixels as f64)]
                })
            })
            .flatten()
            .collect()
    }
}

/// The lines `const <NAME>: u32 = <bytes>u;` that `wgsl` lacks, for each `(NAME, format)`: the
/// byte sizes a shader counts its reads at must be its textures' formats' (a test of each
/// counting shader asserts none is missing). A format without a single texel size is reported too.
#[must_use]
pub fn missing_texel_byte_constants(wgsl: &str, constants: &[(&str, wgpu::TextureFormat)]) -> Vec<String> {
    constants
        .iter()
        .filter_map(|(constant, format)| match format.block_copy_size(None) {
            Some(bytes) => {
                let line = format!("const {constant}: u32 = {bytes}u;");
                (!wgsl.contains(&line)).then(|| format!("`{line}` ({format:?})"))
            }
            None => Some(format!("{constant}: {format:?} has no single texel size")),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    /// The WGSL side spreads the counts over as many buckets as the Rust side sums.
    #[test]
    fn the_shaders_bucket_count_is_the_same() {
        let line = format!("const READ_COUNT_BUCKETS: u32 = {}u;", super::READ_COUNT_BUCKETS);
        assert!(ssm_shaders::common::READ_COUNTS.contains(&line), "common/read_counts.wgsl lacks `{line}`");
    }
}
