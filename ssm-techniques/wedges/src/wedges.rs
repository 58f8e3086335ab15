//! Step 3, second pass per silhouette buffer: the penumbra wedges (Forest et al., Sec. 3.1, 4.2 and 4.3;
//! `wedges_wedges.wgsl`, and `wedges_wedges_counted.wgsl` for counting): each silhouette
//! half-edge's wedge drawn once, back faces tested against the scene; per fragment the inner or
//! outer half-wedge (Fig. 8), Lengyel's bounding-plane rejection (Fig. 7) and local near plane
//! (Fig. 9), and per radial part of the light (Fig. 6) the area beyond the edge integrated
//! exactly from the centre (Fig. 4), with the paper's seven parameters (Fig. 10) written into the
//! silhouette buffer.

use ssm_core::passes::color_attachment;
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Error, Frame, GpuContext, Result};

use crate::blend::{SHADED_COUNT_FORMAT, SILHOUETTE_FORMAT};
use crate::gpu::{LOCAL_SHADERS, MeshPasses, STENCIL_FORMAT, draw_offset};
use crate::{NAME, PenumbraWedges};

/// Penumbra wedges.
pub(crate) const WEDGES_SHADER: &str = ssm_shaders::wedges::WEDGES_WEDGES;
/// Penumbra wedges with the depth test forced before the fragment, for counting.
const WEDGES_COUNTED_SHADER: &str = ssm_shaders::wedges::WEDGES_WEDGES_COUNTED;

/// The wedge pipeline: back faces of the half-wedges (culling front faces, depth unclipped, tested
/// against the scene's), eight float targets, areas and counts added, rectangles and maxima kept by maximum.
///
/// Built for counting (`counting`, with `read_counts` enabled), the fragment counts its reads and has its depth
/// test forced before it (`wedges_wedges_counted.wgsl`: a fragment with a side effect is otherwise
/// tested after it runs, and every wedge fragment behind the scene would run and be counted),
/// which needs [`wgpu::Features::SHADER_EARLY_DEPTH_TEST`].
///
/// # Errors
/// [`Error::MissingFeatures`] when counting on a device without that feature; a shader error.
pub(crate) fn wedge_pipeline(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    (read_counts, counting): (&ReadCounts, bool),
) -> Result<wgpu::RenderPipeline> {
    let device = &gpu.device;
    let early_depth = wgpu::Features::SHADER_EARLY_DEPTH_TEST;
    if counting && !gpu.features().contains(early_depth) {
        return Err(Error::MissingFeatures { technique: NAME.into(), features: early_depth, adapter: gpu.describe() });
    }
    let (module, fragment_entry) = if counting {
        (
            create_shader_with_imports(gpu, "wedges_wedges_counted_shader", WEDGES_COUNTED_SHADER, LOCAL_SHADERS)?,
            "wedges_wedge_fragment_counted",
        )
    } else {
        (create_shader_with_imports(gpu, "wedges_wedges_shader", WEDGES_SHADER, LOCAL_SHADERS)?, "wedges_wedge_fragment")
    };
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("wedges_wedge_pipeline_layout"),
        bind_group_layouts: &[Some(gpu.uniform_layout()), Some(gpu.uniform_layout()), Some(layout), Some(gpu.gbuffer_layout())],
        immediate_size: 0,
    });
    let component = |operation| wgpu::BlendComponent { src_factor: wgpu::BlendFactor::One, dst_factor: wgpu::BlendFactor::One, operation };
    let target = |operation| {
        Some(wgpu::ColorTargetState {
            format: SILHOUETTE_FORMAT,
            blend: Some(wgpu::BlendState { color: component(operation), alpha: component(operation) }),
            write_mask: wgpu::ColorWrites::ALL,
        })
    };
    let add = wgpu::BlendOperation::Add;
    let max = wgpu::BlendOperation::Max;
    let mut targets = [target(add), target(max), target(max), target(max), target(max), target(max), target(max), target(add)];
    if let Some(Some(shaded)) = targets.last_mut() {
        shaded.format = SHADED_COUNT_FORMAT;
    }
    Ok(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("wedges_wedge_pipeline"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("wedges_wedge_vertex"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Front), unclipped_depth: true, ..Default::default() },
        // A surface in front of the back face may be inside; one behind it is not.
        depth_stencil: Some(wgpu::DepthStencilState {
            format: STENCIL_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::GreaterEqual),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some(fragment_entry),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &read_counts.pipeline_constants(), ..Default::default() },
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    }))
}

impl PenumbraWedges {
    /// One silhouette buffer's wedges into its targets, tested against its stencil's depth.
    pub(crate) fn encode_wedges(
        &self,
        frame: &mut Frame<'_>,
        mesh: &MeshPasses,
        (light_frame, group): (&wgpu::BindGroup, u32),
        point_light: bool,
    ) {
        let camera = &frame.scene.camera_bind_group;
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment<'_>>> =
            self.blend.silhouette_views.iter().map(|view| color_attachment(view, Some(wgpu::Color::TRANSPARENT))).collect();
        let mut pass = frame.render_pass(
            "wedges_wedges",
            &attachments,
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.stencil_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
            }),
        );
        // A point light has wedges of zero width: the umbra alone is the hard shadow.
        if !point_light {
            pass.set_pipeline(&mesh.wedge_pipeline);
            pass.set_bind_group(0, light_frame, &[]);
            pass.set_bind_group(1, camera, &[]);
            pass.set_bind_group(2, &mesh.wedge_group, &[]);
            pass.set_bind_group(3, &self.gbuffer_group, &[]);
            pass.draw_indirect(&self.indirect, draw_offset(group, 2));
        }
    }
}
