//! Step 3, first pass per silhouette buffer: the umbra from the light's centre by z-fail shadow
//! volumes (Carmack's reverse; Forest et al., Sec. 4.1; `wedges_volumes.wgsl`). Every region's
//! volume, its silhouette half-edges extruded to infinity and its faces as near and far caps, is
//! counted into the stencil of the depth copy's target, wherever the camera is.

use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Frame, GpuContext, Result};

use crate::PenumbraWedges;
use crate::gpu::{LOCAL_SHADERS, MeshPasses, STENCIL_FORMAT, draw_offset};

/// z-fail shadow volumes.
const VOLUMES_SHADER: &str = ssm_shaders::wedges::WEDGES_VOLUMES;

/// The volumes' two pipelines: the silhouette half-edges' sides and the cap faces.
pub(crate) fn volume_pipelines(
    gpu: &GpuContext,
    volume_layout: &wgpu::BindGroupLayout,
) -> Result<(wgpu::RenderPipeline, wgpu::RenderPipeline)> {
    let volume_module = create_shader_with_imports(gpu, "wedges_volumes_shader", VOLUMES_SHADER, LOCAL_SHADERS)?;
    let side_pipeline = volume_pipeline(gpu, &volume_module, volume_layout, "wedges_side_vertex");
    let cap_pipeline = volume_pipeline(gpu, &volume_module, volume_layout, "wedges_cap_vertex");
    Ok((side_pipeline, cap_pipeline))
}

/// A z-fail volume pipeline (Carmack's reverse): no colour, depth tested (Less) but not written,
/// back faces that fail increment and front faces that fail decrement, with wrapping; depth
/// unclipped so that the caps and sides at infinity are not cut by the far plane.
fn volume_pipeline(gpu: &GpuContext, module: &wgpu::ShaderModule, layout: &wgpu::BindGroupLayout, entry: &str) -> wgpu::RenderPipeline {
    let device = &gpu.device;
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(&format!("{entry}_pipeline_layout")),
        bind_group_layouts: &[Some(gpu.uniform_layout()), Some(gpu.uniform_layout()), Some(layout)],
        immediate_size: 0,
    });
    let face = |depth_fail_op| wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::Always,
        fail_op: wgpu::StencilOperation::Keep,
        depth_fail_op,
        pass_op: wgpu::StencilOperation::Keep,
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(&format!("{entry}_pipeline")),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState { module, entry_point: Some(entry), compilation_options: Default::default(), buffers: &[] },
        primitive: wgpu::PrimitiveState { cull_mode: None, unclipped_depth: true, ..Default::default() },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: STENCIL_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: wgpu::StencilState {
                front: face(wgpu::StencilOperation::DecrementWrap),
                back: face(wgpu::StencilOperation::IncrementWrap),
                read_mask: 0xff,
                write_mask: 0xff,
            },
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    })
}

impl PenumbraWedges {
    /// One silhouette buffer's shadow volumes: the stencil cleared, then the sides and the caps.
    pub(crate) fn encode_volumes(&self, frame: &mut Frame<'_>, mesh: &MeshPasses, (light_frame, group): (&wgpu::BindGroup, u32)) {
        let camera = &frame.scene.camera_bind_group;
        let mut pass = frame.render_pass(
            "wedges_shadow_volumes",
            &[],
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.stencil_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0), store: wgpu::StoreOp::Store }),
            }),
        );
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, camera, &[]);
        pass.set_bind_group(2, &mesh.volume_group, &[]);
        pass.set_pipeline(&mesh.side_pipeline);
        pass.draw_indirect(&self.indirect, draw_offset(group, 0));
        pass.set_pipeline(&mesh.cap_pipeline);
        pass.draw_indirect(&self.indirect, draw_offset(group, 1));
    }
}
