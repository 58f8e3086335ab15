//! What a technique records one frame into.

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::gbuffer::GBuffer;
use crate::gpu_scene::GpuScene;
use crate::timing::PassTimer;

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

/// One frame being recorded: the device, the scene, the shared inputs, an
/// encoder the technique may submit and replace (for mid-frame readbacks),
/// and a timer that times every pass opened through [`Frame::render_pass`] or
/// [`Frame::compute_pass`].
pub struct Frame<'a> {
    /// The GPU.
    pub gpu: &'a GpuContext,
    /// The scene.
    pub scene: &'a GpuScene,
    /// Shared inputs.
    pub shared: &'a SharedInputs,
    /// The command encoder passes are recorded into.
    pub encoder: wgpu::CommandEncoder,
    /// The pass timer.
    pub timer: &'a mut PassTimer,
}

impl Frame<'_> {
    /// Begins a render pass labelled `label`, timed under that name.
    pub fn render_pass<'p>(
        &'p mut self,
        label: &str,
        color_attachments: &[Option<wgpu::RenderPassColorAttachment<'_>>],
        depth_stencil_attachment: Option<wgpu::RenderPassDepthStencilAttachment<'_>>,
    ) -> wgpu::RenderPass<'p> {
        let timestamp_writes = self.timer.render_pass(label);
        self.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments,
            depth_stencil_attachment,
            timestamp_writes,
            ..Default::default()
        })
    }

    /// Begins a compute pass labelled `label`, timed under that name.
    pub fn compute_pass(&mut self, label: &str) -> wgpu::ComputePass<'_> {
        let timestamp_writes = self.timer.compute_pass(label);
        self.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes })
    }

    /// Submits what was recorded so far and starts a new encoder, so that the
    /// technique can read results back in the middle of the frame (PVSM's tile
    /// grid, for instance). Returns the submission to wait for.
    pub fn submit_and_replace(&mut self, label: &str) -> wgpu::SubmissionIndex {
        let next = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        let done = std::mem::replace(&mut self.encoder, next);
        self.gpu.queue.submit([done.finish()])
    }
}
