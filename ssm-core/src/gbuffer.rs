//! The shared G-buffer: what the camera sees, per pixel.

use crate::context::GpuContext;
use crate::error::Result;
use crate::gpu_scene::{GpuScene, SceneVertex};
use crate::passes::{color_attachment, labelled_view, render_texture};
use crate::shader::create_shader;
use crate::timing::PassTimer;

/// Depth, world position and normal from the camera.
#[derive(Debug)]
pub struct GBuffer {
    /// `xyz` world position, `w` 1 where geometry covers the pixel, else 0.
    pub position: wgpu::Texture,
    /// View of `position`.
    pub position_view: wgpu::TextureView,
    /// `xyz` unit normal turned towards the camera, `w` the surface's flags as a whole number
    /// ([`GBuffer::RECEIVES`] | [`GBuffer::CLOSED`]; [`GBuffer::flags`] decodes it).
    pub normal: wgpu::Texture,
    /// View of `normal`.
    pub normal_view: wgpu::TextureView,
    /// Camera depth (`[0, 1]`, perspective).
    pub depth: wgpu::Texture,
    /// View of `depth`.
    pub depth_view: wgpu::TextureView,
    /// Layout: binding 0 position, binding 1 normal, both `texture_2d<f32>` read with `textureLoad`.
    pub layout: wgpu::BindGroupLayout,
    /// The bind group of that layout.
    pub bind_group: wgpu::BindGroup,
    pipeline: wgpu::RenderPipeline,
}

impl GBuffer {
    /// Format of [`GBuffer::position`].
    pub const POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
    /// Format of [`GBuffer::normal`].
    pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
    /// Format of [`GBuffer::depth`].
    pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
    /// Flag of [`GBuffer::normal`]'s `w`: the surface has the receiver role (`GBUFFER_RECEIVES` in WGSL).
    pub const RECEIVES: u32 = 1;
    /// Flag of [`GBuffer::normal`]'s `w`: the surface's mesh is closed (`GBUFFER_CLOSED` in WGSL).
    pub const CLOSED: u32 = 2;

    /// The flags a normal texel's `w` holds.
    #[must_use]
    pub fn flags(normal_w: f32) -> u32 {
        normal_w.max(0.0).round() as u32
    }

    /// Allocates the targets and builds the pipeline.
    ///
    /// # Errors
    /// [`Error::Gpu`](crate::Error::Gpu) if the shader is rejected.
    pub fn new(gpu: &GpuContext, scene: &GpuScene) -> Result<Self> {
        let device = &gpu.device;
        let (width, height) = (scene.width, scene.height);
        let position = render_texture(device, "gbuffer_position", width, height, Self::POSITION_FORMAT, wgpu::TextureUsages::COPY_SRC);
        let normal = render_texture(device, "gbuffer_normal", width, height, Self::NORMAL_FORMAT, wgpu::TextureUsages::COPY_SRC);
        let depth = render_texture(device, "gbuffer_depth", width, height, Self::DEPTH_FORMAT, wgpu::TextureUsages::empty());
        let position_view = labelled_view(&position, "gbuffer_position");
        let normal_view = labelled_view(&normal, "gbuffer_normal");
        let depth_view = labelled_view(&depth, "gbuffer_depth");
        let layout = gpu.gbuffer_layout().clone();
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer_bind_group"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&position_view) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&normal_view) },
            ],
        });
        // One pipeline per device, shared by every renderer.
        let pipeline = gpu.cached_render_pipeline("gbuffer_pipeline", |gpu| {
            let device = &gpu.device;
            let module = create_shader(gpu, "gbuffer_shader", ssm_shaders::core::GBUFFER)?;
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("gbuffer_pipeline_layout"),
                bind_group_layouts: &[Some(gpu.uniform_layout())],
                immediate_size: 0,
            });
            Ok(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("gbuffer_pipeline"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("gbuffer_vertex"),
                    compilation_options: Default::default(),
                    buffers: &[Some(SceneVertex::layout())],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: Self::DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("gbuffer_fragment"),
                    compilation_options: Default::default(),
                    targets: &[Some(Self::POSITION_FORMAT.into()), Some(Self::NORMAL_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            }))
        })?;
        Ok(Self { position, position_view, normal, normal_view, depth, depth_view, layout, bind_group, pipeline })
    }

    /// Records the G-buffer pass, timed as `gbuffer`.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, scene: &GpuScene, timer: &mut PassTimer) {
        let timestamp_writes = timer.render_pass("gbuffer");
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &[
                color_attachment(&self.position_view, Some(wgpu::Color::TRANSPARENT)),
                color_attachment(&self.normal_view, Some(wgpu::Color::TRANSPARENT)),
            ],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes,
            ..Default::default()
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.camera_bind_group, &[]);
        scene.draw(&mut pass, scene.all());
    }
}
