//! Composite shading: visibility × Lambert + ambient, to an sRGB image.

use crate::context::GpuContext;
use crate::error::Result;
use crate::gbuffer::GBuffer;
use crate::gpu_scene::GpuScene;
use crate::passes::{color_attachment, fullscreen_pipeline, labelled_view, render_texture};
use crate::shader::create_shader;

/// The composite pass and its target.
#[derive(Debug)]
pub struct Composite {
    /// The shaded image.
    pub target: wgpu::Texture,
    target_view: wgpu::TextureView,
    base_pipeline: wgpu::RenderPipeline,
    light_pipeline: wgpu::RenderPipeline,
    visibility_groups: Vec<wgpu::BindGroup>,
}

impl Composite {
    /// Format of [`Composite::target`].
    pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

    /// Builds the pipelines and the target, reading one visibility view per light.
    ///
    /// # Errors
    /// [`Error::Gpu`](crate::Error::Gpu) if the shader is rejected.
    pub fn new(gpu: &GpuContext, scene: &GpuScene, visibility_views: &[wgpu::TextureView]) -> Result<Self> {
        let device = &gpu.device;
        let target = render_texture(device, "composite_target", scene.width, scene.height, Self::FORMAT, wgpu::TextureUsages::COPY_SRC);
        let target_view = labelled_view(&target, "composite_target");
        let visibility_layout = gpu.texture_layout();
        // Both pipelines once per device, shared by every renderer.
        let build = |entry: &'static str, blend: Option<wgpu::BlendState>| {
            gpu.cached_render_pipeline(&format!("{entry}_pipeline"), |gpu| {
                let module = create_shader(gpu, "composite_shader", ssm_shaders::core::COMPOSITE)?;
                let layouts = [gpu.uniform_layout(), gpu.gbuffer_layout(), gpu.texture_layout()];
                let target = wgpu::ColorTargetState { format: Self::FORMAT, blend, write_mask: wgpu::ColorWrites::ALL };
                Ok(fullscreen_pipeline(&gpu.device, &format!("{entry}_pipeline"), &module, entry, &layouts, &[target], &[]))
            })
        };
        let base_pipeline = build("composite_base", None)?;
        let additive = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let light_pipeline = build("composite_light", Some(wgpu::BlendState { color: additive, alpha: additive }))?;
        let visibility_groups = visibility_views
            .iter()
            .enumerate()
            .map(|(light, view)| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("composite_visibility_bind_group_{light}")),
                    layout: visibility_layout,
                    entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(view) }],
                })
            })
            .collect();
        Ok(Self { target, target_view, base_pipeline, light_pipeline, visibility_groups })
    }

    /// Records the composite of every light's visibility.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, scene: &GpuScene, gbuffer: &GBuffer) {
        encoder.push_debug_group("composite");
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("composite"),
            color_attachments: &[color_attachment(&self.target_view, Some(wgpu::Color::BLACK))],
            ..Default::default()
        });
        pass.set_bind_group(1, &gbuffer.bind_group, &[]);
        for (light, visibility) in self.visibility_groups.iter().enumerate() {
            pass.set_bind_group(0, &scene.light_bind_groups[light], &[]);
            pass.set_bind_group(2, visibility, &[]);
            if light == 0 {
                pass.set_pipeline(&self.base_pipeline);
                pass.draw(0..3, 0..1);
                pass.set_pipeline(&self.light_pipeline);
            }
            pass.draw(0..3, 0..1);
        }
        drop(pass);
        encoder.pop_debug_group();
    }
}
