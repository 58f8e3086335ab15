//! Atty, Holzschuch, Lapierre, Hasenfratz, Hansen and Sillion, *Soft Shadow
//! Maps: Efficient Sampling of Light Source Visibility*, Computer Graphics
//! Forum 25(4), 2006.
//!
//! The occluders, seen from the light's centre, become one micro-patch per
//! occluder-map texel, parallel to the light at that texel's depth (Sec. 3.2).
//! Each patch's penumbra extent is a pyramid whose section on the soft shadow
//! map (SSM) is an axis-aligned rectangle (Sec. 3.3); for every SSM texel in
//! it, the patch is projected back onto the light from the receiver there, and
//! the hidden fraction, a product of two clamped 1-D overlaps, is added into a
//! float map by blending (Sec. 3.4, 4.2). The SSM is then projected onto the
//! receivers. The two-sided variant does this for the nearest front faces and
//! the farthest back faces and keeps the larger occlusion (Sec. 3.5).
//!
//! Unlike the paper, nothing goes back to the CPU: a compute pass lists the
//! micro-patches and an indirect instanced draw accumulates them (the paper's
//! stated next step, Sec. 4.3 and 7), so the cost no longer grows with a
//! readback. Neighbouring texels at one depth are listed as one patch (their
//! back-projections join exactly, Sec. 5.1.2). And, where the paper separates
//! occluders from receivers (Sec. 1, 7), a surface in both maps is kept from
//! shadowing itself through its own micro-patches: the receiver map carries
//! each receiver's tangent plane, and a patch on or behind it hides nothing
//! (`receiver_plane`, on by default).
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique atty --set
//! atty.occluder_map_size=128 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_atty::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_atty::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("atty")?;
//! let params = info.params_from([("occluder_map_size", "128")])?;
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

pub mod geometry;

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{
    bind_group, bind_group_layout, color_attachment, compute_pipeline, labelled_view, render_texture, storage_entry, texture_entry,
    uniform_buffer, uniform_entry, write_storage_texture_entry,
};
use ssm_core::read_counts::{READ_COUNT_BUCKETS, ReadCounts};
use ssm_core::shader::create_shader_with_imports;
use ssm_core::work::ShaderWork;
use ssm_core::{
    Choice, Error, Frame, Geometry, GpuContext, LightDepthMap, LightDepthMapDesc, ParamValues, Requirements, Result, ScreenPass, Settings,
    ShadowMapBias, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct, VISIBILITY_FORMAT,
    register_technique,
};

/// The registered name.
pub const NAME: &str = "atty";

/// The micro-patch geometry the list pass and the accumulation evaluate, twin of [`geometry`].
pub const GEOMETRY_SHADER: &str = ssm_shaders::atty::ATTY_GEOMETRY;
/// WGSL files the Atty shaders import besides `common/`, as `(path under shaders/, text)`.
pub const LOCAL_SHADERS: &[(&str, &str)] = &[
    ("atty/atty_settings.wgsl", ssm_shaders::atty::ATTY_SETTINGS),
    ("atty/atty_geometry.wgsl", GEOMETRY_SHADER),
    ("atty/atty_counts.wgsl", ssm_shaders::atty::ATTY_COUNTS),
];
/// The accumulation of micro-patches into the SSM.
const ACCUMULATE_SHADER: &str = ssm_shaders::atty::ATTY_ACCUMULATE;
/// The projection of the SSM onto the screen.
const PROJECT_SHADER: &str = ssm_shaders::atty::ATTY_PROJECT;
/// The micro-patch list the accumulation draws.
const PATCHES_SHADER: &str = ssm_shaders::atty::ATTY_PATCHES;
/// Bytes of one micro-patch record (`MicroPatchRecord` in `atty_settings.wgsl`).
const PATCH_RECORD_BYTES: u64 = 32;
/// The receiver map's max-pyramid.
const RECEIVER_BOUNDS_SHADER: &str = ssm_shaders::atty::ATTY_RECEIVER_BOUNDS;
/// The receivers' tangent planes, measured from the receiver map.
const RECEIVER_PLANES_SHADER: &str = ssm_shaders::atty::ATTY_RECEIVER_PLANES;
/// An occluder map's min-max pyramid.
const PATCH_MERGE_SHADER: &str = ssm_shaders::atty::ATTY_PATCH_MERGE;

/// An occluder map's depth range per block.
const PATCH_MERGE: PyramidKind = PyramidKind {
    label: "atty_patch_merge",
    format: wgpu::TextureFormat::Rg32Float,
    shader: PATCH_MERGE_SHADER,
    base: "atty_merge_base",
    reduce: "atty_merge_reduce",
};

/// What bounds each micro-patch's penumbra rectangle on the soft shadow map (the same SSM either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum PenumbraBound {
    /// The frame's far plane, conservative for every receiver (the straightforward bound).
    FarPlane,
    /// The deepest receiver under the rectangle, from a max-pyramid of the receiver map: smaller
    /// rectangles, and no quad at all for a patch with no receiver behind it.
    Receivers,
}

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

/// Settings of [`SoftShadowMaps`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct AttySettings {
    /// Side of the occluder map, texels: one micro-patch per texel (cost grows with its square).
    #[param(default = 256, min = 32, max = 2048)]
    pub occluder_map_size: u32,
    /// Side of the soft shadow map and of the receiver map, texels.
    #[param(default = 512, min = 32, max = 4096)]
    pub ssm_size: u32,
    /// Also discretise the farthest back faces and keep the larger occlusion (Sec. 3.5; about twice the cost).
    #[param(default = false)]
    pub two_sided: bool,
    /// Format of the soft shadow map the patches are summed into: f32 (needs FLOAT32_BLENDABLE) or f16 (the paper's hardware; see Appendix A).
    #[param(choice, default = "f32")]
    pub accumulation: Accumulation,
    /// Projection lookup point moved off the surface along its normal, in receiver-map texels.
    #[param(default = 0.5, min = 0.0, max = 8.0)]
    pub normal_offset: f32,
    /// Receiver-map depths within this many texel footprints (world size of one receiver-map texel at the depth looked up) of a receiver count as that receiver: the SSM's bilinear lookup blends only those, and (without `receiver_plane`) a point farther behind is hidden (in umbra). With `receiver_plane` it is measured from each texel's plane along the point's own ray.
    #[param(default = 2.0, min = 0.0, max = 64.0)]
    pub receiver_tolerance: f32,
    /// A micro-patch less than this many of its widths in front of a receiver hides nothing: without `receiver_plane`, removes the moiré of objects with role `both` shadowing themselves, but also the shadow of an occluder that close to a receiver (0: the paper).
    #[param(default = 0.0, min = 0.0, max = 16.0)]
    pub self_shadow_tolerance: f32,
    /// What bounds each micro-patch's penumbra rectangle: the far plane, or the deepest receiver under it (same result; fewer accumulation fragments, for a pyramid pass whose texel reads exceed what they save).
    #[param(choice, default = "far_plane")]
    pub penumbra_bound: PenumbraBound,
    /// Aligned blocks of occluder texels whose depths differ by at most this many micro-patch widths are drawn as one micro-patch (Sec. 5.1.2: neighbours at one depth join exactly; 0: one patch per texel).
    #[param(default = 0.01, min = 0.0, max = 16.0)]
    pub merge_tolerance: f32,
    /// A micro-patch on or behind a receiver's tangent plane (the receiver map carries each texel's, from its triangle) hides nothing from it, so a surface in both maps does not shadow itself through its own micro-patches; and the projection finds each point's own receiver by its plane (false: the receiver's depth alone decides, the paper).
    #[param(default = true)]
    pub receiver_plane: bool,
    /// With `receiver_plane`: a micro-patch less than this many of its widths (one texel's) in front of a receiver's tangent plane, beyond its own surface's depth spread across the patch, counts as lying on it (a margin for rounding).
    #[param(default = 0.05, min = 0.0, max = 16.0)]
    pub receiver_plane_tolerance: f32,
}

/// The settings uniform both Atty shaders read (`AttySettings` in `shaders/atty/atty_settings.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct AttySettingsUniform {
    occluder_map_size: f32,
    soft_shadow_map_size: f32,
    normal_offset: f32,
    receiver_tolerance: f32,
    self_shadow_tolerance: f32,
    receiver_bias: f32,
    receiver_bounded: f32,
    merge_tolerance: f32,
    receiver_plane: f32,
    receiver_plane_tolerance: f32,
    _pad: [f32; 2],
}

impl From<&AttySettings> for AttySettingsUniform {
    fn from(settings: &AttySettings) -> Self {
        Self {
            occluder_map_size: settings.occluder_map_size as f32,
            soft_shadow_map_size: settings.ssm_size as f32,
            normal_offset: settings.normal_offset,
            receiver_tolerance: settings.receiver_tolerance,
            self_shadow_tolerance: settings.self_shadow_tolerance,
            // The baselines' default constant bias, a fraction of the scene's diagonal.
            receiver_bias: ShadowMapBias::default().constant_bias,
            receiver_bounded: if settings.penumbra_bound == PenumbraBound::Receivers { 1.0 } else { 0.0 },
            merge_tolerance: settings.merge_tolerance,
            receiver_plane: if settings.receiver_plane { 1.0 } else { 0.0 },
            receiver_plane_tolerance: settings.receiver_plane_tolerance,
            _pad: [0.0; 2],
        }
    }
}

/// One occluder side's maps and passes, by name (every pass label a counter can carry is static).
struct Side {
    /// The occluder map.
    occluder_map: &'static str,
    /// The occluder map's min-max pyramid pass.
    patch_merge: &'static str,
    /// The micro-patch list pass.
    patches: &'static str,
    /// The accumulation pass, and the soft shadow map's label stem.
    accumulate: &'static str,
    /// The faces culled from the occluder map, and whether it keeps the farthest surface.
    cull: Option<wgpu::Face>,
    farthest: bool,
}

/// One-sided: the nearest surface of every occluder face.
const ONE_SIDED: &[Side] = &[Side {
    occluder_map: "atty_occluder_map",
    patch_merge: "atty_patch_merge",
    patches: "atty_accumulate_patches",
    accumulate: "atty_accumulate",
    cull: None,
    farthest: false,
}];

/// Two-sided (Sec. 3.5): the nearest front faces and the farthest back faces.
const TWO_SIDED: &[Side] = &[
    Side {
        occluder_map: "atty_occluder_map_front",
        patch_merge: "atty_patch_merge",
        patches: "atty_accumulate_front_patches",
        accumulate: "atty_accumulate_front",
        cull: Some(wgpu::Face::Back),
        farthest: false,
    },
    Side {
        occluder_map: "atty_occluder_map_back",
        patch_merge: "atty_patch_merge_back",
        patches: "atty_accumulate_back_patches",
        accumulate: "atty_accumulate_back",
        cull: Some(wgpu::Face::Front),
        farthest: true,
    },
];

/// Bytes of one [`ReadCounts`] counter: [`READ_COUNT_BUCKETS`] (invocations, amount) pairs of u32.
/// A multiple of 256, the largest `min_storage_buffer_offset_alignment` WebGPU allows, so every
/// counter can start a binding.
const COUNTER_BYTES: u64 = READ_COUNT_BUCKETS as u64 * 8;

/// The counters of `--count-work` (issue #40; [`TechniqueSetup::count_work`]), one slice of
/// consecutive counters per pass that counts, each bound to its pass's shader as its own
/// `read_counts` (`atty_counts.wgsl`): the list pass and the accumulation run once per side with
/// one pipeline, and the pyramids share their shaders, so a slice, not an index, tells them apart.
/// Only the passes that run have counters (a counter of a pass never recorded would be work of a
/// pass that did not run).
struct CounterPlan {
    counters: Vec<(&'static str, &'static str)>,
    /// The receiver map's max-pyramid: reads, their bytes, storage bytes (when it runs).
    receiver_bounds: Option<u32>,
    /// Per side: its occluder map's min-max pyramid (reads, their bytes, storage bytes; when
    /// merging), its list pass (reads, their bytes, atomics, storage bytes) and its accumulation
    /// (reads, their bytes).
    sides: Vec<SideCounters>,
    /// The projection: reads, their bytes.
    project: u32,
}

/// The first counter of each of one side's counting passes ([`CounterPlan`]).
struct SideCounters {
    patch_merge: Option<u32>,
    patches: u32,
    accumulate: u32,
}

/// Counters of a pyramid pass, a list pass and an accumulation or projection pass, in their
/// shaders' order: every pass that counts its texel reads counts the bytes they fetched beside
/// them (each read its texture's texel size, from the formats: [`texel_bytes`]).
const PYRAMID_UNITS: &[&str] = &["reads", "read_bytes", "storage_bytes"];
const PATCHES_UNITS: &[&str] = &["reads", "read_bytes", "atomics", "storage_bytes"];
const READS: &[&str] = &["reads", "read_bytes"];

/// Bytes of one texel of `format`: what a read of it fetches, as the shaders count it (their
/// `*_TEXEL_BYTES` overrides, set from the textures' formats since the receiver map and the soft
/// shadow maps change format with the settings).
fn texel_bytes(format: wgpu::TextureFormat) -> f64 {
    f64::from(format.block_copy_size(None).unwrap_or(0))
}

impl CounterPlan {
    fn new(settings: &AttySettings, sides: &[Side]) -> Self {
        let mut counters = Vec::new();
        let mut add = |pass: &'static str, units: &[&'static str]| {
            let first = counters.len() as u32;
            counters.extend(units.iter().map(|unit| (pass, *unit)));
            first
        };
        let receiver_bounds = (settings.penumbra_bound == PenumbraBound::Receivers).then(|| add(RECEIVER_BOUNDS.label, PYRAMID_UNITS));
        let sides = sides
            .iter()
            .map(|side| SideCounters {
                patch_merge: (settings.merge_tolerance > 0.0).then(|| add(side.patch_merge, PYRAMID_UNITS)),
                patches: add(side.patches, PATCHES_UNITS),
                accumulate: add(side.accumulate, READS),
            })
            .collect();
        let project = add(PROJECT_LABEL, READS);
        Self { counters, receiver_bounds, sides, project }
    }
}

/// `count` counters of `read_counts` from counter `first`, as one binding.
fn counter_slice(read_counts: &ReadCounts, first: u32, count: usize) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer: read_counts.buffer(),
        offset: u64::from(first) * COUNTER_BYTES,
        size: wgpu::BufferSize::new(count as u64 * COUNTER_BYTES),
    })
}

/// The projection pass's label.
const PROJECT_LABEL: &str = "atty_project";

/// One soft shadow map and the pass that fills it from one occluder map.
struct SideAccumulation {
    occluder_map: LightDepthMap,
    /// The indirect draw's arguments: 4 vertices, then the patch count the list pass counts up.
    draw_arguments: wgpu::Buffer,
    /// The list pass's bind group (occluder map, settings, pyramids, patch list, draw arguments).
    patches_group: wgpu::BindGroup,
    /// The list pass's name, `<label>_patches`.
    patches_label: &'static str,
    /// The occluder map's depth range per block, when micro-patches merge.
    patch_merge: Option<DepthPyramid>,
    soft_shadow_map: wgpu::TextureView,
    bind_group: wgpu::BindGroup,
    label: &'static str,
}

/// A pyramid of depth bounds over a light map: the receiver map's largest depth per block
/// (`atty_receiver_bounds.wgsl`, bounding the penumbra rectangles) or an occluder map's depth
/// range per block (`atty_patch_merge.wgsl`, merging micro-patches). Level 0 is built from the
/// map by the shader's `base` entry point, each level above from the one below by `reduce`.
struct DepthPyramid {
    /// Every level, for the accumulation's vertex stage.
    view: wgpu::TextureView,
    base: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
    /// Per level: its bind group (the level below, or the map, and this level) and size.
    levels: Vec<(wgpu::BindGroup, u32)>,
    label: &'static str,
}

/// What a [`DepthPyramid`] holds and how it is built.
struct PyramidKind {
    label: &'static str,
    format: wgpu::TextureFormat,
    shader: &'static str,
    base: &'static str,
    reduce: &'static str,
}

/// The receiver map's largest depth per block.
const RECEIVER_BOUNDS: PyramidKind = PyramidKind {
    label: "atty_receiver_bounds",
    format: wgpu::TextureFormat::R32Float,
    shader: RECEIVER_BOUNDS_SHADER,
    base: "atty_bounds_base",
    reduce: "atty_bounds_reduce",
};

impl DepthPyramid {
    /// The pyramid of `kind` over `map` (of format `map_format`), `size`² texels at level 0 (1
    /// where it is bound but not read), counting into `counts` (its slice of `read_counts`: reads,
    /// their bytes, storage bytes).
    fn new(
        setup: &TechniqueSetup<'_>,
        (kind, label): (&PyramidKind, &'static str),
        (map, map_format): (&wgpu::TextureView, wgpu::TextureFormat),
        size: u32,
        (read_counts, counts): (&ReadCounts, wgpu::BindingResource<'_>),
    ) -> Result<Self> {
        let device = &setup.gpu.device;
        let level_count = u32::BITS - size.leading_zeros();
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
            mip_level_count: level_count,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: kind.format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
            view_formats: &[],
        });
        let layout = bind_group_layout(
            device,
            &format!("{}_layout", kind.label),
            &[texture_entry(0), write_storage_texture_entry(1, kind.format), ReadCounts::layout_entry(2)],
        );
        let views: Vec<wgpu::TextureView> = (0..level_count)
            .map(|level| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some(&format!("{label}_level_{level}_view")),
                    base_mip_level: level,
                    mip_level_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let levels = views
            .iter()
            .enumerate()
            .map(|(level, view)| {
                let finer = if level == 0 { map } else { &views[level - 1] };
                let group = bind_group(
                    device,
                    &format!("{label}_level_{level}_bind_group"),
                    &layout,
                    &[wgpu::BindingResource::TextureView(finer), wgpu::BindingResource::TextureView(view), counts.clone()],
                );
                (group, (size >> level).max(1))
            })
            .collect();
        let module = create_shader_with_imports(setup.gpu, &format!("{}_shader", kind.label), kind.shader, LOCAL_SHADERS)?;
        // The bytes a texel read fetches: level 0 reads the map, each level above the one below.
        let [count_reads] = read_counts.pipeline_constants();
        let constants = [count_reads, ("MAP_TEXEL_BYTES", texel_bytes(map_format)), ("PYRAMID_TEXEL_BYTES", texel_bytes(kind.format))];
        let base = compute_pipeline(device, &format!("{}_pipeline", kind.base), &module, kind.base, &[&layout], &constants);
        let reduce = compute_pipeline(device, &format!("{}_pipeline", kind.reduce), &module, kind.reduce, &[&layout], &constants);
        let messages = setup.gpu.take_errors();
        if !messages.is_empty() {
            return Err(Error::Gpu { during: format!("building Atty's {label}"), messages });
        }
        let view = texture.create_view(&wgpu::TextureViewDescriptor { label: Some(&format!("{label}_view")), ..Default::default() });
        Ok(Self { view, base, reduce, levels, label })
    }

    /// Builds the pyramid from its map just rendered, in one timed compute pass.
    fn encode(&self, frame: &mut Frame<'_>) {
        let mut pass = frame.compute_pass(self.label);
        for (level, (group, size)) in self.levels.iter().enumerate() {
            pass.set_pipeline(if level == 0 { &self.base } else { &self.reduce });
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(size.div_ceil(8), size.div_ceil(8), 1);
        }
    }
}

/// The receiver map: per texel of the light frame, the nearest receiver's linear depth (`.x`),
/// read by the accumulation, the penumbra bounds and the projection.
enum ReceiverMap {
    /// The depth alone (ssm-core's light depth map, no bias): without `receiver_plane`, the paper.
    Depth(LightDepthMap),
    /// The depth and the slope of the receiver's plane (`atty_receiver_planes.wgsl`).
    Planes(ReceiverPlaneMap),
}

impl ReceiverMap {
    /// The pass's name, timed.
    const LABEL: &'static str = "atty_receiver_map";

    fn new(setup: &TechniqueSetup<'_>, settings: &AttySettings, settings_buffer: &wgpu::Buffer) -> Result<Self> {
        if settings.receiver_plane {
            Ok(Self::Planes(ReceiverPlaneMap::new(setup, settings.ssm_size, settings_buffer)?))
        } else {
            Ok(Self::Depth(unbiased_depth_map(setup, Self::LABEL, settings.ssm_size, Geometry::Receivers, (None, false))?))
        }
    }

    fn view(&self) -> &wgpu::TextureView {
        match self {
            Self::Depth(map) => &map.linear_depth_view,
            Self::Planes(map) => &map.view,
        }
    }

    /// The format of [`ReceiverMap::view`]'s texture.
    const fn format(&self) -> wgpu::TextureFormat {
        match self {
            Self::Depth(_) => LightDepthMap::FORMAT,
            Self::Planes(_) => ReceiverPlaneMap::FORMAT,
        }
    }

    /// Records the pass through `light_frame`, a light's frame bind group.
    fn encode(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup) {
        match self {
            Self::Depth(map) => map.encode_with(frame, light_frame),
            Self::Planes(map) => map.encode(frame, light_frame),
        }
    }
}

/// The receivers seen from the light's centre with their tangent planes: `(depth, slope.x,
/// slope.y, 0)` per texel (`atty_receiver_planes.wgsl`), the slope read from the fragment's own
/// triangle.
struct ReceiverPlaneMap {
    view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    pipeline: wgpu::RenderPipeline,
    settings_group: wgpu::BindGroup,
    indices: std::ops::Range<u32>,
}

impl ReceiverPlaneMap {
    const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

    fn new(setup: &TechniqueSetup<'_>, size: u32, settings_buffer: &wgpu::Buffer) -> Result<Self> {
        let gpu = setup.gpu;
        let device = &gpu.device;
        let label = ReceiverMap::LABEL;
        let indices = setup.scene.index_range(NAME, Geometry::Receivers)?;
        let texture = render_texture(device, &format!("{label}_planes"), size, size, Self::FORMAT, wgpu::TextureUsages::empty());
        let depth =
            render_texture(device, &format!("{label}_depth"), size, size, LightDepthMap::DEPTH_FORMAT, wgpu::TextureUsages::empty());
        let settings_group =
            bind_group(device, &format!("{label}_settings_bind_group"), gpu.uniform_layout(), &[settings_buffer.as_entire_binding()]);
        let module = create_shader_with_imports(gpu, &format!("{label}_shader"), RECEIVER_PLANES_SHADER, LOCAL_SHADERS)?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label}_pipeline_layout")),
            bind_group_layouts: &[Some(gpu.uniform_layout()), Some(gpu.uniform_layout())],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(&format!("{label}_pipeline")),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("atty_receiver_vertex"),
                compilation_options: Default::default(),
                buffers: &[Some(ssm_core::SceneVertex::layout())],
            },
            // Both sides of every receiver, as the plain receiver map.
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(LightDepthMap::depth_test(false)),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("atty_receiver_fragment"),
                compilation_options: Default::default(),
                targets: &[Some(Self::FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let messages = gpu.take_errors();
        if !messages.is_empty() {
            return Err(Error::Gpu { during: "building Atty's receiver-plane map".into(), messages });
        }
        Ok(Self {
            view: labelled_view(&texture, &format!("{label}_planes")),
            depth_view: labelled_view(&depth, &format!("{label}_depth")),
            pipeline,
            settings_group,
            indices,
        })
    }

    fn encode(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup) {
        let scene = frame.scene;
        let no_surface = f64::from(ssm_core::NO_SURFACE);
        let mut pass = frame.render_pass(
            ReceiverMap::LABEL,
            &[color_attachment(&self.view, Some(wgpu::Color { r: no_surface, g: 0.0, b: 0.0, a: 0.0 }))],
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.settings_group, &[]);
        scene.draw(&mut pass, self.indices.clone());
    }
}

/// Atty et al.'s soft shadow maps.
pub struct SoftShadowMaps {
    receiver_map: ReceiverMap,
    /// The receiver map's max-pyramid, when it bounds the penumbra rectangles.
    receiver_bounds: Option<DepthPyramid>,
    /// Front faces (or every face, one-sided), then back faces when two-sided.
    accumulations: Vec<SideAccumulation>,
    accumulate_pipeline: wgpu::RenderPipeline,
    patches_pipeline: wgpu::ComputePipeline,
    /// Occluder-map side, texels: the list pass runs one invocation per texel.
    occluder_map_size: u32,
    project: ScreenPass,
    project_group: wgpu::BindGroup,
    /// What the shaders count for `--count-work` ([`CounterPlan`]); enabled only then.
    read_counts: ReadCounts,
}

/// A linear depth map of the occluders or receivers, without bias: micro-patches and receivers sit at their true depths.
fn unbiased_depth_map(
    setup: &TechniqueSetup<'_>,
    label: &str,
    size: u32,
    geometry: Geometry,
    (cull_mode, farthest): (Option<wgpu::Face>, bool),
) -> Result<LightDepthMap> {
    LightDepthMap::new(
        setup.gpu,
        setup.scene,
        &LightDepthMapDesc { label, width: size, height: size, geometry, cull_mode, farthest, constant_bias: 0.0, slope_bias: 0.0 },
    )
}

impl SoftShadowMaps {
    /// Builds the maps and pipelines.
    ///
    /// # Errors
    /// A parameter or GPU error, or [`Error::Unrepresentable`] when the receivers are too small in the light's frame.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = AttySettings::from_params(setup.params)?;
        check_receivers_resolved(setup, settings.ssm_size)?;
        let settings_buffer = uniform_buffer(&setup.gpu.device, "atty_settings_uniform", &AttySettingsUniform::from(&settings));
        let receiver_map = ReceiverMap::new(setup, &settings, &settings_buffer)?;
        let bounded = settings.penumbra_bound == PenumbraBound::Receivers;
        let sides = if settings.two_sided { TWO_SIDED } else { ONE_SIDED };
        let plan = CounterPlan::new(&settings, sides);
        let read_counts = ReadCounts::with_units(&setup.gpu.device, "atty_read_counts", &plan.counters, setup.count_work);
        // Unbounded, the accumulation still binds a pyramid, of one texel, that it never reads (nor
        // builds: its counter slice is the first counters, never written by it).
        let receiver_bounds = DepthPyramid::new(
            setup,
            (&RECEIVER_BOUNDS, RECEIVER_BOUNDS.label),
            (receiver_map.view(), receiver_map.format()),
            if bounded { settings.ssm_size } else { 1 },
            (&read_counts, counter_slice(&read_counts, plan.receiver_bounds.unwrap_or(0), PYRAMID_UNITS.len())),
        )?;
        let accumulations = Self::accumulations(
            setup,
            (&settings, sides, &plan),
            (receiver_map.view(), &receiver_bounds.view),
            (&settings_buffer, &read_counts),
        )?;
        let accumulate_pipeline = Self::accumulate_pipeline(setup, (settings.accumulation, receiver_map.format()), &read_counts)?;
        let patches_pipeline = Self::patches_pipeline(setup, &read_counts)?;
        let (project, project_group) = Self::projection(
            setup,
            (&accumulations, settings.accumulation),
            &receiver_map,
            &settings_buffer,
            (&read_counts, plan.project),
        )?;
        Ok(Self {
            receiver_map,
            receiver_bounds: bounded.then_some(receiver_bounds),
            accumulations,
            accumulate_pipeline,
            patches_pipeline,
            occluder_map_size: settings.occluder_map_size,
            project,
            project_group,
            read_counts,
        })
    }

    /// One occluder map and SSM per side: one-sided, the nearest surface of every occluder face;
    /// two-sided (Sec. 3.5), the nearest front faces and the farthest back faces.
    fn accumulations(
        setup: &TechniqueSetup<'_>,
        (settings, sides, plan): (&AttySettings, &[Side], &CounterPlan),
        (receivers, receiver_bounds): (&wgpu::TextureView, &wgpu::TextureView),
        (settings_buffer, read_counts): (&wgpu::Buffer, &ReadCounts),
    ) -> Result<Vec<SideAccumulation>> {
        let device = &setup.gpu.device;
        let layout = Self::accumulate_layout(device);
        sides
            .iter()
            .zip(&plan.sides)
            .map(|(side, counters)| {
                let (pass_label, farthest) = (side.accumulate, side.farthest);
                let occluder_map =
                    unbiased_depth_map(setup, side.occluder_map, settings.occluder_map_size, Geometry::Occluders, (side.cull, farthest))?;
                let merging = settings.merge_tolerance > 0.0;
                // Without merging, the accumulation still binds a pyramid, of one texel, that it
                // never reads (nor builds: its counter slice is the first counters, never written
                // by it).
                let patch_merge = DepthPyramid::new(
                    setup,
                    (&PATCH_MERGE, side.patch_merge),
                    (&occluder_map.linear_depth_view, LightDepthMap::FORMAT),
                    if merging { settings.occluder_map_size } else { 1 },
                    (read_counts, counter_slice(read_counts, counters.patch_merge.unwrap_or(0), PYRAMID_UNITS.len())),
                )?;
                let texture_label = format!("{pass_label}_soft_shadow_map");
                let texture = render_texture(
                    device,
                    &texture_label,
                    settings.ssm_size,
                    settings.ssm_size,
                    settings.accumulation.format(),
                    wgpu::TextureUsages::empty(),
                );
                let patches = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(&format!("{pass_label}_patches")),
                    size: u64::from(settings.occluder_map_size).pow(2) * PATCH_RECORD_BYTES,
                    usage: wgpu::BufferUsages::STORAGE,
                    mapped_at_creation: false,
                });
                let draw_arguments = wgpu::util::DeviceExt::create_buffer_init(
                    device,
                    &wgpu::util::BufferInitDescriptor {
                        label: Some(&format!("{pass_label}_draw_arguments")),
                        contents: bytemuck::cast_slice(&[4u32, 0, 0, 0]),
                        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                    },
                );
                let patches_group = bind_group(
                    device,
                    &format!("{pass_label}_patches_bind_group"),
                    &Self::patches_layout(device),
                    &[
                        wgpu::BindingResource::TextureView(&occluder_map.linear_depth_view),
                        settings_buffer.as_entire_binding(),
                        wgpu::BindingResource::TextureView(receiver_bounds),
                        wgpu::BindingResource::TextureView(&patch_merge.view),
                        patches.as_entire_binding(),
                        draw_arguments.as_entire_binding(),
                        counter_slice(read_counts, counters.patches, PATCHES_UNITS.len()),
                    ],
                );
                let bind_group = bind_group(
                    device,
                    &format!("{pass_label}_bind_group"),
                    &layout,
                    &[
                        patches.as_entire_binding(),
                        wgpu::BindingResource::TextureView(receivers),
                        settings_buffer.as_entire_binding(),
                        counter_slice(read_counts, counters.accumulate, READS.len()),
                    ],
                );
                Ok(SideAccumulation {
                    occluder_map,
                    draw_arguments,
                    patches_group,
                    patches_label: side.patches,
                    patch_merge: merging.then_some(patch_merge),
                    soft_shadow_map: labelled_view(&texture, &texture_label),
                    bind_group,
                    label: pass_label,
                })
            })
            .collect()
    }

    fn accumulate_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        bind_group_layout(
            device,
            "atty_accumulate_layout",
            &[storage_entry(0, true), texture_entry(1), uniform_entry(2), ReadCounts::layout_entry(3)],
        )
    }

    fn patches_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
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

    /// The pass that lists the micro-patches (`atty_patches.wgsl`).
    fn patches_pipeline(setup: &TechniqueSetup<'_>, read_counts: &ReadCounts) -> Result<wgpu::ComputePipeline> {
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
            &[setup.gpu.uniform_layout(), &Self::patches_layout(device)],
            &constants,
        );
        let messages = setup.gpu.take_errors();
        if !messages.is_empty() {
            return Err(Error::Gpu { during: "building Atty's micro-patch list pass".into(), messages });
        }
        Ok(pipeline)
    }

    /// The instanced micro-patch pipeline: one quad per occluder texel, summed by additive
    /// blending into the float SSM (Sec. 4.1), reading the receiver map (of `receiver_format`).
    fn accumulate_pipeline(
        setup: &TechniqueSetup<'_>,
        (accumulation, receiver_format): (Accumulation, wgpu::TextureFormat),
        read_counts: &ReadCounts,
    ) -> Result<wgpu::RenderPipeline> {
        let device = &setup.gpu.device;
        // The bytes a fragment's receiver texel fetches.
        let [count_reads] = read_counts.pipeline_constants();
        let constants = [count_reads, ("RECEIVER_TEXEL_BYTES", texel_bytes(receiver_format))];
        let module = create_shader_with_imports(setup.gpu, "atty_accumulate_shader", ACCUMULATE_SHADER, LOCAL_SHADERS)?;
        let layout = Self::accumulate_layout(device);
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

    /// The projection of the SSM (the larger occlusion of both sides, summed in `accumulation`'s
    /// format) onto the screen.
    fn projection(
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
        // a test below), the receiver map and the soft shadow maps.
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
}

/// Fewest receiver-map texels across the receivers for the SSM to represent a penumbra on them.
const MIN_RECEIVER_TEXELS: f32 = 4.0;

/// The SSM lives on the receiver map of the light's frame. When that frame must be very wide (an
/// occluder almost touching the light, which every technique's frame keeps), the receivers can
/// shrink below a texel of it and would silently read as lit: refuse instead.
fn check_receivers_resolved(setup: &TechniqueSetup<'_>, ssm_size: u32) -> Result<()> {
    for (light, frame) in setup.scene.light_frames.iter().enumerate() {
        let texels = frame.footprint_texels(&setup.scene.receiver_bounds, ssm_size);
        if !setup.scene.receiver_bounds.is_empty() && texels.min_element() < MIN_RECEIVER_TEXELS {
            return Err(Error::Unrepresentable {
                technique: NAME.into(),
                reason: format!(
                    "light {light}'s frame is {:.1}° wide (an occluder lies almost in the light's plane), so the receivers cover only {:.1}×{:.1} texels of the {ssm_size}² soft shadow map; at least {MIN_RECEIVER_TEXELS} are needed",
                    2.0 * frame.tan_half.max_element().atan().to_degrees(),
                    texels.x,
                    texels.y
                ),
            });
        }
    }
    Ok(())
}

impl ShadowTechnique for SoftShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let light_frame = frame
            .scene
            .light_bind_groups
            .get(light)
            .ok_or_else(|| Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
        self.read_counts.clear(frame, light);
        self.receiver_map.encode(frame, light_frame);
        if let Some(bounds) = &self.receiver_bounds {
            bounds.encode(frame);
        }
        for accumulation in &self.accumulations {
            accumulation.occluder_map.encode(frame, light);
            if let Some(merge) = &accumulation.patch_merge {
                merge.encode(frame);
            }
            // The patch count back to 0 (bytes 4 to 8; the 4 vertices stay).
            frame.clear_buffer("atty_patch_count_reset", &accumulation.draw_arguments, 4, Some(4));
            {
                let mut pass = frame.compute_pass(accumulation.patches_label);
                pass.set_pipeline(&self.patches_pipeline);
                pass.set_bind_group(0, light_frame, &[]);
                pass.set_bind_group(1, &accumulation.patches_group, &[]);
                pass.dispatch_workgroups(self.occluder_map_size.div_ceil(8), self.occluder_map_size.div_ceil(8), 1);
            }
            let mut pass = frame.render_pass(
                accumulation.label,
                &[color_attachment(&accumulation.soft_shadow_map, Some(wgpu::Color::TRANSPARENT))],
                None,
            );
            pass.set_pipeline(&self.accumulate_pipeline);
            pass.set_bind_group(0, light_frame, &[]);
            pass.set_bind_group(1, &accumulation.bind_group, &[]);
            // One quad (4-vertex strip) per listed micro-patch.
            pass.draw_indirect(&accumulation.draw_arguments, 0);
        }
        self.project.encode(frame, light, output, Some(&self.project_group), None);
        Ok(())
    }

    /// Per counting pass (`CounterPlan`): texel reads, atomics and bytes written to storage, as
    /// its shader counted them (`atty_counts.wgsl`), when built for `--count-work`.
    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ShaderWork>>> {
        self.read_counts.work(gpu)
    }
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    let settings = AttySettings::from_params(params)?;
    // f32 accumulation blends into R32Float: never silently fall back to another precision.
    let features = if settings.accumulation == Accumulation::F32 { wgpu::Features::FLOAT32_BLENDABLE } else { wgpu::Features::empty() };
    Ok(Requirements {
        gbuffer: true,
        roles: true,
        features,
        max_texture_size: settings.occluder_map_size.max(settings.ssm_size),
        ..Requirements::NONE
    })
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(SoftShadowMaps::new(setup)?))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "soft shadow maps: occluder micro-patches back-projected onto the light, accumulated on the GPU (one- and two-sided)",
    paper: "Atty et al. 2006, Soft Shadow Maps: Efficient Sampling of Light Source Visibility (CGF 25(4))",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Frame,
    params: AttySettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("occluder_map_size=64,128,256,512"),
    debug_outputs: &[],
    uniforms: &[UniformCheck {
        wgsl_struct: "AttySettings",
        wgsl_source: PROJECT_SHADER,
        imports: LOCAL_SHADERS,
        rust: AttySettingsUniform::LAYOUT,
    }],
    limits: &[
        ssm_core::KnownLimit {
            case: "three lights",
            mean_error: 0.3,
            reason: "the three lights shine on sphere-cube, whose 125 spheres are occluders only, and the method splits the scene into occluders and receivers and computes no shadow on the occluders (Atty et al. 2006, Sec. 1 and Sec. 7: no self-occlusion), so spheres that shadow each other read lit: over the receivers alone its error under the first light is 0.0433, over every pixel 0.1204; under the point light, whose hard shadow leaves few penumbra pixels, the spheres are most of the pixels either shadows (0.2463)",
        },
        ssm_core::KnownLimit {
            case: "wall lit at grazing angles",
            mean_error: 0.2,
            reason: "the block standing on the wall has the role both, so it is in the receiver map, and the soft shadow map holds the occlusion of one receiver per texel, the one nearest the light's centre (Atty et al. 2006, Sec. 3.1: the receiver map's depth is the receiver's; Sec. 7: occluders and receivers must be separated, self-occlusion is left to future work with layered depth images): the wall behind the block, in its hard shadow from the centre, has no value of its own and reads umbra, a band the truth shows as penumbra (0.1678 at 96x72); with the block an occluder only, the split the paper requires, the error is 0.0371 and hard shadows' 0.2369",
        },
        ssm_core::KnownLimit {
            case: "light resting on the receiver",
            mean_error: 0.25,
            reason: "past the light frame's widest angle (84 degrees off the light's normal) the framework answers with a hard shadow from the light's centre (counted: pixels_beyond_frame): the soft shadow map is one virtual plane parallel to the light, onto which each micro-patch's penumbra pyramid cuts an axis-aligned rectangle (Atty et al. 2006, Sec. 3.3, Fig. 7); the micro-patches are parallel to the light (Sec. 3), which a hemicube's side faces, perpendicular to it, are not",
        },
    ],
    paper_configuration: ssm_core::PaperConfiguration {
        // The receiver's depth alone decides, and the SSM is read at the point itself (Sec. 3.1's
        // projective texture lookup; the normal offset is this workspace's, Holbert 2011).
        settings: &["receiver_plane=false", "normal_offset=0"],
        scenes: &["parallel-square", "floating-sphere"],
        truth: &[],
        // Where the occluder's edges fall on the occluder map's grid moves the error several times
        // over (Sec. 5.1.1's half-texel bound, either way): a whole cycle of sizes around 256.
        averaged_over: Some("occluder_map_size=252,253,254,255,256,257,258,259"),
    },
};

/// The error Atty et al.'s figures plot (Sec. 5.2.1): the mean absolute error over the pixels in
/// umbra or penumbra in the ground truth, not the workspace's headline error.
const PAPER_ERROR: &str = "mae-penumbra";

/// The paper's own receiver model and lookup, which every reproduction of its figures runs: a
/// receiver's depth alone decides (no receiver plane; `receiver_plane` is this workspace's model for
/// objects that both cast and receive, which the paper leaves out, Sec. 7), and the SSM is read at
/// the point itself (Sec. 3.1; no normal offset).
const PAPER_MODE: &str = "atty.receiver_plane:normal_offset=false:0";

/// Atty et al.'s studies (Sec. 5.2 and 6.2), as sweeps, in the paper's mode.
const PRESETS: &[ssm_core::Preset] = &[
    ssm_core::Preset {
        name: "atty-map-size",
        summary: "Atty et al., Fig. 17 (error) and Fig. 22 (time, with --error time) against the occluder map's size, one- and two-sided; in counted work (--count-work) the accumulation's fragments grow with the micro-patches, n², while each patch covers fewer",
        scenes: &["floating-sphere"],
        varies: &["atty.occluder_map_size=33,63,127,200,255,383,511", "atty.two_sided=false,true", PAPER_MODE],
        x_axis: "atty.occluder_map_size",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-map-size-time",
        summary: "Atty et al., Fig. 22: frame time against the occluder map's size (128², 256², 512²), one- and two-sided",
        scenes: &["floating-sphere"],
        varies: &["atty.occluder_map_size=128,256,512", "atty.two_sided=false,true", PAPER_MODE],
        x_axis: "atty.occluder_map_size",
        y_axis: "time",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-light-size",
        summary: "Atty et al., Fig. 18 and Fig. 24(b) (error; Fig. 24(a), time, with --error time) against the light's size for 63², 127², 255² maps (not powers of two, as the paper notes in Sec. 5.2.3; a thick occluder such as floating-sphere)",
        scenes: &["floating-sphere"],
        varies: &["scene.light_scale=0.02,0.25,0.5,1,1.5,2", "atty.occluder_map_size=63,127,255", PAPER_MODE],
        x_axis: "scene.light_scale",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-occluder-height",
        summary: "Atty et al., Fig. 20: error as the occluders move from the receiver towards the light (on floating-sphere: from 0.05 above the ground to 0.3 below the light, where every micro-patch's rectangle already covers most of the soft shadow map)",
        scenes: &["floating-sphere"],
        varies: &["scene.occluder_lift=-0.75,-0.5,0,0.5,1,1.5,1.6,1.7", "atty.two_sided=false,true", PAPER_MODE],
        x_axis: "scene.occluder_lift",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-occluder-shift",
        summary: "Atty et al., Fig. 19: error as the occluder moves sideways under the light (scene.occluder_shift, in light widths from its centre), 128² map, one- and two-sided",
        scenes: &["floating-sphere"],
        varies: &["scene.occluder_shift=-1,-0.5,-0.25,0,0.25,0.5,1", "atty.occluder_map_size=128", "atty.two_sided=false,true", PAPER_MODE],
        x_axis: "scene.occluder_shift",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-polygons",
        summary: "Atty et al., Fig. 21: error (and time, with --error time) against the occluder's polygon count, a sphere tessellated from 16 to 261,632 triangles (scene.segments, rings in step), 128² map",
        scenes: &["floating-sphere"],
        varies: &[
            "scene.segments:rings=4:3,16:8,64:32,256:128,512:256",
            "atty.occluder_map_size=128",
            "atty.two_sided=false,true",
            PAPER_MODE,
        ],
        x_axis: "scene.segments",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-small-maps",
        summary: "Atty et al., Fig. 23: large lights with small occluder maps, the error of 32², 64², 128² maps as the light grows (one to four times floating-sphere's)",
        scenes: &["floating-sphere"],
        varies: &["scene.light_scale=1,2,3,4", "atty.occluder_map_size=32,64,128", "atty.two_sided=true", PAPER_MODE],
        x_axis: "scene.light_scale",
        y_axis: PAPER_ERROR,
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-paper-mode",
        summary: "The default receiver model (receiver_plane) against the paper's mode (read at the point, and with this workspace's normal offset) on the paper's analytic case, parallel-square (exact truth), and on floating-sphere, over a whole cycle of the occluder map's grid phase near 256² and near 1024² (compare the means over each eight sizes: one size alone is decided by where the square's edges fall on the texel grid), with FP32 and Appendix A's FP16 accumulation, one patch per texel (merge_tolerance 0, as the paper)",
        scenes: &["parallel-square", "floating-sphere"],
        varies: &[
            "atty.receiver_plane:normal_offset=false:0,false:0.5,true:0.5",
            "atty.occluder_map_size=252,253,254,255,256,257,258,259,1020,1021,1022,1023,1024,1025,1026,1027",
            "atty.accumulation=f32,f16",
            "atty.merge_tolerance=0",
        ],
        x_axis: "atty.occluder_map_size",
        y_axis: PAPER_ERROR,
        ..ssm_core::Preset::DEFAULT
    },
];

register_technique!(INFO);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_accumulation_declares_float32_blendable_and_f16_does_not() {
        let mut params = INFO.default_params();
        params.set("accumulation", "f32").unwrap();
        let f32_needs = requirements(&params).unwrap();
        assert!(f32_needs.features.contains(wgpu::Features::FLOAT32_BLENDABLE) && f32_needs.roles && f32_needs.gbuffer);
        params.set("accumulation", "f16").unwrap();
        assert!(requirements(&params).unwrap().features.is_empty(), "f16 blends on any device");
        params.set("occluder_map_size", "2048").unwrap();
        assert_eq!(requirements(&params).unwrap().max_texture_size, 2048);
    }

    /// The bytes a read fetches are its texture's texel size: the projection counts the G-buffer's
    /// normal at its position's, which is the same format; the receiver map and the soft shadow
    /// maps follow the settings.
    #[test]
    fn the_texel_sizes_are_the_formats() {
        assert_eq!(ssm_core::GBuffer::POSITION_FORMAT, ssm_core::GBuffer::NORMAL_FORMAT);
        assert_eq!(texel_bytes(ssm_core::GBuffer::POSITION_FORMAT), 16.0);
        assert_eq!((texel_bytes(Accumulation::F32.format()), texel_bytes(Accumulation::F16.format())), (4.0, 2.0));
        assert_eq!((texel_bytes(LightDepthMap::FORMAT), texel_bytes(ReceiverPlaneMap::FORMAT)), (4.0, 16.0));
        assert_eq!((texel_bytes(RECEIVER_BOUNDS.format), texel_bytes(PATCH_MERGE.format)), (4.0, 8.0));
    }

    /// Every pass that counts its texel reads counts their bytes, in the order its shader
    /// records them (reads first, their bytes next).
    #[test]
    fn every_counter_of_reads_has_one_of_bytes_after_it() {
        for units in [PYRAMID_UNITS, PATCHES_UNITS, READS] {
            assert_eq!(&units[..2], ["reads", "read_bytes"], "{units:?}");
        }
    }
}
