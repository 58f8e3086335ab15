//! Forest, Barthe and Paulin, *Realistic soft shadows by penumbra-wedges
//! blending*, Graphics Hardware 2006, on the penumbra-wedges (soft shadow
//! volumes) algorithm of Akenine-Möller and Assarsson 2002 and Assarsson and
//! Akenine-Möller 2003, with Lengyel's 2005 fill-rate tests.
//!
//! Per light and frame, entirely on the GPU:
//!
//! 1. **Silhouettes** (`wedges_silhouettes`, compute): each closed
//!    component's winding number around the light's centre tells whether the
//!    centre is inside it; faces are classified from the centre (those a ray
//!    from it crosses first take part: turned towards it, or away from it in
//!    a closed component around it), connected into *silhouette regions* (the
//!    faces that take part, joined across the edges whose volume sides cancel;
//!    each region is bounded by its silhouette loops), ranked, and given
//!    round-robin to `silhouette_buffers` groups; each group's silhouette
//!    half-edges, with their penumbra wedges, and cap faces are written into
//!    lists drawn with indirect draws (wgpu has no geometry shaders).
//! 2. Per group: **shadow volumes** (`wedges_shadow_volumes`): z-fail
//!    (Carmack's reverse) into the technique's Depth24PlusStencil8 target,
//!    whose depth is the G-buffer's (`wedges_depth_copy`), caps included;
//!    **wedges** (`wedges_wedges`), at the point the stencil judged (the
//!    G-buffer's moved by the depth copy's bias): each half-edge's inner and
//!    outer half-wedge, Lengyel's bounding-plane rejection, the local near plane,
//!    and per radial part of the light the occluded area integrated exactly
//!    from the centre, its bounding rectangle, the inner edges' maximum X and
//!    Y (Sec. 3.1, 4.2, 4.3); **blend** (`wedges_blend`): the group's buffer
//!    into the final one, summed (`blending=none`) or by Forest et al.'s
//!    ε = (A_f/B_f)(A_s/B_s)β (Sec. 3.2).
//! 3. **Resolve** (`wedges_resolve`): visibility = 1 − occluded share.
//!
//! No CPU work per frame depends on the triangle count. Everything is sized
//! and checked against the device's limits before anything is allocated
//! ([`AllocationPlan`]). `blending=none silhouette_buffers=1` is the plain
//! penumbra wedges of Akenine-Möller and Assarsson, the paper's baseline.
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique wedges --set
//! wedges.silhouette_buffers=4 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_wedges::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_wedges::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("wedges")?;
//! let params = info.params_from([("silhouette_buffers", "4")])?;
//! let mut renderer = Renderer::new(&gpu, &scene, 64, 48, &(info.requirements)(&params)?)?;
//! let mut technique = renderer.create_technique(info, &params)?;
//! let timings = renderer.render(technique.as_mut(), info.name)?;
//! // One value per pixel for the scene's first light: 1 lit, 0 in shadow.
//! let visibility = renderer.read_visibility(0, info.name)?;
//! assert_eq!(visibility.len(), 64 * 48);
//! assert!(visibility.iter().all(|v| (0.0..=1.0).contains(v)));
//! println!("{} in {:.2} ms", info.name, timings.frame_ms());
//! # Ok(())
//! # }
//! ```

mod mesh;
mod plan;
pub mod scenes;

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{
    bind_group, bind_group_layout, color_attachment, compute_pipeline, labelled_view, render_texture, texture_entry, uniform_buffer,
    uniform_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::work::ShaderWork;
use ssm_core::{
    Choice, Error, Frame, GpuContext, ParamValues, Preset, Requirements, Result, ScreenPass, Settings, ShadowTechnique, TechniqueInfo,
    TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct, VISIBILITY_FORMAT, register_technique,
};
use wgpu::util::DeviceExt;

pub use mesh::{CastingMesh, EdgeRecord, MeshReport, NO_FACE, TWO_SIDED_COMPONENT};
pub use plan::{AllocationPlan, FINAL_BINDING_BYTES_PER_PIXEL, PlannedBuffer, STORAGE_BUFFERS_PER_STAGE};

/// The registered name.
pub const NAME: &str = "wedges";

/// WGSL files the wedges shaders import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] = &[
    ("wedges/wedges_common.wgsl", ssm_shaders::wedges::WEDGES_COMMON),
    ("wedges/wedges_counts.wgsl", ssm_shaders::wedges::WEDGES_COUNTS),
    ("wedges/wedges_wedges.wgsl", WEDGES_SHADER),
];
/// Silhouettes, regions, groups, wedge construction (compute).
const SILHOUETTES_SHADER: &str = ssm_shaders::wedges::WEDGES_SILHOUETTES;
/// The G-buffer's depth into the stencil target.
const DEPTH_COPY_SHADER: &str = ssm_shaders::wedges::WEDGES_DEPTH_COPY;
/// z-fail shadow volumes.
const VOLUMES_SHADER: &str = ssm_shaders::wedges::WEDGES_VOLUMES;
/// Penumbra wedges.
const WEDGES_SHADER: &str = ssm_shaders::wedges::WEDGES_WEDGES;
/// Blending and resolve.
const BLEND_SHADER: &str = ssm_shaders::wedges::WEDGES_BLEND;
/// Penumbra wedges with the depth test forced before the fragment, for counting.
const WEDGES_COUNTED_SHADER: &str = ssm_shaders::wedges::WEDGES_WEDGES_COUNTED;

/// The counters of `--count-work` (issue #40; [`TechniqueSetup::count_work`]), in the order of
/// `wedges_counts.wgsl`'s `COUNTER_*` indices: (pass, unit). The passes that run without a
/// casting mesh come first, so that without one the rest are left out (a counter of a pass that
/// did not run would be work that was not done). Every pass that reads counts the bytes its reads
/// fetched beside them.
const COUNTERS: &[(&str, &str)] = &[
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
const COUNTERS_WITHOUT_MESH: usize = 4;

/// Most silhouette buffers (`MAX_SILHOUETTE_BUFFERS` in the WGSL).
pub const MAX_SILHOUETTE_BUFFERS: u32 = 64;
/// Label-propagation rounds recorded per frame; rounds after the labels settle dispatch nothing.
pub const MAX_LABEL_ROUNDS: u32 = 16;
/// Format of the shadow volumes' depth-stencil target.
pub const STENCIL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24PlusStencil8;
/// Format of the silhouette buffer's seven parameter targets: full-precision floats (the paper packed 8 bits).
pub const SILHOUETTE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the eighth target, the count of wedge fragments shaded.
pub const SHADED_COUNT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Format of the umbra mask (1 where the stencil count is not zero).
pub const UMBRA_MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;
/// Targets of the silhouette buffer: areas, four rectangles, two pairs of inner maxima (the paper's
/// seven parameters per radial part, Sec. 4.3, in seven Rgba32Float targets), and the count of fragments shaded.
pub const SILHOUETTE_TARGETS: usize = 8;
/// Bytes per pixel of the silhouette buffer's targets.
const SILHOUETTE_BYTES: u32 = 7 * 16 + 4;
/// Bytes of one silhouette half-edge with its wedge (`WedgeRecord`).
pub const WEDGE_RECORD_BYTES: u64 = 96;
/// Threads per compute workgroup (`WORKGROUP`).
const WORKGROUP: u32 = 256;
/// u32s of the counters (`Counters`): eight scalars and seven arrays of [`MAX_SILHOUETTE_BUFFERS`].
const COUNTER_WORDS: u64 = 8 + 7 * MAX_SILHOUETTE_BUFFERS as u64;
/// The u32 where `Counters.stencil_levels` starts: after the eight scalars and six arrays.
const STENCIL_LEVELS_WORD: usize = 8 + 6 * MAX_SILHOUETTE_BUFFERS as usize;
/// Stencil levels: the count is 8 bits, wrapping (a point in 256 volumes of one buffer reads 0).
const STENCIL_LEVELS: u32 = 256;
/// u32s of the indirect arguments: two dispatches, then per group four draws.
const INDIRECT_WORDS: u64 = 8 + 16 * MAX_SILHOUETTE_BUFFERS as u64;
/// Radial parts of the light (Sec. 3.1, Fig. 6): the final buffer has one rectangle buffer per part.
const RADIAL_PARTS: usize = 4;

/// How the silhouette buffers' occlusions combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum Blending {
    /// Summed. Within a buffer every silhouette is summed, as the plain penumbra wedges sum (one
    /// stencil test, every wedge's area added or subtracted); the buffers, each clamped to the
    /// light, are then added. With `silhouette_buffers = 1` this is Akenine-Möller and
    /// Assarsson's plain penumbra wedges, the paper's baseline (Forest et al., Figs. 1(a), 2(a));
    /// with more buffers it is a per-buffer sum, not a published method.
    None,
    /// Forest et al.'s blending of overlapping penumbrae (Sec. 3.2).
    Forest,
}

/// Settings of [`PenumbraWedges`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct WedgesSettings {
    /// How the silhouette buffers' occlusions combine: none (summed; with silhouette_buffers=1 the plain penumbra wedges of Akenine-Möller and Assarsson, the paper's baseline; with more, each buffer clamped, then added) or forest (Forest et al.'s blending, Sec. 3.2).
    #[param(choice, default = "forest")]
    pub blending: Blending,
    /// Silhouette buffers: the silhouette regions, ranked by their first face, go round-robin to this many buffers, each one shadow-volume, wedge and blend pass; regions sharing a buffer are summed (the paper: one buffer per silhouette; 1 with blending=none: the plain penumbra wedges).
    #[param(default = 16, min = 1, max = MAX_SILHOUETTE_BUFFERS)]
    pub silhouette_buffers: u32,
}

/// The technique's parameters as the shaders read them (`WedgesSettings` in `shaders/wedges/wedges_common.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct WedgesSettingsUniform {
    blending: u32,
    silhouette_buffers: u32,
    _pad0: u32,
    _pad1: u32,
    near_fraction: f32,
    plane_tolerance: f32,
    depth_bias: f32,
    _pad2: f32,
}

/// Depth in front of the light's plane where silhouette edges are clipped, as a fraction of the scene's diagonal.
const NEAR_FRACTION: f32 = 1e-6;
/// Slack of the bounding-plane rejection, a fraction of the scene's diagonal (it only lets more fragments through).
const PLANE_TOLERANCE: f32 = 1e-5;
/// Camera depth (NDC) the G-buffer's depth is moved by, to the surface's side facing the light, for the volumes: 16 units of 2^-24.
/// The wedges integrate at the point so moved along the view ray, where the stencil judged the umbra.
pub const DEPTH_BIAS: f32 = 16.0 / 16_777_216.0;

impl From<&WedgesSettings> for WedgesSettingsUniform {
    fn from(settings: &WedgesSettings) -> Self {
        Self {
            blending: match settings.blending {
                Blending::None => 0,
                Blending::Forest => 1,
            },
            silhouette_buffers: settings.silhouette_buffers.clamp(1, MAX_SILHOUETTE_BUFFERS),
            _pad0: 0,
            _pad1: 0,
            near_fraction: NEAR_FRACTION,
            plane_tolerance: PLANE_TOLERANCE,
            depth_bias: DEPTH_BIAS,
            _pad2: 0.0,
        }
    }
}

/// The casting mesh's sizes as the shaders read them (`WedgesMesh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct WedgesMeshUniform {
    face_count: u32,
    record_count: u32,
    half_edge_capacity: u32,
    rank_blocks: u32,
    width: u32,
    height: u32,
    _pad0: u32,
    _pad1: u32,
    bounds_min: [f32; 4],
    bounds_max: [f32; 4],
}

/// Margin of the scene's box that cuts the wedges, as a fraction of its diagonal: receivers on
/// its faces stay strictly inside.
const BOUNDS_MARGIN: f32 = 1e-3;

impl WedgesMeshUniform {
    fn new(mesh: &CastingMesh, (width, height): (u32, u32), bounds: &ssm_scene::Aabb) -> Self {
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

fn technique_error(message: impl Into<String>) -> Error {
    Error::Technique { technique: NAME.into(), message: message.into() }
}

/// A storage buffer labelled `label` holding `contents` (at least 16 bytes: wgpu refuses empty bindings).
fn storage_init<T: Pod>(device: &wgpu::Device, label: &str, contents: &[T], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let mut bytes = bytemuck::cast_slice::<T, u8>(contents).to_vec();
    bytes.resize(bytes.len().max(16), 0);
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: &bytes,
        usage: wgpu::BufferUsages::STORAGE | usage,
    })
}

/// An uninitialised storage buffer of `size` bytes (at least 16).
fn storage(device: &wgpu::Device, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16).next_multiple_of(4),
        usage: wgpu::BufferUsages::STORAGE | usage,
        mapped_at_creation: false,
    })
}

fn storage_entry(binding: u32, read_only: bool, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
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

/// The compute passes that find the silhouettes and fill the draw lists.
struct SilhouettePasses {
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

/// The casting mesh on the GPU, and everything drawn from it.
struct MeshPasses {
    silhouettes: SilhouettePasses,
    face_workgroups: u32,
    record_workgroups: u32,
    volume_group: wgpu::BindGroup,
    wedge_group: wgpu::BindGroup,
    side_pipeline: wgpu::RenderPipeline,
    cap_pipeline: wgpu::RenderPipeline,
    wedge_pipeline: wgpu::RenderPipeline,
    counters: wgpu::Buffer,
    half_edges: wgpu::Buffer,
    /// Per closed component, its winding number around the light's centre (cleared per light).
    winding: wgpu::Buffer,
    report: MeshReport,
}

/// Forest et al.'s penumbra-wedges blending (and, with `blending=none`, the plain penumbra wedges).
pub struct PenumbraWedges {
    settings: WedgesSettings,
    mesh: Option<MeshPasses>,
    indirect: wgpu::Buffer,
    depth_copy_pipeline: wgpu::RenderPipeline,
    depth_copy_group: wgpu::BindGroup,
    stencil_view: wgpu::TextureView,
    silhouette_views: Vec<wgpu::TextureView>,
    umbra_mask_view: wgpu::TextureView,
    umbra_mask_pipeline: wgpu::RenderPipeline,
    blend_pipeline: wgpu::ComputePipeline,
    blend_group: wgpu::BindGroup,
    gbuffer_group: wgpu::BindGroup,
    resolve: ScreenPass,
    /// The final buffer (Sec. 3.2): per pixel, the four radial parts' occluded areas ...
    final_areas: wgpu::Buffer,
    /// ... and each part's bounding rectangle, one buffer per part (16 bytes per pixel each, so
    /// that every binding stays under the storage binding limit: [`AllocationPlan`]).
    final_rectangles: [wgpu::Buffer; RADIAL_PARTS],
    fragment_counts: wgpu::Buffer,
    passes_issued: u32,
    pixels: u64,
    /// What the shaders count for `--count-work` ([`COUNTERS`]); enabled only then.
    read_counts: ReadCounts,
}

impl PenumbraWedges {
    /// Prepares the casting mesh (once: welding, records, the two-sided rule), uploads it, and builds every pipeline.
    ///
    /// # Errors
    /// A parameter or GPU error; [`Error::LimitTooLow`], before anything is allocated, when the
    /// device's limits cannot hold what [`AllocationPlan`] sizes for this view and mesh.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = WedgesSettings::from_params(setup.params)?;
        let gpu = setup.gpu;
        let device = &gpu.device;
        let (width, height) = (setup.scene.width, setup.scene.height);
        let pixels = u64::from(width) * u64::from(height);
        let gbuffer = setup.shared.gbuffer(NAME)?;
        // Everything is sized first and checked against the device's limits, before any allocation.
        let casting = CastingMesh::prepare(setup.shared.adjacency(NAME)?);
        let casting = (!casting.faces.is_empty()).then_some(casting);
        AllocationPlan::new(width, height, casting.as_ref()).check(&device.limits())?;
        let settings_buffer = uniform_buffer(device, "wedges_settings_uniform", &WedgesSettingsUniform::from(&settings));
        let counters = if casting.is_some() { COUNTERS } else { &COUNTERS[..COUNTERS_WITHOUT_MESH] };
        let read_counts = ReadCounts::with_units(device, "wedges_read_counts", counters, setup.count_work);

        let indirect = storage(device, "wedges_indirect_arguments", INDIRECT_WORDS * 4, wgpu::BufferUsages::INDIRECT);
        let final_size = pixels * FINAL_BINDING_BYTES_PER_PIXEL;
        let final_areas = storage(device, "wedges_final_areas", final_size, wgpu::BufferUsages::COPY_DST);
        let final_rectangles =
            [0, 1, 2, 3].map(|part| storage(device, &format!("wedges_final_rectangles_{part}"), final_size, wgpu::BufferUsages::COPY_DST));
        let fragment_counts =
            storage(device, "wedges_fragment_counts", pixels * 4, wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC);

        let stencil = render_texture(device, "wedges_stencil", width, height, STENCIL_FORMAT, wgpu::TextureUsages::empty());
        let stencil_view = labelled_view(&stencil, "wedges_stencil");
        let silhouette_views: Vec<wgpu::TextureView> = (0..SILHOUETTE_TARGETS)
            .map(|k| {
                let label = format!("wedges_silhouette_buffer_{k}");
                let format = if k + 1 == SILHOUETTE_TARGETS { SHADED_COUNT_FORMAT } else { SILHOUETTE_FORMAT };
                labelled_view(&render_texture(device, &label, width, height, format, wgpu::TextureUsages::empty()), &label)
            })
            .collect();

        let (depth_copy_pipeline, depth_copy_group) =
            depth_copy(gpu, gbuffer, (&settings_buffer, &setup.scene.camera_buffer), &read_counts)?;
        let umbra_mask = render_texture(device, "wedges_umbra_mask", width, height, UMBRA_MASK_FORMAT, wgpu::TextureUsages::empty());
        let umbra_mask_view = labelled_view(&umbra_mask, "wedges_umbra_mask");
        let blend_layout = blend_layout(device);
        let mut blend_resources: Vec<wgpu::BindingResource<'_>> = silhouette_views.iter().map(wgpu::BindingResource::TextureView).collect();
        blend_resources.push(final_areas.as_entire_binding());
        blend_resources.push(settings_buffer.as_entire_binding());
        blend_resources.push(wgpu::BindingResource::TextureView(&umbra_mask_view));
        blend_resources.push(fragment_counts.as_entire_binding());
        blend_resources.extend(final_rectangles.iter().map(wgpu::Buffer::as_entire_binding));
        blend_resources.push(read_counts.buffer().as_entire_binding());
        let blend_group = bind_group(device, "wedges_blend_bind_group", &blend_layout, &blend_resources);
        let blend_module = create_shader_with_imports(gpu, "wedges_blend_shader", BLEND_SHADER, LOCAL_SHADERS)?;
        let blend_pipeline = compute_pipeline(
            device,
            "wedges_blend_pipeline",
            &blend_module,
            "wedges_blend",
            &[gpu.uniform_layout(), gpu.gbuffer_layout(), &blend_layout],
            &read_counts.pipeline_constants(),
        );
        let umbra_mask_pipeline = umbra_mask_pipeline(gpu, &blend_module);
        let resolve = ScreenPass::new(
            setup,
            NAME,
            "wedges_resolve",
            (&blend_module, "wedges_resolve"),
            Some(&blend_layout),
            VISIBILITY_FORMAT.into(),
            &read_counts.pipeline_constants(),
        )?;

        let mesh = match &casting {
            Some(casting) => {
                let uniform = WedgesMeshUniform::new(casting, (width, height), &setup.scene.bounds);
                Some(MeshPasses::new(setup, casting, uniform, (&settings_buffer, &indirect, &read_counts))?)
            }
            None => None,
        };
        Ok(Self {
            settings,
            mesh,
            indirect,
            depth_copy_pipeline,
            depth_copy_group,
            stencil_view,
            silhouette_views,
            umbra_mask_view,
            umbra_mask_pipeline,
            blend_pipeline,
            blend_group,
            gbuffer_group: gbuffer.bind_group.clone(),
            resolve,
            final_areas,
            final_rectangles,
            fragment_counts,
            passes_issued: 0,
            pixels,
            read_counts,
        })
    }

    /// What the setup found in the casting mesh (`None` when nothing casts).
    #[must_use]
    pub fn mesh_report(&self) -> Option<MeshReport> {
        self.mesh.as_ref().map(|m| m.report)
    }
}

fn depth_copy(
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

fn blend_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let mut entries: Vec<wgpu::BindGroupLayoutEntry> = (0..SILHOUETTE_TARGETS as u32).map(texture_entry).collect();
    let areas = SILHOUETTE_TARGETS as u32;
    entries.push(storage_entry(areas, false, wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE));
    entries.push(uniform_entry(areas + 1));
    entries.push(texture_entry(areas + 2));
    entries.push(storage_entry(areas + 3, false, wgpu::ShaderStages::COMPUTE));
    entries.extend((0..RADIAL_PARTS as u32).map(|part| storage_entry(areas + 4 + part, false, wgpu::ShaderStages::COMPUTE)));
    entries.push(ReadCounts::layout_entry(areas + 4 + RADIAL_PARTS as u32));
    bind_group_layout(device, "wedges_blend_layout", &entries)
}

/// The umbra mask: 1 where this buffer's stencil count is not zero. Storage writes are not
/// gated by the stencil test (fragment tests run after a shader with side effects), colour writes are.
fn umbra_mask_pipeline(gpu: &GpuContext, module: &wgpu::ShaderModule) -> wgpu::RenderPipeline {
    let device = &gpu.device;
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("wedges_umbra_mask_pipeline_layout"),
        bind_group_layouts: &[Some(gpu.uniform_layout()), Some(gpu.gbuffer_layout())],
        immediate_size: 0,
    });
    let face = wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::NotEqual,
        fail_op: wgpu::StencilOperation::Keep,
        depth_fail_op: wgpu::StencilOperation::Keep,
        pass_op: wgpu::StencilOperation::Keep,
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("wedges_umbra_mask_pipeline"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState { module, entry_point: Some("fullscreen_vertex"), compilation_options: Default::default(), buffers: &[] },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: STENCIL_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: wgpu::StencilState { front: face, back: face, read_mask: 0xff, write_mask: 0 },
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("wedges_umbra_mask"),
            compilation_options: Default::default(),
            targets: &[Some(UMBRA_MASK_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl MeshPasses {
    fn new(
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
        let module = create_shader_with_imports(gpu, "wedges_silhouettes_shader", SILHOUETTES_SHADER, LOCAL_SHADERS)?;
        let light = gpu.uniform_layout();
        let plain = [light, &mesh_layout];
        let writes_arguments = [light, &mesh_layout, &indirect_layout];
        let constants = read_counts.pipeline_constants();
        let pipeline = |entry: &str, layouts: &[&wgpu::BindGroupLayout]| {
            compute_pipeline(device, &format!("{entry}_pipeline"), &module, entry, layouts, &constants)
        };
        let silhouettes = SilhouettePasses {
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
        };

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
        let volume_module = create_shader_with_imports(gpu, "wedges_volumes_shader", VOLUMES_SHADER, LOCAL_SHADERS)?;
        let side_pipeline = volume_pipeline(gpu, &volume_module, &volume_layout, "wedges_side_vertex");
        let cap_pipeline = volume_pipeline(gpu, &volume_module, &volume_layout, "wedges_cap_vertex");

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
        let wedge_pipeline = wedge_pipeline(gpu, &wedge_layout, (read_counts, setup.count_work))?;
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
fn wedge_pipeline(
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

/// Byte offset of group `group`'s draw arguments (sides 0, caps 1, wedges 2, blend 3).
fn draw_offset(group: u32, draw: u64) -> u64 {
    (8 + 16 * u64::from(group) + 4 * draw) * 4
}

impl MeshPasses {
    /// Every dispatch of the silhouette step, in one timed compute pass.
    fn encode_silhouettes(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup, indirect: &wgpu::Buffer) {
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
}

impl ShadowTechnique for PenumbraWedges {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let scene = frame.scene;
        let light_frame = scene.light_bind_groups.get(light).ok_or_else(|| technique_error(format!("no light {light}")))?;
        let point_light = scene.light_frames.get(light).is_some_and(|f| f.light.is_point());
        if light == 0 {
            self.passes_issued = 0;
        }
        self.read_counts.clear(frame, light);
        if let Some(mesh) = &self.mesh {
            mesh.encode_silhouettes(frame, light_frame, &self.indirect);
            self.passes_issued += 1;
        }
        {
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
            self.passes_issued += 1;
        }
        frame.clear_buffer("wedges_final_areas_clear", &self.final_areas, 0, None);
        for rectangles in &self.final_rectangles {
            frame.clear_buffer("wedges_final_rectangles_clear", rectangles, 0, None);
        }
        frame.clear_buffer("wedges_fragment_counts_clear", &self.fragment_counts, 0, None);
        if let Some(mesh) = &self.mesh {
            for group in 0..self.settings.silhouette_buffers.clamp(1, MAX_SILHOUETTE_BUFFERS) {
                self.encode_group(frame, mesh, (light_frame, group), point_light);
                self.passes_issued += 4;
            }
        }
        self.resolve.encode(frame, light, output, Some(&self.blend_group), None);
        self.passes_issued += 1;
        Ok(())
    }

    /// Per counting pass (`COUNTERS`): texel reads, atomics and bytes written to storage, as its
    /// shader counted them (`wedges_counts.wgsl`), when built for `--count-work`.
    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ShaderWork>>> {
        self.read_counts.work(gpu)
    }

    fn diagnostics(&mut self, gpu: &GpuContext) -> Vec<(String, f64)> {
        let mut out = vec![("passes".to_owned(), f64::from(self.passes_issued))];
        let Some(mesh) = &self.mesh else { return out };
        let word =
            |bytes: &[u8], index: usize| bytes.get(index * 4..index * 4 + 4).map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if let Ok(counters) = ssm_core::readback::read_buffer(gpu, &mesh.counters, COUNTER_WORDS * 4, "wedges counters") {
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
            if let Some(loops) = silhouette_loops(gpu, &mesh.half_edges, half_edges) {
                out.push(("silhouette_loops".to_owned(), loops as f64));
            }
        }
        if let Ok(counts) = ssm_core::readback::read_buffer(gpu, &self.fragment_counts, self.pixels * 4, "wedges fragment counts") {
            let total: u64 = counts.chunks_exact(4).map(|b| u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))).sum();
            out.push(("wedge_fragments".to_owned(), total as f64));
        }
        out
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

impl PenumbraWedges {
    /// One silhouette buffer: its shadow volumes, its wedges, and its blend into the final buffer.
    fn encode_group(&self, frame: &mut Frame<'_>, mesh: &MeshPasses, (light_frame, group): (&wgpu::BindGroup, u32), point_light: bool) {
        let camera = &frame.scene.camera_bind_group;
        {
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
        {
            let attachments: Vec<Option<wgpu::RenderPassColorAttachment<'_>>> =
                self.silhouette_views.iter().map(|view| color_attachment(view, Some(wgpu::Color::TRANSPARENT))).collect();
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
        {
            // The stencil count becomes a colour: one full-screen triangle through the stencil test.
            let mut pass = frame.render_pass(
                "wedges_shadow_volumes",
                &[color_attachment(&self.umbra_mask_view, Some(wgpu::Color::TRANSPARENT))],
                Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.stencil_view,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                    stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                }),
            );
            pass.set_pipeline(&self.umbra_mask_pipeline);
            pass.set_bind_group(0, light_frame, &[]);
            pass.set_bind_group(1, &self.gbuffer_group, &[]);
            pass.set_stencil_reference(0);
            pass.draw(0..3, 0..1);
        }
        let mut pass = frame.compute_pass("wedges_blend");
        pass.set_pipeline(&self.blend_pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        pass.set_bind_group(2, &self.blend_group, &[]);
        pass.dispatch_workgroups_indirect(&self.indirect, draw_offset(group, 3));
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(PenumbraWedges::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    WedgesSettings::from_params(params)?;
    Ok(Requirements {
        gbuffer: true,
        adjacency: true,
        // Additive and max blending into Rgba32Float; depth unclipped for the volumes at infinity.
        features: wgpu::Features::FLOAT32_BLENDABLE | wgpu::Features::DEPTH_CLIP_CONTROL,
        ..Requirements::NONE
    })
}

/// Fig. 12's scenes: cubes of 1 to 7 spheres a side (1 to 343 spheres) of the paper's 760
/// triangles, the built-in `sphere-cube` with parameters ([`scenes::sphere_cube_name`]).
pub const FIG12_SCENES: &[&str] = &[
    "sphere-cube:spheres=1,segments=20,rings=20",
    "sphere-cube:spheres=2,segments=20,rings=20",
    "sphere-cube:spheres=3,segments=20,rings=20",
    "sphere-cube:spheres=4,segments=20,rings=20",
    "sphere-cube:spheres=5,segments=20,rings=20",
    "sphere-cube:spheres=6,segments=20,rings=20",
    "sphere-cube:spheres=7,segments=20,rings=20",
];

/// Atty et al.'s Fig. 25: the same cubes from 8 spheres.
pub const FIG25_SCENES: &[&str] = &[
    "sphere-cube:spheres=2,segments=20,rings=20",
    "sphere-cube:spheres=3,segments=20,rings=20",
    "sphere-cube:spheres=4,segments=20,rings=20",
    "sphere-cube:spheres=5,segments=20,rings=20",
    "sphere-cube:spheres=6,segments=20,rings=20",
    "sphere-cube:spheres=7,segments=20,rings=20",
];

/// Forest et al.'s evaluations, as sweeps.
const PRESETS: &[Preset] = &[
    Preset {
        name: "wedges-fig1",
        summary: "Forest et al., Figs. 1 and 2: the plain penumbra wedges (blending=none, one silhouette buffer) against the blending (forest, 16 buffers), on sphere-cube; read mae_penumbra and mean_signed_error in sweep.csv",
        scenes: &["sphere-cube"],
        varies: &["wedges.blending:silhouette_buffers=none:1,forest:16"],
        ..Preset::DEFAULT
    },
    Preset {
        name: "wedges-buffers",
        summary: "penumbra error against the number of silhouette buffers (1 = every silhouette summed within one buffer, the blend between buffers only), on sphere-cube",
        scenes: &["sphere-cube"],
        varies: &["wedges.silhouette_buffers=1,2,4,8,16,32,64"],
        x_axis: "wedges.silhouette_buffers",
        ..Preset::DEFAULT
    },
    Preset {
        name: "wedges-fig12",
        summary: "Forest et al., Fig. 12: frame time of the plain penumbra wedges (blending=none, one silhouette buffer) and of the blending (forest, 16 buffers); one scene per sphere count (the crate's fig12 example sweeps them all and plots time against triangles). In counted work (--count-work): the same wedge fragments, and per buffer a blend thread per pixel, a full-screen umbra mask and the silhouette targets written back",
        scenes: FIG12_SCENES,
        varies: &["wedges.blending:silhouette_buffers=none:1,forest:16"],
        y_axis: "time",
        ..Preset::DEFAULT
    },
    Preset {
        name: "wedges-atty-fig25",
        summary: "Atty et al., Fig. 25: soft shadow volumes (wedges, forest) against soft shadow maps (atty two-sided, 210² occluder map) as polygons grow; one scene per sphere count, time against error (the fig12 example sweeps them all)",
        scenes: FIG25_SCENES,
        varies: &["wedges.blending=forest", "atty.two_sided=true", "atty.occluder_map_size=210"],
        ..Preset::DEFAULT
    },
];

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "penumbra wedges (soft shadow volumes) with GPU silhouettes and z-fail umbra; blending=forest blends overlapping penumbrae, blending=none silhouette_buffers=1 is the plain penumbra wedges",
    paper: "Forest, Barthe and Paulin 2006, Realistic soft shadows by penumbra-wedges blending (Graphics Hardware); Akenine-Möller and Assarsson 2002; Assarsson and Akenine-Möller 2003",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Hemisphere,
    params: WedgesSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("silhouette_buffers=1,4,16,64"),
    debug_outputs: &[],
    uniforms: &[
        UniformCheck {
            wgsl_struct: "WedgesSettings",
            wgsl_source: SILHOUETTES_SHADER,
            imports: LOCAL_SHADERS,
            rust: WedgesSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: "WedgesMesh",
            wgsl_source: SILHOUETTES_SHADER,
            imports: LOCAL_SHADERS,
            rust: WedgesMeshUniform::LAYOUT,
        },
    ],
    limits: &[],
    paper_configuration: ssm_core::PaperConfiguration::DEFAULTS,
};

register_technique!(INFO);

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn requirements_declare_adjacency_and_the_features_used() {
        let needs = requirements(&INFO.default_params()).unwrap();
        assert!(needs.adjacency && needs.gbuffer && !needs.roles);
        assert!(needs.features.contains(wgpu::Features::FLOAT32_BLENDABLE | wgpu::Features::DEPTH_CLIP_CONTROL));
    }

    #[test]
    fn the_settings_uniform_carries_the_blending() {
        let mut params = INFO.default_params();
        assert_eq!(WedgesSettingsUniform::from(&WedgesSettings::from_params(&params).unwrap()).blending, 1);
        params.set("blending", "none").unwrap();
        params.set("silhouette_buffers", "3").unwrap();
        let uniform = WedgesSettingsUniform::from(&WedgesSettings::from_params(&params).unwrap());
        assert_eq!((uniform.blending, uniform.silhouette_buffers), (0, 3));
        assert!(params.set("blending", "probabilistic").is_err());
    }

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
