//! Step 6, the projection (Atty et al. 2006, Sec. 3.1, 3.5; `shaders/atty/atty_projection.wgsl`):
//! each visible point is projected into the light's frame and reads the soft shadow map there like
//! a shadow map (Sec. 3.1's projective texture), two-sided the larger occlusion of the front- and
//! back-face maps (Sec. 3.5), giving the screen-space visibility.

use ssm_core::passes::{bind_group, bind_group_layout, texture_entry, uniform_entry};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Error, Result, ScreenPass, TechniqueSetup, VISIBILITY_FORMAT};

use crate::counts::{READS, counter_slice, texel_bytes};
use crate::gpu::SideAccumulation;
use crate::receiver_map::ReceiverMap;
use crate::{Accumulation, LOCAL_SHADERS, NAME};

/// The projection of the SSM onto the screen.
pub(crate) const PROJECT_SHADER: &str = ssm_shaders::atty::ATTY_PROJECTION;

/// The projection pass's label.
pub(crate) const PROJECT_LABEL: &str = "atty_project";

/// The projection of the SSM (the larger occlusion of both sides, summed in `accumulation`'s
/// format) onto the screen.
pub(crate) fn projection(
    setup: &TechniqueSetup<'_>,
    (accumulations, accumulation): (&[SideAccumulation], Accumulation),
    receiver_map: &ReceiverMap,
    settings_buffer: &wgpu::Buffer,
    (read_counts, first_counter): (&ReadCounts, u32),
) -> Result<(ScreenPass, wgpu::BindGroup)> {
    let device = &setup.gpu.device;
    let layout = bind_group_layout(
        device,
        "atty_project_layout",
        &[texture_entry(0), texture_entry(1), texture_entry(2), uniform_entry(3), ReadCounts::layout_entry(4)],
    );
    let Some(front) = accumulations.first().map(|a| &a.soft_shadow_map) else {
        return Err(Error::Technique { technique: NAME.into(), message: "no occluder side to project".into() });
    };
    // One-sided: the front map stands in for the back one (max(x, x) = x).
    let back = accumulations.get(1).map_or(front, |a| &a.soft_shadow_map);
    let group = bind_group(
        device,
        "atty_project_bind_group",
        &layout,
        &[
            wgpu::BindingResource::TextureView(front),
            wgpu::BindingResource::TextureView(back),
            wgpu::BindingResource::TextureView(receiver_map.view()),
            settings_buffer.as_entire_binding(),
            counter_slice(read_counts, first_counter, READS.len()),
        ],
    );
    let module = create_shader_with_imports(setup.gpu, "atty_project_shader", PROJECT_SHADER, LOCAL_SHADERS)?;
    // The bytes a texel read fetches: of the G-buffer (its normal has its position's format:
    // a test in counts.rs), the receiver map and the soft shadow maps.
    let [count_reads] = read_counts.pipeline_constants();
    let constants = [
        count_reads,
        ("GBUFFER_TEXEL_BYTES", texel_bytes(ssm_core::GBuffer::POSITION_FORMAT)),
        ("RECEIVER_TEXEL_BYTES", texel_bytes(receiver_map.format())),
        ("SOFT_SHADOW_TEXEL_BYTES", texel_bytes(accumulation.format())),
    ];
    let project =
        ScreenPass::new(setup, NAME, PROJECT_LABEL, (&module, "atty_project"), Some(&layout), VISIBILITY_FORMAT.into(), &constants)?;
    Ok((project, group))
}
