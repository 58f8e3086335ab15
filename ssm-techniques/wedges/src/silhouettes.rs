//! Step 1: the silhouettes from the light's centre (Forest et al., Sec. 4.1, done there on the
//! CPU with a half-edge structure; here every frame in compute passes, `wedges_silhouettes.wgsl`):
//! each closed component's winding number around the centre, the faces that take part, the
//! silhouette regions they form (hooking and pointer jumping, at most [`MAX_LABEL_ROUNDS`]
//! rounds), the regions ranked and given round-robin to the silhouette buffers, and per buffer
//! the silhouette half-edges, each with its penumbra wedge (Sec. 4.2), and the cap faces, in lists
//! drawn with indirect draws. Also what the diagnostics read back from them after the frame.

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::compute_pipeline;
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Frame, GpuContext, Result, UniformStruct};

use crate::gpu::{LOCAL_SHADERS, MeshPasses, WORKGROUP};
use crate::{CastingMesh, MAX_SILHOUETTE_BUFFERS};

/// Silhouettes, regions, groups, wedge construction (compute).
pub(crate) const SILHOUETTES_SHADER: &str = ssm_shaders::wedges::WEDGES_SILHOUETTES;

/// Label-propagation rounds recorded per frame; rounds after the labels settle dispatch nothing.
pub const MAX_LABEL_ROUNDS: u32 = 16;
/// Bytes of one silhouette half-edge with its wedge (`WedgeRecord`).
pub const WEDGE_RECORD_BYTES: u64 = 96;
/// u32s of the counters (`Counters`): eight scalars and seven arrays of [`MAX_SILHOUETTE_BUFFERS`].
pub(crate) const COUNTER_WORDS: u64 = 8 + 7 * MAX_SILHOUETTE_BUFFERS as u64;
/// The u32 where `Counters.stencil_levels` starts: after the eight scalars and six arrays.
const STENCIL_LEVELS_WORD: usize = 8 + 6 * MAX_SILHOUETTE_BUFFERS as usize;
/// Stencil levels: the count is 8 bits, wrapping (a point in 256 volumes of one buffer reads 0).
const STENCIL_LEVELS: u32 = 256;

/// The casting mesh's sizes as the shaders read them: the WGSL struct `WedgesMesh`, which the derive
/// writes and `shaders/wedges/wedges_common.wgsl` imports (`// #import rust/WedgesMesh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct WedgesMeshUniform {
    /// Faces of the casting mesh.
    pub(crate) face_count: u32,
    /// Edge records of the casting mesh (`CastingMesh::records`).
    pub(crate) record_count: u32,
    /// Slots of the half-edge table (`CastingMesh::half_edge_capacity`).
    half_edge_capacity: u32,
    /// Workgroups of the face-ranking pass: faces ÷ `WORKGROUP`, rounded up.
    pub(crate) rank_blocks: u32,
    /// The frame's width, pixels.
    width: u32,
    /// The frame's height, pixels.
    height: u32,
    _pad0: u32,
    _pad1: u32,
    /// The scene's bounding box, enlarged by a margin (w unused): wedges are cut at its faces.
    bounds_min: [f32; 4],
    bounds_max: [f32; 4],
}

/// Margin of the scene's box that cuts the wedges, as a fraction of its diagonal: receivers on
/// its faces stay strictly inside.
const BOUNDS_MARGIN: f32 = 1e-3;

impl WedgesMeshUniform {
    pub(crate) fn new(mesh: &CastingMesh, (width, height): (u32, u32), bounds: &ssm_scene::Aabb) -> Self {
        let face_count = mesh.faces.len() as u32;
        let margin = glam::Vec3::splat(bounds.size().length() * BOUNDS_MARGIN);
        Self {
            face_count,
            record_count: mesh.records.len() as u32,
            half_edge_capacity: mesh.half_edge_capacity,
            rank_blocks: face_count.div_ceil(WORKGROUP),
            width,
            height,
            _pad0: 0,
            _pad1: 0,
            bounds_min: (bounds.min - margin).extend(0.0).to_array(),
            bounds_max: (bounds.max + margin).extend(0.0).to_array(),
        }
    }
}

/// The compute passes that find the silhouettes and fill the draw lists.
pub(crate) struct SilhouettePasses {
    reset: wgpu::ComputePipeline,
    winding: wgpu::ComputePipeline,
    classify_faces: wgpu::ComputePipeline,
    hook: wgpu::ComputePipeline,
    jump: wgpu::ComputePipeline,
    control: wgpu::ComputePipeline,
    rank_blocks: wgpu::ComputePipeline,
    rank_scan: wgpu::ComputePipeline,
    rank_faces: wgpu::ComputePipeline,
    count_edges: wgpu::ComputePipeline,
    count_caps: wgpu::ComputePipeline,
    offsets: wgpu::ComputePipeline,
    scatter_edges: wgpu::ComputePipeline,
    scatter_caps: wgpu::ComputePipeline,
    mesh_group: wgpu::BindGroup,
    indirect_group: wgpu::BindGroup,
}

impl SilhouettePasses {
    /// The silhouette step's pipelines, with the casting mesh's group and the indirect arguments' group.
    pub(crate) fn new(
        gpu: &GpuContext,
        (mesh_layout, mesh_group): (&wgpu::BindGroupLayout, wgpu::BindGroup),
        (indirect_layout, indirect_group): (&wgpu::BindGroupLayout, wgpu::BindGroup),
        read_counts: &ReadCounts,
    ) -> Result<Self> {
        let device = &gpu.device;
        let module = create_shader_with_imports(gpu, "wedges_silhouettes_shader", SILHOUETTES_SHADER, LOCAL_SHADERS)?;
        let light = gpu.uniform_layout();
        let plain = [light, mesh_layout];
        let writes_arguments = [light, mesh_layout, indirect_layout];
        let constants = read_counts.pipeline_constants();
        let pipeline = |entry: &str, layouts: &[&wgpu::BindGroupLayout]| {
            compute_pipeline(device, &format!("{entry}_pipeline"), &module, entry, layouts, &constants)
        };
        Ok(Self {
            reset: pipeline("wedges_reset", &writes_arguments),
            winding: pipeline("wedges_winding", &plain),
            classify_faces: pipeline("wedges_classify_faces", &plain),
            hook: pipeline("wedges_hook", &plain),
            jump: pipeline("wedges_jump", &plain),
            control: pipeline("wedges_control", &writes_arguments),
            rank_blocks: pipeline("wedges_rank_blocks", &plain),
            rank_scan: pipeline("wedges_rank_scan", &plain),
            rank_faces: pipeline("wedges_rank_faces", &plain),
            count_edges: pipeline("wedges_count_edges", &plain),
            count_caps: pipeline("wedges_count_caps", &plain),
            offsets: pipeline("wedges_offsets", &writes_arguments),
            scatter_edges: pipeline("wedges_scatter_edges", &plain),
            scatter_caps: pipeline("wedges_scatter_caps", &plain),
            mesh_group,
            indirect_group,
        })
    }
}

impl MeshPasses {
    /// Every dispatch of the silhouette step, in one timed compute pass.
    pub(crate) fn encode_silhouettes(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup, indirect: &wgpu::Buffer) {
        let s = &self.silhouettes;
        frame.clear_buffer("wedges_component_winding_clear", &self.winding, 0, None);
        let mut pass = frame.compute_pass("wedges_silhouettes");
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &s.mesh_group, &[]);
        let single = |pass: &mut wgpu::ComputePass<'_>, pipeline: &wgpu::ComputePipeline| {
            pass.set_pipeline(pipeline);
            pass.set_bind_group(2, &s.indirect_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        };
        single(&mut pass, &s.reset);
        pass.set_pipeline(&s.winding);
        pass.dispatch_workgroups(self.face_workgroups, 1, 1);
        pass.set_pipeline(&s.classify_faces);
        pass.dispatch_workgroups(self.face_workgroups, 1, 1);
        for _ in 0..MAX_LABEL_ROUNDS {
            pass.set_pipeline(&s.hook);
            pass.dispatch_workgroups_indirect(indirect, 0);
            pass.set_pipeline(&s.jump);
            pass.dispatch_workgroups_indirect(indirect, 16);
            single(&mut pass, &s.control);
        }
        pass.set_pipeline(&s.rank_blocks);
        pass.dispatch_workgroups(self.face_workgroups, 1, 1);
        pass.set_pipeline(&s.rank_scan);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&s.rank_faces);
        pass.dispatch_workgroups(self.face_workgroups, 1, 1);
        pass.set_pipeline(&s.count_edges);
        pass.dispatch_workgroups(self.record_workgroups, 1, 1);
        pass.set_pipeline(&s.count_caps);
        pass.dispatch_workgroups(self.face_workgroups, 1, 1);
        single(&mut pass, &s.offsets);
        pass.set_pipeline(&s.scatter_edges);
        pass.dispatch_workgroups(self.record_workgroups, 1, 1);
        pass.set_pipeline(&s.scatter_caps);
        pass.dispatch_workgroups(self.face_workgroups, 1, 1);
    }

    /// The silhouette step's diagnostics, read back after the frame: half-edges, regions, cap
    /// faces, fallback wedges, label rounds, the stencil's bound, buffers used and loops.
    pub(crate) fn diagnostics(&self, gpu: &GpuContext, out: &mut Vec<(String, f64)>) {
        let word =
            |bytes: &[u8], index: usize| bytes.get(index * 4..index * 4 + 4).map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if let Ok(counters) = ssm_core::readback::read_buffer(gpu, &self.counters, COUNTER_WORDS * 4, "wedges counters") {
            let half_edges = word(&counters, 3);
            out.push(("silhouette_edges".to_owned(), f64::from(half_edges)));
            out.push(("silhouette_regions".to_owned(), f64::from(word(&counters, 2))));
            out.push(("cap_faces".to_owned(), f64::from(word(&counters, 4))));
            out.push(("fallback_wedges".to_owned(), f64::from(word(&counters, 5))));
            let rounds = word(&counters, 1);
            out.push(("label_rounds".to_owned(), f64::from(rounds)));
            // Every recorded round linked labels: the last may not have been the last needed, and
            // a region left split has silhouette edges (and wedges) inside it.
            out.push(("label_rounds_capped".to_owned(), f64::from(u8::from(rounds >= MAX_LABEL_ROUNDS))));
            // A bound on any point's stencil count (`Counters.stencil_levels`); past 255 the 8-bit
            // count may wrap to 0 (lit).
            let levels = (0..MAX_SILHOUETTE_BUFFERS as usize).map(|g| word(&counters, STENCIL_LEVELS_WORD + g)).max().unwrap_or(0);
            out.push(("stencil_levels_bound".to_owned(), f64::from(levels)));
            out.push(("stencil_may_wrap".to_owned(), f64::from(u8::from(levels >= STENCIL_LEVELS))));
            out.push(("silhouette_buffers_used".to_owned(), f64::from(word(&counters, 6))));
            if let Some(loops) = silhouette_loops(gpu, &self.half_edges, half_edges) {
                out.push(("silhouette_loops".to_owned(), loops as f64));
            }
        }
    }
}

/// Connected loops of the last frame's silhouette half-edges (their ends welded by position),
/// for the diagnostics only: read back after the frame, never during it.
fn silhouette_loops(gpu: &GpuContext, half_edges: &wgpu::Buffer, count: u32) -> Option<usize> {
    if count == 0 {
        return Some(0);
    }
    let bytes = ssm_core::readback::read_buffer(gpu, half_edges, u64::from(count) * WEDGE_RECORD_BYTES, "wedges half-edges").ok()?;
    let mut ids: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
    let mut parent: Vec<u32> = Vec::new();
    let mut id_of = |p: [f32; 3], parent: &mut Vec<u32>| {
        *ids.entry(p.map(f32::to_bits)).or_insert_with(|| {
            parent.push(parent.len() as u32);
            parent.len() as u32 - 1
        })
    };
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for record in bytes.chunks_exact(WEDGE_RECORD_BYTES as usize) {
        // a and b: the first two vec4s.
        let floats: &[f32] = bytemuck::cast_slice(&record[..32]);
        let a = id_of([floats[0], floats[1], floats[2]], &mut parent);
        let b = id_of([floats[4], floats[5], floats[6]], &mut parent);
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    Some((0..parent.len() as u32).filter(|&x| find(&mut parent, x) == x).count())
}
