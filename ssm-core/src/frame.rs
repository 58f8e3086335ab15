//! What a technique records one frame into.

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gbuffer::GBuffer;
use crate::gpu_scene::GpuScene;
use crate::passes::color_attachment;
use crate::timing::PassTimer;
use crate::work::{StatisticsQueries, stored_target_bytes};

/// Shared inputs built by the framework, each only when a technique in use
/// declared it in its [`Requirements`](crate::Requirements).
#[derive(Debug, Default)]
pub struct SharedInputs {
    /// Depth, world position and normal from the camera.
    pub gbuffer: Option<GBuffer>,
    /// Edge–face adjacency of all shadow-casting geometry, in world space.
    pub adjacency: Option<ssm_scene::Adjacency>,
}

impl SharedInputs {
    /// The G-buffer, or an error naming `technique` if it was not declared.
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`].
    pub fn gbuffer(&self, technique: &str) -> Result<&GBuffer> {
        self.gbuffer.as_ref().ok_or_else(|| Error::UndeclaredRequirement { technique: technique.into(), input: "G-buffer" })
    }

    /// The adjacency, or an error naming `technique` if it was not declared.
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`].
    pub fn adjacency(&self, technique: &str) -> Result<&ssm_scene::Adjacency> {
        self.adjacency.as_ref().ok_or_else(|| Error::UndeclaredRequirement { technique: technique.into(), input: "mesh adjacency" })
    }
}

/// One frame being recorded for one technique: the device, the scene, the
/// shared inputs, and the passes the technique opens.
///
/// The command encoder is private: every pass goes through
/// [`Frame::render_pass`] or [`Frame::compute_pass`], which label it and time
/// it on the GPU, inside the debug group the renderer opens for the technique;
/// copies go through [`Frame::copy_texture_to_buffer`] and the like, which
/// mark them; a mid-frame readback goes through [`Frame::read_back`], which
/// times the stall on the CPU. An unlabelled or untimed pass cannot be written.
pub struct Frame<'a> {
    /// The GPU.
    pub gpu: &'a GpuContext,
    /// The scene.
    pub scene: &'a GpuScene,
    /// Shared inputs.
    pub shared: &'a SharedInputs,
    encoder: wgpu::CommandEncoder,
    timer: &'a mut PassTimer,
    /// The debug group every pass of the technique is recorded in.
    group: String,
    /// What the last [`Frame::read_back`] waited for the GPU, ms.
    read_back_wait_ms: f64,
    /// In a counting frame ([`Renderer::count_work`](crate::Renderer::count_work)): the pipeline
    /// statistics queried around each pass.
    statistics: Option<&'a mut StatisticsQueries>,
}

impl<'a> Frame<'a> {
    /// A frame for technique `group` (the debug group its passes go in).
    pub(crate) fn new(gpu: &'a GpuContext, scene: &'a GpuScene, shared: &'a SharedInputs, timer: &'a mut PassTimer, group: &str) -> Self {
        let encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(&format!("{group}_frame_encoder")) });
        Self { gpu, scene, shared, encoder, timer, group: group.to_owned(), read_back_wait_ms: 0.0, statistics: None }
    }

    /// This frame, counting each pass's work into `statistics`.
    pub(crate) fn counting(mut self, statistics: &'a mut StatisticsQueries) -> Self {
        self.statistics = Some(statistics);
        self
    }

    /// Starts light `light`'s passes: clears `target` to fully lit (the
    /// technique contract) and opens the technique's debug group.
    pub(crate) fn begin_light(&mut self, light: usize, target: &wgpu::TextureView) {
        drop(self.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("visibility_clear"),
            color_attachments: &[color_attachment(target, Some(wgpu::Color::WHITE))],
            ..Default::default()
        }));
        self.timer.set_light(light);
        self.encoder.push_debug_group(&self.group);
    }

    /// Closes light `light`'s debug group.
    pub(crate) fn end_light(&mut self) {
        self.encoder.pop_debug_group();
    }

    /// The encoder, after the last pass: for the framework to resolve the timers and submit.
    pub(crate) fn finish(self) -> wgpu::CommandEncoder {
        self.encoder
    }

    /// Begins a render pass labelled `label`, timed under that name (and, in a counting frame,
    /// with its pipeline statistics queried). The pass derefs to a [`wgpu::RenderPass`].
    pub fn render_pass<'p>(
        &'p mut self,
        label: &str,
        color_attachments: &[Option<wgpu::RenderPassColorAttachment<'_>>],
        depth_stencil_attachment: Option<wgpu::RenderPassDepthStencilAttachment<'_>>,
    ) -> CountedRenderPass<'p> {
        let Self { encoder, timer, statistics, .. } = self;
        let target_bytes = statistics.as_ref().map(|_| stored_target_bytes(color_attachments, depth_stencil_attachment.as_ref()));
        let timestamp_writes = timer.render_pass(label);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments,
            depth_stencil_attachment,
            timestamp_writes,
            ..Default::default()
        });
        let query = statistics.as_mut().zip(target_bytes).and_then(|(queries, bytes)| queries.allocate(label, bytes));
        let counting = query.is_some();
        if let Some((query_set, index)) = query {
            pass.begin_pipeline_statistics_query(query_set, index);
        }
        CountedRenderPass { pass, counting }
    }

    /// Begins a compute pass labelled `label`, timed under that name (and, in a counting frame,
    /// with its pipeline statistics queried). The pass derefs to a [`wgpu::ComputePass`].
    pub fn compute_pass(&mut self, label: &str) -> CountedComputePass<'_> {
        let Self { encoder, timer, statistics, .. } = self;
        let timestamp_writes = timer.compute_pass(label);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes });
        let query = statistics.as_mut().and_then(|queries| queries.allocate(label, 0));
        let counting = query.is_some();
        if let Some((query_set, index)) = query {
            pass.begin_pipeline_statistics_query(query_set, index);
        }
        CountedComputePass { pass, counting }
    }

    /// Copies a texture region into a buffer, marked `label` in captures.
    pub fn copy_texture_to_buffer(
        &mut self,
        label: &str,
        source: wgpu::TexelCopyTextureInfo<'_>,
        destination: wgpu::TexelCopyBufferInfo<'_>,
        size: wgpu::Extent3d,
    ) {
        self.encoder.insert_debug_marker(label);
        self.encoder.copy_texture_to_buffer(source, destination, size);
    }

    /// Copies between buffers, marked `label` in captures.
    pub fn copy_buffer_to_buffer(
        &mut self,
        label: &str,
        source: &wgpu::Buffer,
        source_offset: u64,
        destination: &wgpu::Buffer,
        destination_offset: u64,
        size: u64,
    ) {
        self.encoder.insert_debug_marker(label);
        self.encoder.copy_buffer_to_buffer(source, source_offset, destination, destination_offset, size);
    }

    /// Fills a buffer range with zeros, marked `label` in captures.
    pub fn clear_buffer(&mut self, label: &str, buffer: &wgpu::Buffer, offset: u64, size: Option<u64>) {
        self.encoder.insert_debug_marker(label);
        self.encoder.clear_buffer(buffer, offset, size);
    }

    /// Reads `buffer` (usage `MAP_READ`) back in the middle of the frame: what
    /// was recorded so far is submitted, the CPU waits for it and maps the
    /// buffer, and recording goes on in a new encoder (PVSM's tile grid). The
    /// mapping and copy, after the submitted work has finished, are timed on
    /// the CPU under `label`: the stall's own cost. The wait for the submitted
    /// passes is not, since their GPU time is already counted; it is kept for
    /// [`Frame::last_read_back_wait_ms`].
    ///
    /// # Errors
    /// [`Error::Readback`] if the GPU fails or the buffer cannot be mapped.
    pub fn read_back(&mut self, label: &str, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
        let next = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(&format!("{}_after_{label}", self.group)) });
        let mut done = std::mem::replace(&mut self.encoder, next);
        // Debug groups do not span command buffers: close it here, reopen it in the next one.
        done.pop_debug_group();
        self.gpu.queue.submit([done.finish()]);
        self.encoder.push_debug_group(&self.group);
        let wait = std::time::Instant::now();
        self.gpu.wait_idle().map_err(|e| Error::readback(label, crate::error::Reason(e)))?;
        self.read_back_wait_ms = wait.elapsed().as_secs_f64() * 1e3;
        let start = std::time::Instant::now();
        let bytes = crate::readback::map_and_read(self.gpu, buffer, label)?;
        self.timer.cpu_scope(label, start.elapsed().as_secs_f64() * 1e3);
        Ok(bytes)
    }

    /// How long the last [`Frame::read_back`] waited, ms, from the submission to the GPU's idle:
    /// the submitted passes' run (their GPU time is counted already) and the stall around it.
    /// Not a timed scope, so that the frame's total does not count the passes twice; a technique
    /// reports it as a diagnostic.
    #[must_use]
    pub fn last_read_back_wait_ms(&self) -> f64 {
        self.read_back_wait_ms
    }

    /// Runs CPU work of the technique's (what its paper puts on the CPU, such
    /// as PVSM's kd-tree) and times it under `label`.
    pub fn cpu_scope<T>(&mut self, label: &str, work: impl FnOnce() -> T) -> T {
        let start = std::time::Instant::now();
        let out = work();
        self.timer.cpu_scope(label, start.elapsed().as_secs_f64() * 1e3);
        out
    }
}

/// A render pass opened by [`Frame::render_pass`]: a [`wgpu::RenderPass`] (through `Deref`) that,
/// in a counting frame, ends its pipeline-statistics query when dropped.
pub struct CountedRenderPass<'p> {
    pass: wgpu::RenderPass<'p>,
    counting: bool,
}

impl<'p> std::ops::Deref for CountedRenderPass<'p> {
    type Target = wgpu::RenderPass<'p>;
    fn deref(&self) -> &Self::Target {
        &self.pass
    }
}

impl std::ops::DerefMut for CountedRenderPass<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.pass
    }
}

impl Drop for CountedRenderPass<'_> {
    fn drop(&mut self) {
        if self.counting {
            self.pass.end_pipeline_statistics_query();
        }
    }
}

/// A compute pass opened by [`Frame::compute_pass`]: a [`wgpu::ComputePass`] (through `Deref`)
/// that, in a counting frame, ends its pipeline-statistics query when dropped.
pub struct CountedComputePass<'p> {
    pass: wgpu::ComputePass<'p>,
    counting: bool,
}

impl<'p> std::ops::Deref for CountedComputePass<'p> {
    type Target = wgpu::ComputePass<'p>;
    fn deref(&self) -> &Self::Target {
        &self.pass
    }
}

impl std::ops::DerefMut for CountedComputePass<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.pass
    }
}

impl Drop for CountedComputePass<'_> {
    fn drop(&mut self) {
        if self.counting {
            self.pass.end_pipeline_statistics_query();
        }
    }
}
