//! GPU plumbing that several steps share; it holds no step of the paper itself. Here are the
//! WGSL files every wedges shader imports (`wedges_common.wgsl`, `wedges_counts.wgsl`), the
//! counters of `--count-work` that every pass adds to, the format of the depth-stencil target
//! that the depth copy fills and the shadow volumes, wedges and umbra mask test, the indirect
//! arguments that the silhouettes (Sec. 4.1) write and the later steps draw and dispatch by, the
//! storage-buffer helpers, and the casting mesh on the GPU ([`MeshPasses`]): its buffers and the
//! bind groups through which the silhouettes, the shadow volumes and the wedges (Sec. 4.2, 4.3)
//! read them.

use bytemuck::Pod;
use ssm_core::passes::{bind_group, bind_group_layout, uniform_buffer, uniform_entry};
use ssm_core::read_counts::ReadCounts;
use ssm_core::{Result, TechniqueSetup, UniformStruct};
use wgpu::util::DeviceExt;

use crate::silhouettes::{COUNTER_WORDS, SilhouettePasses, WEDGE_RECORD_BYTES, WedgesMeshUniform};
use crate::{CastingMesh, MAX_SILHOUETTE_BUFFERS, MeshReport, WedgesSettingsUniform, volumes, wedges};

/// WGSL files the wedges shaders import besides `common/`.
pub(crate) const LOCAL_SHADERS: &[(&str, &str)] = &[
    (WedgesSettingsUniform::WGSL_IMPORT, WedgesSettingsUniform::WGSL),
    (WedgesMeshUniform::WGSL_IMPORT, WedgesMeshUniform::WGSL),
    ("wedges/wedges_common.wgsl", ssm_shaders::wedges::WEDGES_COMMON),
    ("wedges/wedges_counts.wgsl", ssm_shaders::wedges::WEDGES_COUNTS),
    ("wedges/wedges_wedges.wgsl", wedges::WEDGES_SHADER),
];

/// The counters of `--count-work` (issue #40; [`TechniqueSetup::count_work`]), in the order of
/// `wedges_counts.wgsl`'s `COUNTER_*` indices: (pass, unit). The passes that run without a
/// casting mesh come first, so that without one the rest are left out (a counter of a pass that
/// did not run would be work that was not done). Every pass that reads counts the bytes its reads
/// fetched beside them.
pub(crate) const COUNTERS: &[(&str, &str)] = &[
    ("wedges_depth_copy", "reads"),
    ("wedges_depth_copy", "read_bytes"),
    ("wedges_resolve", "reads"),
    ("wedges_resolve", "read_bytes"),
    ("wedges_wedges", "reads"),
    ("wedges_wedges", "read_bytes"),
    ("wedges_blend", "reads"),
    ("wedges_blend", "read_bytes"),
    ("wedges_blend", "storage_bytes"),
    ("wedges_silhouettes", "atomics"),
    ("wedges_silhouettes", "storage_bytes"),
];
/// The counters of the passes that run without a casting mesh.
pub(crate) const COUNTERS_WITHOUT_MESH: usize = 4;

/// Format of the shadow volumes' depth-stencil target.
pub const STENCIL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24PlusStencil8;
/// Threads per compute workgroup (`WORKGROUP`).
pub(crate) const WORKGROUP: u32 = 256;
/// u32s of the indirect arguments: two dispatches, then per group four draws.
pub(crate) const INDIRECT_WORDS: u64 = 8 + 16 * MAX_SILHOUETTE_BUFFERS as u64;

/// Byte offset of group `group`'s draw arguments (sides 0, caps 1, wedges 2, blend 3).
pub(crate) fn draw_offset(group: u32, draw: u64) -> u64 {
    (8 + 16 * u64::from(group) + 4 * draw) * 4
}

/// A storage buffer labelled `label` holding `contents` (at least 16 bytes: wgpu refuses empty bindings).
pub(crate) fn storage_init<T: Pod>(device: &wgpu::Device, label: &str, contents: &[T], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let mut bytes = bytemuck::cast_slice::<T, u8>(contents).to_vec();
    bytes.resize(bytes.len().max(16), 0);
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: &bytes,
        usage: wgpu::BufferUsages::STORAGE | usage,
    })
}

/// An uninitialised storage buffer of `size` bytes (at least 16).
pub(crate) fn storage(device: &wgpu::Device, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16).next_multiple_of(4),
        usage: wgpu::BufferUsages::STORAGE | usage,
        mapped_at_creation: false,
    })
}

pub(crate) fn storage_entry(binding: u32, read_only: bool, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// The casting mesh on the GPU, and everything drawn from it.
pub(crate) struct MeshPasses {
    pub(crate) silhouettes: SilhouettePasses,
    pub(crate) face_workgroups: u32,
    pub(crate) record_workgroups: u32,
    pub(crate) volume_group: wgpu::BindGroup,
    pub(crate) wedge_group: wgpu::BindGroup,
    pub(crate) side_pipeline: wgpu::RenderPipeline,
    pub(crate) cap_pipeline: wgpu::RenderPipeline,
    pub(crate) wedge_pipeline: wgpu::RenderPipeline,
    pub(crate) counters: wgpu::Buffer,
    pub(crate) half_edges: wgpu::Buffer,
    /// Per closed component, its winding number around the light's centre (cleared per light).
    pub(crate) winding: wgpu::Buffer,
    pub(crate) report: MeshReport,
}

impl MeshPasses {
    /// Uploads the casting mesh and builds the bind groups and pipelines of the silhouettes, the
    /// shadow volumes and the wedges.
    pub(crate) fn new(
        setup: &TechniqueSetup<'_>,
        casting: &CastingMesh,
        uniform: WedgesMeshUniform,
        (settings_buffer, indirect, read_counts): (&wgpu::Buffer, &wgpu::Buffer, &ReadCounts),
    ) -> Result<Self> {
        let gpu = setup.gpu;
        let device = &gpu.device;
        let face_count = u64::from(uniform.face_count);
        let half_edge_bytes = u64::from(casting.half_edge_capacity) * WEDGE_RECORD_BYTES;
        let mesh_uniform = uniform_buffer(device, "wedges_mesh_uniform", &uniform);
        let positions = storage_init(device, "wedges_positions", &casting.positions, wgpu::BufferUsages::empty());
        let faces = storage_init(device, "wedges_faces", &casting.faces, wgpu::BufferUsages::empty());
        let records = storage_init(device, "wedges_edge_records", &casting.records, wgpu::BufferUsages::empty());
        let face_state = storage(device, "wedges_face_state", face_count * 4, wgpu::BufferUsages::empty());
        let labels = storage(device, "wedges_region_labels", face_count * 4, wgpu::BufferUsages::empty());
        let ranks = storage(device, "wedges_region_ranks", face_count * 4, wgpu::BufferUsages::empty());
        let block_sums = storage(device, "wedges_rank_block_sums", u64::from(uniform.rank_blocks) * 4, wgpu::BufferUsages::empty());
        let counters = storage(device, "wedges_counters", COUNTER_WORDS * 4, wgpu::BufferUsages::COPY_SRC);
        let half_edges = storage(device, "wedges_half_edges", half_edge_bytes, wgpu::BufferUsages::COPY_SRC);
        let caps = storage(device, "wedges_cap_faces", face_count * 4, wgpu::BufferUsages::empty());
        let winding =
            storage(device, "wedges_component_winding", casting.report.closed_components() as u64 * 4, wgpu::BufferUsages::COPY_DST);
        let component_convex = storage_init(device, "wedges_component_convex", &casting.closed_convex, wgpu::BufferUsages::empty());

        let compute = wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![uniform_entry(0), uniform_entry(1)];
        entries.extend((2..5).map(|b| storage_entry(b, true, compute)));
        entries.extend((5..13).map(|b| storage_entry(b, false, compute)));
        entries.push(storage_entry(13, true, compute));
        entries.push(ReadCounts::layout_entry(14));
        let mesh_layout = bind_group_layout(device, "wedges_silhouettes_layout", &entries);
        let mesh_group = bind_group(
            device,
            "wedges_silhouettes_bind_group",
            &mesh_layout,
            &[
                settings_buffer.as_entire_binding(),
                mesh_uniform.as_entire_binding(),
                positions.as_entire_binding(),
                faces.as_entire_binding(),
                records.as_entire_binding(),
                face_state.as_entire_binding(),
                labels.as_entire_binding(),
                ranks.as_entire_binding(),
                block_sums.as_entire_binding(),
                counters.as_entire_binding(),
                half_edges.as_entire_binding(),
                caps.as_entire_binding(),
                winding.as_entire_binding(),
                component_convex.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        let indirect_layout = bind_group_layout(device, "wedges_indirect_layout", &[storage_entry(0, false, compute)]);
        let indirect_group = bind_group(device, "wedges_indirect_bind_group", &indirect_layout, &[indirect.as_entire_binding()]);
        let silhouettes = SilhouettePasses::new(gpu, (&mesh_layout, mesh_group), (&indirect_layout, indirect_group), read_counts)?;

        let vertex = wgpu::ShaderStages::VERTEX;
        let volume_layout =
            bind_group_layout(device, "wedges_volume_layout", &(0..5).map(|b| storage_entry(b, true, vertex)).collect::<Vec<_>>());
        let volume_group = bind_group(
            device,
            "wedges_volume_bind_group",
            &volume_layout,
            &[
                positions.as_entire_binding(),
                faces.as_entire_binding(),
                face_state.as_entire_binding(),
                half_edges.as_entire_binding(),
                caps.as_entire_binding(),
            ],
        );
        let (side_pipeline, cap_pipeline) = volumes::volume_pipelines(gpu, &volume_layout)?;

        let wedge_layout = bind_group_layout(
            device,
            "wedges_wedge_layout",
            &[storage_entry(0, true, wgpu::ShaderStages::VERTEX_FRAGMENT), uniform_entry(1), ReadCounts::layout_entry(2)],
        );
        let wedge_group = bind_group(
            device,
            "wedges_wedge_bind_group",
            &wedge_layout,
            &[half_edges.as_entire_binding(), settings_buffer.as_entire_binding(), read_counts.buffer().as_entire_binding()],
        );
        let wedge_pipeline = wedges::wedge_pipeline(gpu, &wedge_layout, (read_counts, setup.count_work))?;
        Ok(Self {
            silhouettes,
            face_workgroups: uniform.rank_blocks,
            record_workgroups: uniform.record_count.div_ceil(WORKGROUP),
            volume_group,
            wedge_group,
            side_pipeline,
            cap_pipeline,
            wedge_pipeline,
            counters,
            half_edges,
            winding,
            report: casting.report,
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use crate::blend::{SHADED_COUNT_FORMAT, SILHOUETTE_FORMAT, UMBRA_MASK_FORMAT};

    /// The shaders count each texel they read at its format's size, and each storage element at
    /// its type's (`wedges_counts.wgsl`'s `*_BYTES`), and index the counters in [`COUNTERS`]'s order.
    #[test]
    fn the_shaders_count_bytes_read_at_the_formats_sizes() {
        let gbuffer = [
            ("GBUFFER_DEPTH_BYTES", ssm_core::GBuffer::DEPTH_FORMAT),
            ("GBUFFER_TEXEL_BYTES", ssm_core::GBuffer::POSITION_FORMAT),
            ("GBUFFER_TEXEL_BYTES", ssm_core::GBuffer::NORMAL_FORMAT),
        ];
        let own = [
            ("SILHOUETTE_TEXEL_BYTES", SILHOUETTE_FORMAT),
            ("SHADED_COUNT_TEXEL_BYTES", SHADED_COUNT_FORMAT),
            ("UMBRA_MASK_TEXEL_BYTES", UMBRA_MASK_FORMAT),
        ];
        let constants: Vec<(&str, wgpu::TextureFormat)> = gbuffer.into_iter().chain(own).collect();
        let missing = ssm_core::read_counts::missing_texel_byte_constants(ssm_shaders::wedges::WEDGES_COUNTS, &constants);
        assert!(missing.is_empty(), "wedges_counts.wgsl lacks {missing:?}");
        // The final buffer's elements are vec4<f32>, the fragment counts u32.
        let elements = [("FINAL_ELEMENT_BYTES", size_of::<[f32; 4]>()), ("FRAGMENT_COUNT_BYTES", size_of::<u32>())];
        for (constant, bytes) in elements {
            let line = format!("const {constant}: u32 = {bytes}u;");
            assert!(ssm_shaders::wedges::WEDGES_COUNTS.contains(&line), "wedges_counts.wgsl lacks `{line}`");
        }
        let counters = [
            ("COUNTER_DEPTH_COPY_READS", ("wedges_depth_copy", "reads")),
            ("COUNTER_RESOLVE_READS", ("wedges_resolve", "reads")),
            ("COUNTER_WEDGE_READS", ("wedges_wedges", "reads")),
            ("COUNTER_BLEND_READS", ("wedges_blend", "reads")),
            ("COUNTER_BLEND_STORAGE_BYTES", ("wedges_blend", "storage_bytes")),
            ("COUNTER_SILHOUETTE_ATOMICS", ("wedges_silhouettes", "atomics")),
            ("COUNTER_SILHOUETTE_STORAGE_BYTES", ("wedges_silhouettes", "storage_bytes")),
        ];
        for (constant, counter) in counters {
            let index = COUNTERS.iter().position(|c| *c == counter).unwrap();
            let line = format!("const {constant}: u32 = {index}u;");
            assert!(ssm_shaders::wedges::WEDGES_COUNTS.contains(&line), "wedges_counts.wgsl lacks `{line}`");
            // `record_reads` counts a pass's read bytes in the counter after its reads.
            if counter.1 == "reads" {
                assert_eq!(COUNTERS[index + 1], (counter.0, "read_bytes"));
            }
        }
        assert!(COUNTERS[..COUNTERS_WITHOUT_MESH].iter().all(|(pass, _)| ["wedges_depth_copy", "wedges_resolve"].contains(pass)));
        assert!(COUNTERS[COUNTERS_WITHOUT_MESH..].iter().all(|(pass, _)| !["wedges_depth_copy", "wedges_resolve"].contains(pass)));
    }

    #[test]
    fn draw_arguments_follow_the_shader_layout() {
        // DRAW_ARGUMENTS = 8 u32s, GROUP_ARGUMENTS = 16, four draws of four u32s.
        assert_eq!(draw_offset(0, 0), 32);
        assert_eq!(draw_offset(1, 3), (8 + 16 + 12) * 4);
        assert_eq!(INDIRECT_WORDS * 4, draw_offset(MAX_SILHOUETTE_BUFFERS, 0));
    }
}
