//! Step 2: the depth copy (`wedges_depth_copy.wgsl`; no section of the paper: wgpu's G-buffer
//! depth has no stencil): the G-buffer's depth into the technique's `Depth24PlusStencil8` target
//! that the shadow volumes (Sec. 4.1) count in and the wedges (Sec. 4.2) test against, moved by
//! [`DEPTH_BIAS`](crate::DEPTH_BIAS) towards the side of the surface that faces the light.

use ssm_core::passes::{bind_group, bind_group_layout, texture_entry, uniform_entry};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Frame, GpuContext, Result};

use crate::PenumbraWedges;
use crate::gpu::{LOCAL_SHADERS, STENCIL_FORMAT};

/// The G-buffer's depth into the stencil target.
const DEPTH_COPY_SHADER: &str = ssm_shaders::wedges::WEDGES_DEPTH_COPY;

/// The depth copy's pipeline and bind group (the G-buffer's depth, position and normal, the
/// settings and the camera).
pub(crate) fn depth_copy(
    gpu: &GpuContext,
    gbuffer: &ssm_core::GBuffer,
    (settings, camera): (&wgpu::Buffer, &wgpu::Buffer),
    read_counts: &ReadCounts,
) -> Result<(wgpu::RenderPipeline, wgpu::BindGroup)> {
    let device = &gpu.device;
    let layout = bind_group_layout(
        device,
        "wedges_depth_copy_layout",
        &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            uniform_entry(1),
            texture_entry(2),
            texture_entry(3),
            uniform_entry(4),
            ReadCounts::layout_entry(5),
        ],
    );
    let group = bind_group(
        device,
        "wedges_depth_copy_bind_group",
        &layout,
        &[
            wgpu::BindingResource::TextureView(&gbuffer.depth_view),
            settings.as_entire_binding(),
            wgpu::BindingResource::TextureView(&gbuffer.position_view),
            wgpu::BindingResource::TextureView(&gbuffer.normal_view),
            camera.as_entire_binding(),
            read_counts.buffer().as_entire_binding(),
        ],
    );
    let module = create_shader_with_imports(gpu, "wedges_depth_copy_shader", DEPTH_COPY_SHADER, LOCAL_SHADERS)?;
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("wedges_depth_copy_pipeline_layout"),
        bind_group_layouts: &[Some(gpu.uniform_layout()), Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("wedges_depth_copy_pipeline"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("fullscreen_vertex"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: STENCIL_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("wedges_depth_copy"),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &read_counts.pipeline_constants(), ..Default::default() },
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    });
    Ok((pipeline, group))
}

impl PenumbraWedges {
    /// The depth copy's pass: clears the stencil and writes the depth.
    pub(crate) fn encode_depth_copy(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup) {
        let mut pass = frame.render_pass(
            "wedges_depth_copy",
            &[],
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.stencil_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0), store: wgpu::StoreOp::Store }),
            }),
        );
        pass.set_pipeline(&self.depth_copy_pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.depth_copy_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
