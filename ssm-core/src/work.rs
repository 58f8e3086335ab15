//! Counted work: what a frame did, in the units the papers reason in, beside its time.
//!
//! Times measured on lavapipe rank code as a CPU does (every branch body run masked, a texel fetch
//! a ~140-instruction call), not as a GPU does, so cost claims are also made in work that any
//! device does the same amount of:
//! - vertex, fragment and compute invocations and primitives per pass, from pipeline-statistics
//!   queries the framework opens around every pass it times ([`Frame::render_pass`],
//!   [`Frame::compute_pass`]), where the adapter has `PIPELINE_STATISTICS_QUERY`;
//! - the bytes each render pass stores to its attachments, from the attachments' sizes;
//! - texel reads, atomics and storage bytes written, which only a shader can count: each technique
//!   counts them in its own WGSL ([`crate::read_counts::ReadCounts`]) when built with
//!   [`TechniqueSetup::count_work`](crate::TechniqueSetup::count_work), and returns them from
//!   [`ShadowTechnique::counted_work`](crate::ShadowTechnique::counted_work).
//!
//! The counts come from an extra frame rendered with a technique built for counting
//! ([`Renderer::count_work`](crate::Renderer::count_work)), so the timed frames run the
//! pipelines without the counting code.
//!
//! [`Frame::render_pass`]: crate::Frame::render_pass
//! [`Frame::compute_pass`]: crate::Frame::compute_pass

use serde::Serialize;

use crate::context::GpuContext;
use crate::error::{Error, Reason, Result};
use crate::readback::read_buffer;

/// Most passes per counting frame whose pipeline statistics are queried; later passes are
/// counted in [`FrameWork::uncounted_passes`].
pub const MAX_COUNTED_PASSES: u32 = 2048;

/// The pipeline statistics queried per pass, in the order the query writes them.
const STATISTICS: wgpu::PipelineStatisticsTypes = wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
    .union(wgpu::PipelineStatisticsTypes::CLIPPER_INVOCATIONS)
    .union(wgpu::PipelineStatisticsTypes::CLIPPER_PRIMITIVES_OUT)
    .union(wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS)
    .union(wgpu::PipelineStatisticsTypes::COMPUTE_SHADER_INVOCATIONS);

/// Values [`STATISTICS`] writes per query.
const STATISTICS_PER_QUERY: u64 = 5;

/// What a technique's shaders counted in one pass over a frame (every light): the counts the
/// device cannot give. A technique returns them from
/// [`ShadowTechnique::counted_work`](crate::ShadowTechnique::counted_work).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ShaderWork {
    /// The pass's label, as given to [`Frame::render_pass`](crate::Frame::render_pass) or
    /// [`Frame::compute_pass`](crate::Frame::compute_pass).
    pub pass: String,
    /// Invocations that counted (pixels, texels or threads doing the pass's work).
    pub invocations: u64,
    /// Texels read from textures or from storage arrays of texels: a load or a nearest sample
    /// is one, a bilinear sample or a gather four.
    pub texel_reads: u64,
    /// Bytes those reads fetched: each texel read times its format's size (an `Rgba32Float`
    /// texel 16, an `R32Float` depth 4); 0 where the technique counts reads but not their bytes.
    pub read_bytes: u64,
    /// Atomic operations on storage.
    pub atomics: u64,
    /// Bytes written to storage buffers and storage textures.
    pub storage_bytes: u64,
}

/// The work of one pass over a frame: its lights summed.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct PassWork {
    /// The pass's label.
    pub name: String,
    /// Times the pass ran in the frame (once per light, or more).
    pub runs: u64,
    /// Vertex shader invocations (pipeline statistics).
    pub vertex_invocations: u64,
    /// Primitives that reached the clipper (pipeline statistics).
    pub primitives: u64,
    /// Primitives out of the clipper, to the rasteriser (pipeline statistics).
    pub clipped_primitives: u64,
    /// Fragment shader invocations (pipeline statistics).
    pub fragment_invocations: u64,
    /// Compute shader invocations (pipeline statistics).
    pub compute_invocations: u64,
    /// Bytes the pass stores to its attachments: each stored attachment's texels times its texel
    /// size (the write-back a tiled GPU does; a pass that leaves an attachment unstored adds none).
    pub target_bytes: u64,
    /// Invocations the technique's shaders counted, [`ShaderWork::invocations`].
    pub counted_invocations: u64,
    /// Texel reads the technique's shaders counted.
    pub texel_reads: u64,
    /// Bytes those reads fetched, as the technique's shaders counted.
    pub read_bytes: u64,
    /// Atomic operations the technique's shaders counted.
    pub atomics: u64,
    /// Bytes written to storage, as the technique's shaders counted.
    pub storage_bytes: u64,
}

impl PassWork {
    /// `key=value` pairs of the counts, without the name, for `passes_work` columns: only the
    /// counts that are not zero, so that a pass says what it did.
    #[must_use]
    pub fn pairs(&self) -> Vec<(&'static str, u64)> {
        [
            ("runs", self.runs),
            ("vertex_invocations", self.vertex_invocations),
            ("primitives", self.primitives),
            ("clipped_primitives", self.clipped_primitives),
            ("fragment_invocations", self.fragment_invocations),
            ("compute_invocations", self.compute_invocations),
            ("target_bytes", self.target_bytes),
            ("counted_invocations", self.counted_invocations),
            ("texel_reads", self.texel_reads),
            ("read_bytes", self.read_bytes),
            ("atomics", self.atomics),
            ("storage_bytes", self.storage_bytes),
        ]
        .into_iter()
        .filter(|(_, value)| *value > 0)
        .collect()
    }
}

/// The counted work of one frame of one technique (every light).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FrameWork {
    /// Whether the invocation and primitive counts come from pipeline statistics; without the
    /// feature they are zero (the adapter cannot count them) and only the shaders' counts are known.
    pub pipeline_statistics: bool,
    /// Whether the technique's shaders counted (it implements
    /// [`ShadowTechnique::counted_work`](crate::ShadowTechnique::counted_work)): without it,
    /// texel reads, atomics and storage bytes are unknown, not zero.
    pub shader_counts: bool,
    /// Each pass, in the order first recorded, its lights summed.
    pub passes: Vec<PassWork>,
    /// Passes past [`MAX_COUNTED_PASSES`], without pipeline statistics.
    pub uncounted_passes: u32,
    /// The counting instance's own diagnostics ([`ShadowTechnique::diagnostics`](crate::ShadowTechnique::diagnostics)
    /// after the counting frame): the figures only a build that counts can give, such as the
    /// reads per pixel of one pass or what they are set against.
    pub diagnostics: Vec<(String, f64)>,
}

impl FrameWork {
    /// The sum of `count` over the passes.
    #[must_use]
    pub fn total(&self, count: impl Fn(&PassWork) -> u64) -> u64 {
        self.passes.iter().map(count).sum()
    }

    /// The `passes_work` column: `pass:key=value,...;pass:...`.
    #[must_use]
    pub fn passes_column(&self) -> String {
        self.passes
            .iter()
            .map(|pass| {
                let pairs: Vec<String> = pass.pairs().iter().map(|(key, value)| format!("{key}={value}")).collect();
                format!("{}:{}", pass.name, pairs.join(","))
            })
            .collect::<Vec<_>>()
            .join(";")
    }

    /// The pass called `name`, added (with no work) if the frame has none yet.
    fn pass_named(&mut self, name: &str) -> &mut PassWork {
        let index = match self.passes.iter().position(|pass| pass.name == name) {
            Some(index) => index,
            None => {
                self.passes.push(PassWork { name: name.to_owned(), ..PassWork::default() });
                self.passes.len() - 1
            }
        };
        &mut self.passes[index]
    }

    /// Adds the shaders' counts to the passes of the same name (a pass the pipeline statistics
    /// did not see, such as one past [`MAX_COUNTED_PASSES`], is added).
    pub fn add_shader_work(&mut self, shader_work: &[ShaderWork]) {
        self.shader_counts = true;
        for counted in shader_work {
            let pass = self.pass_named(&counted.pass);
            pass.counted_invocations += counted.invocations;
            pass.texel_reads += counted.texel_reads;
            pass.read_bytes += counted.read_bytes;
            pass.atomics += counted.atomics;
            pass.storage_bytes += counted.storage_bytes;
        }
    }
}

/// One query per pass of a counting frame: the pipeline statistics around it and the bytes its
/// attachments store.
#[derive(Debug)]
pub(crate) struct StatisticsQueries {
    query_set: Option<wgpu::QuerySet>,
    resolve_buffer: Option<wgpu::Buffer>,
    /// Per query: the pass's name and the bytes its attachments store.
    scopes: Vec<(String, u64)>,
    /// Passes recorded past the query set's end (still given their target bytes).
    overflow: Vec<(String, u64)>,
}

impl StatisticsQueries {
    /// Queries for one counting frame; without `PIPELINE_STATISTICS_QUERY` only the target bytes
    /// are recorded.
    pub(crate) fn new(gpu: &GpuContext) -> Self {
        let supported = gpu.features().contains(wgpu::Features::PIPELINE_STATISTICS_QUERY);
        let query_set = supported.then(|| {
            gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("work_statistics_query_set"),
                ty: wgpu::QueryType::PipelineStatistics(STATISTICS),
                count: MAX_COUNTED_PASSES,
            })
        });
        let resolve_buffer = supported.then(|| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("work_statistics_resolve_buffer"),
                size: u64::from(MAX_COUNTED_PASSES) * STATISTICS_PER_QUERY * 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        });
        Self { query_set, resolve_buffer, scopes: Vec::new(), overflow: Vec::new() }
    }

    /// The query set and index for a pass called `name` storing `target_bytes`, or `None` when
    /// the pass runs without a query (no feature, or past the set's end).
    pub(crate) fn allocate(&mut self, name: &str, target_bytes: u64) -> Option<(&wgpu::QuerySet, u32)> {
        let index = self.scopes.len() as u32;
        match &self.query_set {
            Some(query_set) if index < MAX_COUNTED_PASSES => {
                self.scopes.push((name.to_owned(), target_bytes));
                Some((query_set, index))
            }
            _ => {
                self.overflow.push((name.to_owned(), target_bytes));
                None
            }
        }
    }

    /// Records the resolve of the frame's queries; call once, last, in the frame's final encoder.
    pub(crate) fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let (Some(query_set), Some(buffer)) = (&self.query_set, &self.resolve_buffer)
            && !self.scopes.is_empty()
        {
            encoder.resolve_query_set(query_set, 0..self.scopes.len() as u32, buffer, 0);
        }
    }

    /// The frame's work per pass, after the frame was submitted and finished.
    ///
    /// # Errors
    /// [`Error::Readback`] if the resolved queries cannot be read.
    pub(crate) fn read(&self, gpu: &GpuContext) -> Result<FrameWork> {
        let mut work = FrameWork { pipeline_statistics: self.query_set.is_some(), ..FrameWork::default() };
        let mut add = |name: &str, target_bytes: u64, statistics: Option<&[u64]>| {
            let pass = work.pass_named(name);
            pass.runs += 1;
            pass.target_bytes += target_bytes;
            if let Some(values) = statistics {
                pass.vertex_invocations += values[0];
                pass.primitives += values[1];
                pass.clipped_primitives += values[2];
                pass.fragment_invocations += values[3];
                pass.compute_invocations += values[4];
            }
        };
        if let Some(buffer) = &self.resolve_buffer
            && !self.scopes.is_empty()
        {
            let size = self.scopes.len() as u64 * STATISTICS_PER_QUERY * 8;
            let bytes = read_buffer(gpu, buffer, size, "pipeline statistics")?;
            let values: &[u64] =
                bytemuck::try_cast_slice(&bytes).map_err(|e| Error::readback("pipeline statistics", Reason(e.to_string())))?;
            for ((name, target_bytes), statistics) in self.scopes.iter().zip(values.chunks_exact(STATISTICS_PER_QUERY as usize)) {
                add(name, *target_bytes, Some(statistics));
            }
        }
        for (name, target_bytes) in &self.overflow {
            add(name, *target_bytes, None);
        }
        work.uncounted_passes = if work.pipeline_statistics { self.overflow.len() as u32 } else { 0 };
        Ok(work)
    }
}

/// Bytes a render pass stores to its attachments: each attachment whose store op is `Store`
/// contributes its texture's texels times its texel size (wgpu does not expose a view's mip level,
/// so an attachment that is one level or layer of a larger texture is counted at the texture's
/// first level's size: an over-count).
pub(crate) fn stored_target_bytes(
    color_attachments: &[Option<wgpu::RenderPassColorAttachment<'_>>],
    depth_stencil_attachment: Option<&wgpu::RenderPassDepthStencilAttachment<'_>>,
) -> u64 {
    let texels = |view: &wgpu::TextureView| {
        let texture = view.texture();
        u64::from(texture.width()) * u64::from(texture.height())
    };
    let mut bytes = 0;
    for attachment in color_attachments.iter().flatten() {
        if attachment.ops.store == wgpu::StoreOp::Store {
            let texel = attachment.view.texture().format().block_copy_size(None).unwrap_or(0);
            bytes += texels(attachment.view) * u64::from(texel);
        }
    }
    if let Some(attachment) = depth_stencil_attachment {
        let format = attachment.view.texture().format();
        if attachment.depth_ops.is_some_and(|ops| ops.store == wgpu::StoreOp::Store) {
            let texel = format.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)).unwrap_or(4);
            bytes += texels(attachment.view) * u64::from(texel);
        }
        if attachment.stencil_ops.is_some_and(|ops| ops.store == wgpu::StoreOp::Store) {
            let texel = format.block_copy_size(Some(wgpu::TextureAspect::StencilOnly)).unwrap_or(1);
            bytes += texels(attachment.view) * u64::from(texel);
        }
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shader_counts_join_the_passes_of_their_name() {
        let mut work = FrameWork {
            pipeline_statistics: true,
            passes: vec![PassWork { name: "x_filter".into(), runs: 2, fragment_invocations: 100, ..PassWork::default() }],
            ..FrameWork::default()
        };
        work.add_shader_work(&[
            ShaderWork { pass: "x_filter".into(), invocations: 90, texel_reads: 900, read_bytes: 3600, atomics: 0, storage_bytes: 0 },
            ShaderWork { pass: "x_cpu_side".into(), invocations: 1, texel_reads: 0, read_bytes: 0, atomics: 3, storage_bytes: 8 },
        ]);
        assert!(work.shader_counts);
        assert_eq!(work.total(|p| p.texel_reads), 900);
        assert_eq!(
            work.passes_column(),
            "x_filter:runs=2,fragment_invocations=100,counted_invocations=90,texel_reads=900,read_bytes=3600;x_cpu_side:counted_invocations=1,atomics=3,storage_bytes=8"
        );
    }
}
