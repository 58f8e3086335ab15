//! Step 5, the accumulation (Atty et al. 2006, Sec. 3.4, 4.1, 4.2;
//! `shaders/atty/atty_accumulation.wgsl`): each listed micro-patch is drawn as its penumbra
//! rectangle on the soft shadow map (SSM), and for every SSM texel in it the patch is projected
//! back from the receiver there onto the light; the fraction of the light it hides, a product of
//! two clamped 1-D overlaps (Sec. 3.4, 4.2; the geometry's twin is [`crate::geometry`]), is summed
//! into the float SSM by additive blending (Sec. 4.1), in FP32 or the paper's FP16 (Appendix A).

use ssm_core::passes::{bind_group_layout, color_attachment, storage_entry, texture_entry, uniform_entry};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Choice, Frame, Result, TechniqueSetup};

use crate::LOCAL_SHADERS;
use crate::counts::texel_bytes;
use crate::gpu::SideAccumulation;

/// The accumulation of micro-patches into the SSM.
const ACCUMULATE_SHADER: &str = ssm_shaders::atty::ATTY_ACCUMULATION;

/// The format the micro-patches' occlusions are summed in (Sec. 4.1, Appendix A).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum Accumulation {
    /// 32-bit float: needs FLOAT32_BLENDABLE.
    F32,
    /// 16-bit float: the paper's 2006 hardware; loses patches that hide less than 2⁻¹⁰ of the light.
    F16,
}

impl Accumulation {
    /// The soft shadow map's texture format.
    #[must_use]
    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            Self::F32 => wgpu::TextureFormat::R32Float,
            Self::F16 => wgpu::TextureFormat::R16Float,
        }
    }
}

pub(crate) fn accumulate_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    bind_group_layout(
        device,
        "atty_accumulate_layout",
        &[storage_entry(0, true), texture_entry(1), uniform_entry(2), ReadCounts::layout_entry(3)],
    )
}

/// The instanced micro-patch pipeline: one quad per occluder texel, summed by additive
/// blending into the float SSM (Sec. 4.1), reading the receiver map (of `receiver_format`).
pub(crate) fn accumulate_pipeline(
    setup: &TechniqueSetup<'_>,
    (accumulation, receiver_format): (Accumulation, wgpu::TextureFormat),
    read_counts: &ReadCounts,
) -> Result<wgpu::RenderPipeline> {
    let device = &setup.gpu.device;
    // The bytes a fragment's receiver texel fetches.
    let [count_reads] = read_counts.pipeline_constants();
    let constants = [count_reads, ("RECEIVER_TEXEL_BYTES", texel_bytes(receiver_format))];
    let module = create_shader_with_imports(setup.gpu, "atty_accumulate_shader", ACCUMULATE_SHADER, LOCAL_SHADERS)?;
    let layout = accumulate_layout(device);
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("atty_accumulate_pipeline_layout"),
        bind_group_layouts: &[Some(setup.gpu.uniform_layout()), Some(&layout)],
        immediate_size: 0,
    });
    let additive = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    Ok(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("atty_accumulate_pipeline"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("atty_patch_vertex"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::TriangleStrip, ..Default::default() },
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("atty_patch_fragment"),
            compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
            targets: &[Some(wgpu::ColorTargetState {
                format: accumulation.format(),
                blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                write_mask: wgpu::ColorWrites::RED,
            })],
        }),
        multiview_mask: None,
        cache: None,
    }))
}

/// Records one side's accumulation into its soft shadow map, through `light_frame`, a light's
/// frame bind group, after its list pass.
pub(crate) fn encode(frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup, side: &SideAccumulation, pipeline: &wgpu::RenderPipeline) {
    let mut pass = frame.render_pass(side.label, &[color_attachment(&side.soft_shadow_map, Some(wgpu::Color::TRANSPARENT))], None);
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, light_frame, &[]);
    pass.set_bind_group(1, &side.bind_group, &[]);
    // One quad (4-vertex strip) per listed micro-patch.
    pass.draw_indirect(&side.draw_arguments, 0);
}
