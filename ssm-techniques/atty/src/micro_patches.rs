//! Step 4, the micro-patch list (Atty et al. 2006, Sec. 3.2, 3.3, 5.1.2;
//! `shaders/atty/atty_micro_patches.wgsl`): one invocation per occluder-map texel makes it a
//! micro-patch at its depth (Sec. 3.2), merged with its neighbours into one where their depths
//! agree (Sec. 5.1.2, with [`crate::patch_merge`]'s pyramid), bounds the patch's penumbra
//! rectangle on the soft shadow map (Sec. 3.3; by the far plane, or by [`crate::receiver_bounds`]'s
//! pyramid), and appends the patches that can hide anything to the list that the accumulation
//! draws with one indirect instanced draw. The paper read the occluder map back to the CPU for
//! this step; listing on the GPU is its stated next step (Sec. 4.3, 7).

use ssm_core::passes::{bind_group_layout, compute_pipeline, storage_entry, texture_entry, uniform_entry};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Error, Frame, LightDepthMap, Result, TechniqueSetup};

use crate::LOCAL_SHADERS;
use crate::counts::texel_bytes;
use crate::gpu::SideAccumulation;
use crate::patch_merge::PATCH_MERGE;
use crate::receiver_bounds::RECEIVER_BOUNDS;

/// The micro-patch list the accumulation draws.
const PATCHES_SHADER: &str = ssm_shaders::atty::ATTY_MICRO_PATCHES;
/// Bytes of one micro-patch record (`MicroPatchRecord` in `atty_settings.wgsl`).
pub(crate) const PATCH_RECORD_BYTES: u64 = 32;

pub(crate) fn patches_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    bind_group_layout(
        device,
        "atty_patches_layout",
        &[
            texture_entry(0),
            uniform_entry(1),
            texture_entry(2),
            texture_entry(3),
            storage_entry(4, false),
            storage_entry(5, false),
            ReadCounts::layout_entry(6),
        ],
    )
}

/// The pass that lists the micro-patches (`atty_micro_patches.wgsl`).
pub(crate) fn patches_pipeline(setup: &TechniqueSetup<'_>, read_counts: &ReadCounts) -> Result<wgpu::ComputePipeline> {
    let device = &setup.gpu.device;
    let module = create_shader_with_imports(setup.gpu, "atty_patches_shader", PATCHES_SHADER, LOCAL_SHADERS)?;
    // The bytes a texel read fetches: of the occluder map and of the two pyramids.
    let [count_reads] = read_counts.pipeline_constants();
    let constants = [
        count_reads,
        ("OCCLUDER_TEXEL_BYTES", texel_bytes(LightDepthMap::FORMAT)),
        ("BOUNDS_TEXEL_BYTES", texel_bytes(RECEIVER_BOUNDS.format)),
        ("MERGE_TEXEL_BYTES", texel_bytes(PATCH_MERGE.format)),
    ];
    let pipeline = compute_pipeline(
        device,
        "atty_patches_pipeline",
        &module,
        "atty_patches",
        &[setup.gpu.uniform_layout(), &patches_layout(device)],
        &constants,
    );
    let messages = setup.gpu.take_errors();
    if !messages.is_empty() {
        return Err(Error::Gpu { during: "building Atty's micro-patch list pass".into(), messages });
    }
    Ok(pipeline)
}

/// Records one side's list pass through `light_frame`, a light's frame bind group: its patch
/// count back to 0, then one invocation per texel of its `occluder_map_size`² occluder map.
pub(crate) fn encode(
    frame: &mut Frame<'_>,
    light_frame: &wgpu::BindGroup,
    side: &SideAccumulation,
    (pipeline, occluder_map_size): (&wgpu::ComputePipeline, u32),
) {
    // The patch count back to 0 (bytes 4 to 8; the 4 vertices stay).
    frame.clear_buffer("atty_patch_count_reset", &side.draw_arguments, 4, Some(4));
    let mut pass = frame.compute_pass(side.patches_label);
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, light_frame, &[]);
    pass.set_bind_group(1, &side.patches_group, &[]);
    pass.dispatch_workgroups(occluder_map_size.div_ceil(8), occluder_map_size.div_ceil(8), 1);
}
