//! Shen, Guennebaud, Yang and Feng, *Predicted Virtual Soft Shadow Maps with
//! High Quality Filtering*, Computer Graphics Forum 30(2) (Eurographics
//! 2011).
//!
//! The eight steps of the paper's Sec. 5.2, each a named, timed pass:
//! 1. the G-buffer (shared);
//! 2. a low-resolution shadow map rendered conservatively (`pvsm_low_res_map`),
//!    and its minimum-depth mip chain (`pvsm_low_res_mips`);
//! 3. per pixel, the average occluder depth, the soft-shadowing filter, the
//!    pixel's warped footprint and the anti-aliased filter h (`pvsm_kernel_shape`);
//! 4. in the same pass, the perceptual resolution prediction and its
//!    accumulation into the shadow-map tile grid;
//! 5. the grid's pyramid on the GPU (`pvsm_smtg_pyramid`), read back in the
//!    middle of the frame (`pvsm_smtg_readback`, the mapping timed on the CPU;
//!    the wait for the GPU before it is the `pvsm_smtg_readback_wait_ms`
//!    diagnostic);
//! 6. the kd-tree on the CPU (`pvsm_kdtree`, [`kdtree`]);
//! 7. per tile, a shadow map of the predicted resolution (`pvsm_tile_map`);
//! 8. per tile, the min/max depth pyramid of its map (`pvsm_tile_pyramid`)
//!    and the texel-as-quad filtering of the pixels whose filter reaches it,
//!    walked top-down over that pyramid (`pvsm_tile_filter`), merged per
//!    pixel, then the ratio (`pvsm_resolve`).
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique pvsm --set
//! pvsm.max_tile_size=1024 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_pvsm::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_pvsm::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("pvsm")?;
//! let params = info.params_from([("max_tile_size", "1024")])?;
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

pub mod kdtree;
pub mod prediction;
#[cfg(test)]
mod wgsl_tests;

use bytemuck::{Pod, Zeroable};
use glam::{UVec2, Vec2};
use ssm_core::passes::{
    bind_group, bind_group_layout, compute_pipeline, readback_buffer, storage_buffer, storage_entry, texture_entry, uniform_buffer,
    uniform_entry, visibility_storage_entry, write_storage_texture_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    Choice, DebugOutput, DepthBiasUniform, Error, ExtraImage, Frame, Geometry, GpuContext, LightDepthMap, LightDepthMapDesc,
    LightFrameUniform, ParamValues, Preset, ReceiverModel, Requirements, Result, Settings, ShadowMapBias, ShadowTechnique, TechniqueInfo,
    TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct, register_technique,
};

pub use kdtree::{Pyramid, Tile, Tiling};
pub use prediction::Prediction;

/// The registered name.
pub const NAME: &str = "pvsm";

/// WGSL files the PVSM shaders import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] = &[("pvsm/pvsm_common.wgsl", ssm_shaders::pvsm::PVSM_COMMON)];
/// Step 2: the conservative low-resolution map.
const CONSERVATIVE_SHADER: &str = ssm_shaders::pvsm::PVSM_CONSERVATIVE;
/// Steps 3–4: the kernel shape and the prediction.
const KERNEL_SHADER: &str = ssm_shaders::pvsm::PVSM_KERNEL;
/// Step 5: the grid's pyramid.
const PYRAMID_SHADER: &str = ssm_shaders::pvsm::PVSM_PYRAMID;
/// Step 2's minimum-depth mip chain.
const MIPS_SHADER: &str = ssm_shaders::pvsm::PVSM_MIPS;
/// Step 8 and the merge.
const FILTER_SHADER: &str = ssm_shaders::pvsm::PVSM_FILTER;
/// Step 7's culling to the tile.
const CULL_SHADER: &str = ssm_shaders::pvsm::PVSM_CULL;
/// Step 8's min/max pyramid of a tile's map.
const TILE_PYRAMID_SHADER: &str = ssm_shaders::pvsm::PVSM_TILE_PYRAMID;

/// The work the passes count with `count_reads` ([`ReadCounts`]), in the order the shaders index
/// them: `(WGSL constant, shader, pass, unit)`. A texel read is one texel fetched (a `textureLoad`,
/// or one element of a storage array read as a map's texel or a pixel's record), every read of
/// every invocation, the G-buffer's two texels included; beside each pass's reads, the bytes they
/// fetched (unit `read_bytes`): each read its texture's texel size or its storage element's size
/// (`*_BYTES` constants of the shaders, checked against the formats and records here by
/// `the_shaders_byte_sizes_are_the_formats_and_records`). `pvsm_tile_filter_walk` is no pass: the
/// filter's walk's reads alone per filter evaluation (unit `texels`, a diagnostic only), whose total
/// is `pvsm_texels_filtered`. The tile maps' texels rendered are the `pvsm_texels_rendered`
/// diagnostic, counted on the CPU from the tiles' sizes; the bytes the render passes store to
/// them the framework counts as target bytes.
const READ_COUNTERS: [(&str, &str, &str, &str); 16] = [
    ("READ_COUNTER_LOW_RES_MIPS", MIPS_SHADER, "pvsm_low_res_mips", "reads"),
    ("READ_COUNTER_LOW_RES_MIPS_READ_BYTES", MIPS_SHADER, "pvsm_low_res_mips", "read_bytes"),
    ("READ_COUNTER_KERNEL_SHAPE", KERNEL_SHADER, "pvsm_kernel_shape", "reads"),
    ("READ_COUNTER_KERNEL_SHAPE_READ_BYTES", KERNEL_SHADER, "pvsm_kernel_shape", "read_bytes"),
    ("READ_COUNTER_KERNEL_SHAPE_ATOMICS", KERNEL_SHADER, "pvsm_kernel_shape", "atomics"),
    ("READ_COUNTER_SMTG_PYRAMID", PYRAMID_SHADER, "pvsm_smtg_pyramid", "reads"),
    ("READ_COUNTER_SMTG_PYRAMID_READ_BYTES", PYRAMID_SHADER, "pvsm_smtg_pyramid", "read_bytes"),
    ("READ_COUNTER_TILE_PYRAMID", TILE_PYRAMID_SHADER, "pvsm_tile_pyramid", "reads"),
    ("READ_COUNTER_TILE_PYRAMID_READ_BYTES", TILE_PYRAMID_SHADER, "pvsm_tile_pyramid", "read_bytes"),
    ("READ_COUNTER_TILE_PYRAMID_STORAGE_BYTES", TILE_PYRAMID_SHADER, "pvsm_tile_pyramid", "storage_bytes"),
    ("READ_COUNTER_TILE_FILTER", FILTER_SHADER, "pvsm_tile_filter", "reads"),
    ("READ_COUNTER_TILE_FILTER_READ_BYTES", FILTER_SHADER, "pvsm_tile_filter", "read_bytes"),
    ("READ_COUNTER_TILE_FILTER_WALK", FILTER_SHADER, "pvsm_tile_filter_walk", "texels"),
    ("READ_COUNTER_RESOLVE", FILTER_SHADER, "pvsm_resolve", "reads"),
    ("READ_COUNTER_RESOLVE_READ_BYTES", FILTER_SHADER, "pvsm_resolve", "read_bytes"),
    ("READ_COUNTER_PREDICTED_TEXELS", KERNEL_SHADER, "pvsm_predicted", "texels_under_filter"),
];

/// How the low-resolution map is rasterised conservatively (step 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum Conservative {
    /// The hardware's conservative rasterization where the adapter has it, else [`Conservative::Software`].
    Auto,
    /// Hasselgren et al. 2005's second algorithm: triangles enlarged by half a texel's diagonal, clipped to their bounding box.
    Software,
    /// The adapter's CONSERVATIVE_RASTERIZATION (refused with a typed error where it is missing).
    Hardware,
    /// Plain rasterization: an occluder thinner than a texel can be missed, and its shadow lost (for comparison).
    Off,
}

/// How the filter weighs the shadow map's texels (Sec. 4.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum Integration {
    /// Each texel a quad of constant depth, weighted by the area of its intersection with the filter (Eq. 2).
    Quads,
    /// Each texel a point at its centre, weighted fully inside the filter (classic PCF).
    Points,
}

/// Which texels of a tile a pixel's filter reads (step 8).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum FilterTexels {
    /// Every texel under the filter, at the tile's resolution (the paper), walked as `filter_walk` says.
    Tile,
    /// Every k-th, each standing for a k×k block, k the ratio of the pixel's predicted texel to the
    /// tile's: a pixel's cost stays about ρ² in a tile a neighbour made finer, but occluders thinner
    /// than a block can fall between the samples. Always read sample by sample.
    Predicted,
}

/// How the filter's Eq. 2 sum over a tile's texels is walked (step 8); both give the same sum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum FilterWalk {
    /// Top-down over the tile's min/max depth pyramid: a block entirely in front of or behind the
    /// receiver adds its covered area at once, only mixed blocks descend; the cost follows the
    /// penumbra's boundary texels.
    Hierarchy,
    /// Every texel under the filter read and weighed; the cost follows the filter's area in texels.
    Texels,
}

/// Settings of [`PredictedVirtualShadowMaps`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct PvsmSettings {
    /// Side of the low-resolution shadow map rendered conservatively (step 2), which the blocker search and the fully-lit test read, texels.
    #[param(default = 1024, min = 64, max = 8192)]
    pub low_res_size: u32,
    /// Conservative rasterization of the low-resolution map: auto (the hardware's where the adapter has it), software (Hasselgren et al. 2005, Alg. 2), hardware, or off (for comparison).
    #[param(choice, default = "auto")]
    pub conservative: Conservative,
    /// Samples per axis of the average occluder depth on the low-resolution map (the detection of blockers reads every texel of the region at a coarser level of its minimum-depth mip chain).
    #[param(default = 8, min = 1, max = 32)]
    pub blocker_kernel: u32,
    /// Side of the shadow-map tile grid (SMTG), cells; a power of two.
    #[param(default = 64, min = 4, max = 256)]
    pub grid_size: u32,
    /// Largest side of a tile's shadow map, texels (clamped to the device's limit).
    #[param(default = 4096, min = 64, max = 16384)]
    pub max_tile_size: u32,
    /// Most tiles per light and frame: past it, tiles get less resolution than predicted (reported in the diagnostics).
    #[param(default = 64, min = 1, max = 256)]
    pub max_tiles: u32,
    /// A tile that fits one map is also split (kd-tree, step 6) while its map has more than this many times the texels its grid cells need, each at its own resolution: a few cells asking for fine texels (contact shadows, surfaces the light sees edge-on) then refine only their part of the map (not the paper's, whose tile takes its finest cell's resolution everywhere); 0: never (the paper). Fewer texels rendered and filtered, but thin occluders under large filters lose the resolution those cells gave them (README, "What differs").
    #[param(default = 0, min = 0, max = 64)]
    pub split_excess: u32,
    /// ρ, the perceptual model (Sec. 5.1): dynamic, static, linear (Fig. 8(b)), or fixed (no prediction: one map of fixed_size², Fig. 8(c)).
    #[param(choice, default = "dynamic")]
    pub prediction: Prediction,
    /// With prediction = fixed: side of the single map covering the light frame, texels (clamped to the device's limit).
    #[param(default = 4096, min = 64, max = 16384)]
    pub fixed_size: u32,
    /// Analytic anisotropic anti-aliasing (Sec. 4.2): the filter convolved with the pixel's footprint on the map, so that a pixel gets the visibility averaged over its footprint rather than at its point (off by default: the framework compares the visibility at each pixel's point; compare with reference.footprint=pixel when on).
    #[param(default = false)]
    pub antialiasing: bool,
    /// With antialiasing off: texels per pixel (along each axis) that the sharpest shadows ask for, penumbrae getting two texels across down to that width (not the paper's: its 1:1 rule for hard shadows, Sec. 5, suits an average over the footprint, while a point sample of a hard edge is placed only to within half a texel). 1 is the paper's rule and costs the least.
    #[param(default = 4, min = 1, max = 16)]
    pub hard_texels: u32,
    /// How texels are weighted (Sec. 4.1): quads (each texel's exact overlap with the filter, Eq. 2) or points (classic PCF, which bands where the penumbra's width changes quickly, Fig. 4).
    #[param(choice, default = "quads")]
    pub integration: Integration,
    /// Which texels of a tile the filter reads: tile (every one, the paper) or predicted (every k-th, k the ratio of the pixel's predicted texel to the tile's; cheaper where a neighbour made the tile finer).
    #[param(choice, default = "tile")]
    pub filter_texels: FilterTexels,
    /// How the filter walks a tile's texels (Eq. 2, the same sum either way): hierarchy (top-down over the tile's min/max depth pyramid; blocks entirely in front of or behind the receiver count at once) or texels (every texel under the filter, one by one). Point samples and filter_texels = predicted always read texel by texel.
    #[param(choice, default = "hierarchy")]
    pub filter_walk: FilterWalk,
    /// Count the texels each pass reads per pixel, its atomics and bytes written (diagnostics `<pass>_<unit>_per_pixel`, `pvsm_texels_filtered`); the atomics cost time, so off when timing.
    #[param(default = false)]
    pub count_reads: bool,
    /// k: the filter evaluated at k×k points of each pixel and averaged (Fig. 11's supersampling; set antialiasing=false).
    #[param(default = 1, min = 1, max = 32)]
    pub supersampling: u32,
    /// Step 7's culling to the tile: a compute pass keeps the triangles that can touch the tile and the tile map draws only those (false: every triangle, left to the clipper; for comparison).
    #[param(default = true)]
    pub tile_culling: bool,
    /// What the texels are compared with (as pcss's).
    #[param(flatten)]
    pub receiver: ReceiverModel,
    /// Depth bias and normal offset (in texels of the resolution each pixel asks for).
    #[param(flatten)]
    pub bias: ShadowMapBias,
}

/// `PvsmSettings` of `shaders/pvsm/pvsm_common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct PvsmSettingsUniform {
    grid_size: u32,
    blocker_kernel: u32,
    prediction: u32,
    antialiasing: u32,
    supersampling: u32,
    receiver_plane: u32,
    normal_offset: f32,
    constant_bias: f32,
    fixed_size: f32,
    point_samples: u32,
    predicted_stride: u32,
    hard_texels: f32,
    texel_walk: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

impl PvsmSettings {
    /// Whether step 8 walks the tiles' min/max pyramids (and so builds them): the paper's quads at
    /// the tile's resolution with `filter_walk = hierarchy`.
    fn walks_hierarchy(&self) -> bool {
        self.filter_walk == FilterWalk::Hierarchy && self.integration == Integration::Quads && self.filter_texels == FilterTexels::Tile
    }
}

impl From<&PvsmSettings> for PvsmSettingsUniform {
    fn from(settings: &PvsmSettings) -> Self {
        Self {
            grid_size: settings.grid_size,
            blocker_kernel: settings.blocker_kernel,
            prediction: settings.prediction.code(),
            antialiasing: u32::from(settings.antialiasing),
            supersampling: settings.supersampling,
            receiver_plane: u32::from(settings.receiver.receiver_plane),
            normal_offset: settings.bias.normal_offset,
            constant_bias: settings.bias.constant_bias,
            fixed_size: settings.fixed_size as f32,
            point_samples: u32::from(settings.integration == Integration::Points),
            predicted_stride: u32::from(settings.filter_texels == FilterTexels::Predicted),
            hard_texels: settings.hard_texels as f32,
            texel_walk: u32::from(settings.filter_walk == FilterWalk::Texels),
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        }
    }
}

/// `RasterSettings` of `shaders/pvsm/pvsm_conservative.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct RasterSettingsUniform {
    half_texel: [f32; 2],
    size: [f32; 2],
    enlarge: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

/// `PyramidSettings` of `shaders/pvsm/pvsm_pyramid.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct PyramidSettingsUniform {
    grid_size: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

/// `PyramidLevel` of `shaders/pvsm/pvsm_tile_pyramid.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct TilePyramidLevelUniform {
    level: u32,
    from_map: u32,
    _pad0: u32,
    _pad1: u32,
}

/// `CullSettings` of `shaders/pvsm/pvsm_cull.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct CullSettingsUniform {
    first_index: u32,
    triangle_count: u32,
    _pad0: u32,
    _pad1: u32,
}

/// `TileSettings` of `shaders/pvsm/pvsm_filter.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct TileSettingsUniform {
    uv_min: [f32; 2],
    uv_max: [f32; 2],
    size: [f32; 2],
    _pad0: f32,
    _pad1: f32,
}

impl From<&Tile> for TileSettingsUniform {
    fn from(tile: &Tile) -> Self {
        Self {
            uv_min: tile.uv_min.to_array(),
            uv_max: tile.uv_max.to_array(),
            size: tile.size.as_vec2().to_array(),
            _pad0: 0.0,
            _pad1: 0.0,
        }
    }
}

/// The conservative low-resolution map and its minimum-depth mip chain.
struct LowResMap {
    texture: wgpu::Texture,
    /// Level 0, rendered into.
    level0: wgpu::TextureView,
    depth: wgpu::TextureView,
    /// Per level from 1: the group reading the level above and writing this one, and its size.
    mips: Vec<(wgpu::BindGroup, u32)>,
    /// Every level, for the blocker search.
    all_levels: wgpu::TextureView,
}

impl LowResMap {
    fn new(device: &wgpu::Device, side: u32, mip_layout: &wgpu::BindGroupLayout, read_counts: &ReadCounts) -> Self {
        let levels = side.max(1).ilog2() + 1;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("pvsm_low_res_map"),
            size: wgpu::Extent3d { width: side, height: side, depth_or_array_layers: 1 },
            mip_level_count: levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: LightDepthMap::FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let level_view = |level: u32| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("pvsm_low_res_map_level{level}_view")),
                base_mip_level: level,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let mips = (1..levels)
            .map(|level| {
                let group = bind_group(
                    device,
                    &format!("pvsm_low_res_mip{level}_bind_group"),
                    mip_layout,
                    &[
                        wgpu::BindingResource::TextureView(&level_view(level - 1)),
                        wgpu::BindingResource::TextureView(&level_view(level)),
                        read_counts.buffer().as_entire_binding(),
                    ],
                );
                (group, (side >> level).max(1))
            })
            .collect();
        let depth = ssm_core::passes::render_texture(
            device,
            "pvsm_low_res_depth",
            side,
            side,
            LightDepthMap::DEPTH_FORMAT,
            wgpu::TextureUsages::empty(),
        );
        Self {
            texture: texture.clone(),
            level0: level_view(0),
            depth: ssm_core::passes::labelled_view(&depth, "pvsm_low_res_depth"),
            mips,
            all_levels: ssm_core::passes::labelled_view(&texture, "pvsm_low_res_map_all_levels"),
        }
    }
}

/// `Kernel` of `shaders/pvsm/pvsm_common.wgsl`: one pixel's filter from step 3, read back for the
/// debug outputs.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct KernelRecord {
    centre: [f32; 2],
    u_axis: [f32; 2],
    v_height: f32,
    depth: f32,
    flags: u32,
    offset: f32,
    texel: [f32; 2],
    blocker_depth: f32,
    _pad: f32,
}

impl KernelRecord {
    /// `KERNEL_ACTIVE` of the WGSL: the pixel has a filter to evaluate.
    const ACTIVE: u32 = 1;

    fn is_active(&self) -> bool {
        self.flags & Self::ACTIVE != 0
    }
}

/// The `COUNTER_*` slots of `pvsm_common.wgsl`, in order: pixels filtered, skipped as lit, whose
/// filter's walk reached its cap, and not covered by any tile.
const COUNTER_NAMES: [&str; 4] = ["COUNTER_FILTERED", "COUNTER_LIT", "COUNTER_CAPPED", "COUNTER_UNCOVERED"];
/// Bytes of the counters buffer.
const COUNTER_BYTES: u64 = COUNTER_NAMES.len() as u64 * 4;

/// Bytes of one [`KernelRecord`].
const KERNEL_BYTES: u64 = std::mem::size_of::<KernelRecord>() as u64;
/// Bytes of one pixel's accumulated sums, (Σ c·o, Σ c) as a `vec2<f32>`.
const ACCUMULATED_BYTES: u64 = 8;
/// Bytes of one pixel's capped flag, a `u32`.
const CAPPED_BYTES: u64 = 4;
/// Bytes of one cell of the tile grid (its resolutions along u and v, two u32) and of its pyramid
/// (the same, as a `vec2<f32>`).
const SMTG_CELL_BYTES: u64 = 8;

/// The uniforms of one tile of one light, written when the kd-tree has decided it.
struct TileSlot {
    frame: wgpu::Buffer,
    frame_group: wgpu::BindGroup,
    bias: wgpu::Buffer,
    bias_group: wgpu::BindGroup,
    settings: wgpu::Buffer,
    /// The tile's settings alone, for the pyramid's passes.
    pyramid_group: wgpu::BindGroup,
    /// One per tile map size (`tile_maps`): the tile's settings, that map and the pyramid.
    filter_groups: Vec<wgpu::BindGroup>,
}

/// Step 8's two-layer min/max depth pyramid of the current tile's map: mip m holds level m + 1
/// (blocks of 2^(m+1) texels a side) as (nearest, farthest, near_max, far_min), its near
/// cluster's texels per child in a second texture of the same mips, for the tile's region only
/// (`pvsm_tile_pyramid.wgsl`). One
/// pair serves every tile, rebuilt before each tile's filter; its side is half the largest tile
/// map's side rounded up to a power of two, so that level l holds ceil(size / 2^l) texels of any
/// region.
struct TilePyramid {
    /// Every mip, for the filter.
    view: wgpu::TextureView,
    /// Every mip of the near counts, for the filter.
    counts_view: wgpu::TextureView,
    /// Per tile map size: level 1's group, reading that map.
    first_level: Vec<wgpu::BindGroup>,
    /// Levels 2, 3...: each reading the mip below.
    upper_levels: Vec<wgpu::BindGroup>,
}

/// The format of the tile pyramid's depths: (nearest, farthest, near_max, far_min).
const TILE_PYRAMID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The format of its near counts: the near cluster's texels in each of the four children.
const TILE_PYRAMID_COUNTS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// A bind-group-layout entry for a `texture_2d<u32>` read with `textureLoad`.
const fn uint_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

impl TilePyramid {
    /// The pyramid for maps up to `largest` texels a side, and its level groups; 1×1 textures that
    /// no pass reads when the filter does not walk it (`built` false).
    fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        maps: &[LightDepthMap],
        read_counts: &ReadCounts,
        largest: u32,
        built: bool,
    ) -> Self {
        let side = if built { (largest.next_power_of_two() / 2).max(1) } else { 1 };
        let mips = side.ilog2() + 1;
        let texture = |label: &str, format: wgpu::TextureFormat, side: u32, mips: u32| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: side, height: side, depth_or_array_layers: 1 },
                mip_level_count: mips,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
                view_formats: &[],
            })
        };
        let depths = texture("pvsm_tile_pyramid", TILE_PYRAMID_FORMAT, side, mips);
        let counts = texture("pvsm_tile_pyramid_near_counts", TILE_PYRAMID_COUNTS_FORMAT, side, mips);
        let mip_view = |texture: &wgpu::Texture, mip: u32| {
            let name = if texture.format() == TILE_PYRAMID_FORMAT { "pvsm_tile_pyramid" } else { "pvsm_tile_pyramid_near_counts" };
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(&format!("{name}_mip{mip}_view")),
                base_mip_level: mip,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let level_uniform = |level: u32, from_map: bool| {
            let value = TilePyramidLevelUniform { level, from_map: u32::from(from_map), _pad0: 0, _pad1: 0 };
            uniform_buffer(device, &format!("pvsm_tile_pyramid_level{level}_uniform"), &value)
        };
        let (first_level, upper_levels) = if built {
            // Level 1 reads the map, not counts: a 1×1 texture stands in for them.
            let no_counts = texture("pvsm_tile_pyramid_no_counts", TILE_PYRAMID_COUNTS_FORMAT, 1, 1);
            let no_counts_view = ssm_core::passes::labelled_view(&no_counts, "pvsm_tile_pyramid_no_counts_view");
            let first_uniform = level_uniform(1, true);
            let first = maps
                .iter()
                .map(|map| {
                    bind_group(
                        device,
                        &format!("pvsm_tile_pyramid_level1_bind_group_{}", map.linear_depth.width()),
                        layout,
                        &[
                            first_uniform.as_entire_binding(),
                            wgpu::BindingResource::TextureView(&map.linear_depth_view),
                            wgpu::BindingResource::TextureView(&mip_view(&depths, 0)),
                            read_counts.buffer().as_entire_binding(),
                            wgpu::BindingResource::TextureView(&no_counts_view),
                            wgpu::BindingResource::TextureView(&mip_view(&counts, 0)),
                        ],
                    )
                })
                .collect();
            let upper = (2..=mips)
                .map(|level| {
                    bind_group(
                        device,
                        &format!("pvsm_tile_pyramid_level{level}_bind_group"),
                        layout,
                        &[
                            level_uniform(level, false).as_entire_binding(),
                            wgpu::BindingResource::TextureView(&mip_view(&depths, level - 2)),
                            wgpu::BindingResource::TextureView(&mip_view(&depths, level - 1)),
                            read_counts.buffer().as_entire_binding(),
                            wgpu::BindingResource::TextureView(&mip_view(&counts, level - 2)),
                            wgpu::BindingResource::TextureView(&mip_view(&counts, level - 1)),
                        ],
                    )
                })
                .collect();
            (first, upper)
        } else {
            (Vec::new(), Vec::new())
        };
        Self {
            view: ssm_core::passes::labelled_view(&depths, "pvsm_tile_pyramid_all_levels"),
            counts_view: ssm_core::passes::labelled_view(&counts, "pvsm_tile_pyramid_near_counts_all_levels"),
            first_level,
            upper_levels,
        }
    }
}

/// The pipelines, made once.
struct Pipelines {
    low_res: wgpu::RenderPipeline,
    mip: wgpu::ComputePipeline,
    kernel: wgpu::ComputePipeline,
    pyramid: wgpu::ComputePipeline,
    filter: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    cull: wgpu::ComputePipeline,
    tile_pyramid: wgpu::ComputePipeline,
}

/// The buffers of the screen-space and grid passes.
struct Buffers {
    kernels: wgpu::Buffer,
    accumulated: wgpu::Buffer,
    /// Per pixel, a u32: 1 once its filter's walk reached its cap in some tile.
    capped: wgpu::Buffer,
    grid: wgpu::Buffer,
    /// `COUNTER_*` of `pvsm_common.wgsl`, summed over the lights of the last frame.
    counters: wgpu::Buffer,
    pyramid: wgpu::Buffer,
    pyramid_readback: wgpu::Buffer,
    pyramid_cells: u64,
    /// Step 7: the indices of the triangles kept for the current tile, and its indirect draw.
    culled_indices: wgpu::Buffer,
    tile_draw: wgpu::Buffer,
}

/// What the last frame measured, for `diagnostics`.
#[derive(Clone, Debug, Default)]
struct LastFrame {
    tilings: Vec<Tiling>,
    /// The mid-frame readbacks' waits for the GPU, summed over the lights (`Frame::last_read_back_wait_ms`).
    readback_wait_ms: f64,
}

/// Predicted virtual soft shadow maps.
pub struct PredictedVirtualShadowMaps {
    settings: PvsmSettings,
    pipelines: Pipelines,
    buffers: Buffers,
    low_res: LowResMap,
    low_res_group: wgpu::BindGroup,
    gbuffer_group: wgpu::BindGroup,
    kernel_group: wgpu::BindGroup,
    pyramid_group: wgpu::BindGroup,
    cull_group: wgpu::BindGroup,
    /// Triangles step 7's culling tests per tile.
    cull_triangles: u32,
    /// Per light: its tile slots, then its resolve group (binding its visibility target).
    slots: Vec<Vec<TileSlot>>,
    resolve_groups: Vec<wgpu::BindGroup>,
    common_group: wgpu::BindGroup,
    /// Tile maps of sides 64, 128, 256... up to the largest tile: a tile is rendered into the
    /// smallest that holds it, so that clearing a map costs what the tile needs.
    tile_maps: Vec<LightDepthMap>,
    /// Step 8's min/max pyramid of the current tile's map.
    tile_pyramid: TilePyramid,
    /// The passes' counted work, with `count_reads` or the framework's counting frame.
    read_counts: ReadCounts,
    /// Whether the shaders count (`count_reads`, or `TechniqueSetup::count_work`).
    counting: bool,
    atlas_side: u32,
    triangle_count: u32,
    width: u32,
    height: u32,
    last: LastFrame,
}

impl PredictedVirtualShadowMaps {
    /// Builds the maps, buffers and pipelines.
    ///
    /// # Errors
    /// A parameter error (a tile grid that is not a power of two), a missing device feature, or a GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = PvsmSettings::from_params(setup.params)?;
        if !settings.grid_size.is_power_of_two() {
            return Err(Error::Technique {
                technique: NAME.into(),
                message: format!("grid_size = {} is not a power of two", settings.grid_size),
            });
        }
        let gpu = setup.gpu;
        let device = &gpu.device;
        let gbuffer = setup.shared.gbuffer(NAME)?;
        let limit = device.limits().max_texture_dimension_2d;
        let atlas_side = if settings.prediction == Prediction::Fixed { settings.fixed_size } else { settings.max_tile_size }.min(limit);
        let (width, height) = (setup.scene.width, setup.scene.height);
        let buffers = Self::buffers(device, &settings, width, height, setup.scene.triangle_count);
        let hardware = match settings.conservative {
            Conservative::Hardware => true,
            Conservative::Software | Conservative::Off => false,
            Conservative::Auto => gpu.features().contains(wgpu::Features::CONSERVATIVE_RASTERIZATION),
        };
        let layouts = Layouts::new(device);
        let counters: Vec<(&'static str, &'static str)> = READ_COUNTERS.iter().map(|(_, _, pass, unit)| (*pass, *unit)).collect();
        let counting = settings.count_reads || setup.count_work;
        let read_counts = ReadCounts::with_units(device, "pvsm_read_counts", &counters, counting);
        let low_res = LowResMap::new(device, settings.low_res_size, &layouts.mip, &read_counts);
        let groups = StepGroups::new(setup, &settings, &layouts, &buffers, &low_res, &read_counts, hardware);
        let tile_maps = Self::tile_maps(setup, atlas_side)?;
        let tile_pyramid =
            TilePyramid::new(device, &layouts.tile_pyramid_level, &tile_maps, &read_counts, atlas_side, settings.walks_hierarchy());
        let range = tile_maps.first().map_or(0..0, LightDepthMap::index_range);
        let cull_triangles = (range.end - range.start) / 3;
        let cull_settings = CullSettingsUniform { first_index: range.start, triangle_count: cull_triangles, _pad0: 0, _pad1: 0 };
        let cull_group = bind_group(
            device,
            "pvsm_tile_cull_bind_group",
            &layouts.cull,
            &[
                uniform_buffer(device, "pvsm_tile_cull_uniform", &cull_settings).as_entire_binding(),
                setup.scene.vertex_buffer.as_entire_binding(),
                setup.scene.index_buffer.as_entire_binding(),
                buffers.culled_indices.as_entire_binding(),
                buffers.tile_draw.as_entire_binding(),
            ],
        );
        let slots = (0..setup.scene.light_count())
            .map(|light| Self::tile_slots(gpu, &layouts, &tile_maps, &tile_pyramid, light, settings.max_tiles))
            .collect();
        let resolve_groups = Self::resolve_groups(setup, &layouts.resolve);
        let pipelines = Pipelines::new(setup, &layouts, &gbuffer.layout, &read_counts, hardware)?;
        Ok(Self {
            settings,
            pipelines,
            buffers,
            low_res,
            low_res_group: groups.low_res,
            gbuffer_group: gbuffer.bind_group.clone(),
            kernel_group: groups.kernel,
            pyramid_group: groups.pyramid,
            cull_group,
            cull_triangles,
            slots,
            resolve_groups,
            common_group: groups.common,
            tile_maps,
            tile_pyramid,
            read_counts,
            counting,
            atlas_side,
            triangle_count: setup.scene.triangle_count,
            width,
            height,
            last: LastFrame::default(),
        })
    }

    /// Step 7's depth maps: one per power-of-two side up to the atlas's, each tile drawn into the
    /// smallest that holds it.
    fn tile_maps(setup: &TechniqueSetup<'_>, atlas_side: u32) -> Result<Vec<LightDepthMap>> {
        tile_map_sides(atlas_side)
            .into_iter()
            .map(|side| {
                LightDepthMap::new(
                    setup.gpu,
                    setup.scene,
                    &LightDepthMapDesc {
                        label: &format!("pvsm_tile_map_{side}"),
                        width: side,
                        height: side,
                        geometry: Geometry::All,
                        cull_mode: None,
                        farthest: false,
                        // Each tile gets its own bias (its own texel size); see `TileSlot`.
                        constant_bias: 0.0,
                        slope_bias: 0.0,
                    },
                )
            })
            .collect()
    }

    /// The resolve pass's output per light (binding 2: the filter's tile resources hold 0 and 1 of
    /// the same group in the same module).
    fn resolve_groups(setup: &TechniqueSetup<'_>, layout: &wgpu::BindGroupLayout) -> Vec<wgpu::BindGroup> {
        setup
            .outputs
            .iter()
            .enumerate()
            .map(|(light, output)| {
                setup.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("pvsm_resolve_bind_group_{light}")),
                    layout,
                    entries: &[wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(output) }],
                })
            })
            .collect()
    }

    fn buffers(device: &wgpu::Device, settings: &PvsmSettings, width: u32, height: u32, triangles: u32) -> Buffers {
        let pixels = u64::from(width) * u64::from(height);
        // Every level of the pyramid: a geometric series of the grid's cells.
        let mut pyramid_cells = 0u64;
        let mut side = u64::from(settings.grid_size);
        while side >= 1 {
            pyramid_cells += side * side;
            if side == 1 {
                break;
            }
            side /= 2;
        }
        let cells = u64::from(settings.grid_size).pow(2);
        Buffers {
            kernels: storage_buffer(device, "pvsm_kernel_buffer", pixels * KERNEL_BYTES),
            accumulated: storage_buffer(device, "pvsm_accumulated_buffer", pixels * ACCUMULATED_BYTES),
            capped: storage_buffer(device, "pvsm_capped_buffer", pixels * CAPPED_BYTES),
            grid: storage_buffer(device, "pvsm_smtg_buffer", cells * SMTG_CELL_BYTES),
            counters: storage_buffer(device, "pvsm_counters_buffer", COUNTER_BYTES),
            pyramid: storage_buffer(device, "pvsm_smtg_pyramid_buffer", pyramid_cells * SMTG_CELL_BYTES),
            pyramid_readback: readback_buffer(device, "pvsm_smtg_pyramid_readback", pyramid_cells * SMTG_CELL_BYTES),
            pyramid_cells,
            culled_indices: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pvsm_tile_culled_indices"),
                size: (u64::from(triangles) * 12).max(12),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDEX,
                mapped_at_creation: false,
            }),
            tile_draw: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pvsm_tile_draw_arguments"),
                size: 20,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
        }
    }

    /// The uniforms and bind groups of `max_tiles` tiles of one light. Each light has its own:
    /// the writes of a tile's uniforms land before the next submission, and a light's tiles are
    /// recorded before the next light's readback submits them.
    fn tile_slots(
        gpu: &GpuContext,
        layouts: &Layouts,
        maps: &[LightDepthMap],
        pyramid: &TilePyramid,
        light: usize,
        max_tiles: u32,
    ) -> Vec<TileSlot> {
        let device = &gpu.device;
        (0..max_tiles)
            .map(|k| {
                let label = format!("pvsm_tile_{light}_{k}");
                let frame = uniform_buffer_writable(device, &format!("{label}_frame"), std::mem::size_of::<LightFrameUniform>() as u64);
                let bias = uniform_buffer_writable(device, &format!("{label}_bias"), std::mem::size_of::<DepthBiasUniform>() as u64);
                let settings =
                    uniform_buffer_writable(device, &format!("{label}_settings"), std::mem::size_of::<TileSettingsUniform>() as u64);
                TileSlot {
                    frame_group: bind_group(
                        device,
                        &format!("{label}_frame_bind_group"),
                        gpu.uniform_layout(),
                        &[frame.as_entire_binding()],
                    ),
                    bias_group: bind_group(device, &format!("{label}_bias_bind_group"), gpu.uniform_layout(), &[bias.as_entire_binding()]),
                    pyramid_group: bind_group(
                        device,
                        &format!("{label}_pyramid_bind_group"),
                        &layouts.tile_pyramid_tile,
                        &[settings.as_entire_binding()],
                    ),
                    filter_groups: maps
                        .iter()
                        .map(|map| {
                            // Binding 2 of the group is the resolve pass's target (the same module).
                            device.create_bind_group(&wgpu::BindGroupDescriptor {
                                label: Some(&format!("{label}_filter_bind_group_{}", map.linear_depth.width())),
                                layout: &layouts.tile,
                                entries: &[
                                    wgpu::BindGroupEntry { binding: 0, resource: settings.as_entire_binding() },
                                    wgpu::BindGroupEntry {
                                        binding: 1,
                                        resource: wgpu::BindingResource::TextureView(&map.linear_depth_view),
                                    },
                                    wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&pyramid.view) },
                                    wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&pyramid.counts_view) },
                                ],
                            })
                        })
                        .collect(),
                    frame,
                    bias,
                    settings,
                }
            })
            .collect()
    }

    fn dispatch(&self, frame: &mut Frame<'_>, label: &str, pipeline: &wgpu::ComputePipeline, groups: &[&wgpu::BindGroup], light: usize) {
        let light_group = &frame.scene.light_bind_groups[light];
        let mut pass = frame.compute_pass(label);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, light_group, &[]);
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        for (index, group) in groups.iter().enumerate() {
            pass.set_bind_group(2 + index as u32, *group, &[]);
        }
        pass.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
    }

    /// Step 7's culling: the triangles that can touch the tile whose frame is `tile_frame`, compacted
    /// into `culled_indices` with their count in `tile_draw`'s indirect arguments.
    fn cull_to_tile(&self, frame: &mut Frame<'_>, tile_frame: &wgpu::BindGroup) {
        frame.clear_buffer("pvsm_clear_tile_draw", &self.buffers.tile_draw, 0, None);
        let groups = self.cull_triangles.div_ceil(256).max(1);
        let mut pass = frame.compute_pass("pvsm_tile_cull");
        pass.set_pipeline(&self.pipelines.cull);
        pass.set_bind_group(0, tile_frame, &[]);
        pass.set_bind_group(1, &self.cull_group, &[]);
        pass.dispatch_workgroups(groups.min(65535), groups.div_ceil(65535), 1);
    }

    /// Step 8's min/max pyramid of the tile map of size class `class`, over the tile's `size`
    /// texels: levels 1 to ceil(log2 of the longer side), each a pass reading the one below.
    fn build_tile_pyramid(&self, frame: &mut Frame<'_>, slot: &TileSlot, class: usize, size: UVec2) -> Result<()> {
        let levels = size.max_element().max(2).next_power_of_two().ilog2();
        for level in 1..=levels {
            let group =
                if level == 1 { self.tile_pyramid.first_level.get(class) } else { self.tile_pyramid.upper_levels.get(level as usize - 2) };
            let Some(group) = group else {
                return Err(Error::Technique {
                    technique: NAME.into(),
                    message: format!("no tile pyramid level {level} for a tile of {size}"),
                });
            };
            let texels = (size + UVec2::splat((1 << level) - 1)) >> level;
            let mut pass = frame.compute_pass("pvsm_tile_pyramid");
            pass.set_pipeline(&self.pipelines.tile_pyramid);
            pass.set_bind_group(0, &slot.pyramid_group, &[]);
            pass.set_bind_group(1, group, &[]);
            pass.dispatch_workgroups(texels.x.div_ceil(8), texels.y.div_ceil(8), 1);
        }
        Ok(())
    }

    /// Steps 5 and 6: the pyramid, its readback, the kd-tree.
    fn tiling(&self, frame: &mut Frame<'_>) -> Result<Tiling> {
        if self.settings.prediction == Prediction::Fixed {
            let side = self.atlas_side;
            return Ok(Tiling {
                tiles: vec![Tile {
                    uv_min: Vec2::ZERO,
                    uv_max: Vec2::ONE,
                    size: UVec2::splat(side),
                    clamped: side < self.settings.fixed_size,
                }],
                cap_reached: false,
            });
        }
        {
            let mut pass = frame.compute_pass("pvsm_smtg_pyramid");
            pass.set_pipeline(&self.pipelines.pyramid);
            pass.set_bind_group(0, &self.pyramid_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        frame.copy_buffer_to_buffer(
            "pvsm_smtg_copy",
            &self.buffers.pyramid,
            0,
            &self.buffers.pyramid_readback,
            0,
            self.buffers.pyramid_cells * SMTG_CELL_BYTES,
        );
        let bytes = frame.read_back("pvsm_smtg_readback", &self.buffers.pyramid_readback)?;
        let values: Vec<Vec2> = bytemuck::pod_collect_to_vec::<u8, [f32; 2]>(&bytes).into_iter().map(Vec2::from_array).collect();
        let pyramid = Pyramid::from_levels(self.settings.grid_size, &values)
            .map_err(|message| Error::Technique { technique: NAME.into(), message })?;
        let (max_tile, max_tiles) = (self.atlas_side, self.settings.max_tiles as usize);
        let split_excess = self.settings.split_excess as f32;
        Ok(frame.cpu_scope("pvsm_kdtree", || kdtree::tile(&pyramid, max_tile, max_tiles, split_excess)))
    }
}

/// The sides of the tile maps: 64, 128, ... below `largest`, then `largest`.
fn tile_map_sides(largest: u32) -> Vec<u32> {
    let mut sides: Vec<u32> = (6..15).map(|k| 1u32 << k).take_while(|side| *side < largest).collect();
    sides.push(largest);
    sides
}

/// A uniform buffer of `size` bytes written each frame.
fn uniform_buffer_writable(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The bind groups of steps 2 to 5 and 8 that do not change per light or tile.
struct StepGroups {
    low_res: wgpu::BindGroup,
    kernel: wgpu::BindGroup,
    pyramid: wgpu::BindGroup,
    common: wgpu::BindGroup,
}

impl StepGroups {
    fn new(
        setup: &TechniqueSetup<'_>,
        settings: &PvsmSettings,
        layouts: &Layouts,
        buffers: &Buffers,
        low_res: &LowResMap,
        read_counts: &ReadCounts,
        hardware: bool,
    ) -> Self {
        let device = &setup.gpu.device;
        let settings_buffer = uniform_buffer(device, "pvsm_settings_uniform", &PvsmSettingsUniform::from(settings));
        let raster = RasterSettingsUniform {
            half_texel: [1.0 / settings.low_res_size as f32; 2],
            size: [settings.low_res_size as f32; 2],
            enlarge: u32::from(!hardware && settings.conservative != Conservative::Off),
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        };
        let low_res_group = bind_group(
            device,
            "pvsm_low_res_bind_group",
            &layouts.low_res,
            &[
                setup.scene.vertex_buffer.as_entire_binding(),
                setup.scene.index_buffer.as_entire_binding(),
                uniform_buffer(device, "pvsm_raster_uniform", &raster).as_entire_binding(),
            ],
        );
        let kernel = bind_group(
            device,
            "pvsm_kernel_bind_group",
            &layouts.kernel,
            &[
                setup.scene.camera_buffer.as_entire_binding(),
                settings_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&low_res.all_levels),
                buffers.kernels.as_entire_binding(),
                buffers.grid.as_entire_binding(),
                buffers.counters.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        let pyramid_settings = PyramidSettingsUniform { grid_size: settings.grid_size, _pad0: 0, _pad1: 0, _pad2: 0 };
        let pyramid = bind_group(
            device,
            "pvsm_pyramid_bind_group",
            &layouts.pyramid,
            &[
                uniform_buffer(device, "pvsm_pyramid_uniform", &pyramid_settings).as_entire_binding(),
                buffers.grid.as_entire_binding(),
                buffers.pyramid.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        let common = bind_group(
            device,
            "pvsm_filter_common_bind_group",
            &layouts.common,
            &[
                setup.scene.camera_buffer.as_entire_binding(),
                settings_buffer.as_entire_binding(),
                buffers.kernels.as_entire_binding(),
                buffers.accumulated.as_entire_binding(),
                buffers.capped.as_entire_binding(),
                buffers.counters.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        Self { low_res: low_res_group, kernel, pyramid, common }
    }
}

/// The bind group layouts of the passes' own resources.
struct Layouts {
    low_res: wgpu::BindGroupLayout,
    mip: wgpu::BindGroupLayout,
    kernel: wgpu::BindGroupLayout,
    pyramid: wgpu::BindGroupLayout,
    common: wgpu::BindGroupLayout,
    tile: wgpu::BindGroupLayout,
    resolve: wgpu::BindGroupLayout,
    cull: wgpu::BindGroupLayout,
    /// The tile pyramid's passes: the tile's settings, and one level's resources.
    tile_pyramid_tile: wgpu::BindGroupLayout,
    tile_pyramid_level: wgpu::BindGroupLayout,
}

impl Layouts {
    fn new(device: &wgpu::Device) -> Self {
        Self {
            low_res: bind_group_layout(device, "pvsm_low_res_layout", &[storage_entry(0, true), storage_entry(1, true), uniform_entry(2)]),
            mip: bind_group_layout(
                device,
                "pvsm_low_res_mip_layout",
                &[texture_entry(0), write_storage_texture_entry(1, LightDepthMap::FORMAT), ReadCounts::layout_entry(2)],
            ),
            kernel: bind_group_layout(
                device,
                "pvsm_kernel_layout",
                &[
                    uniform_entry(0),
                    uniform_entry(1),
                    texture_entry(2),
                    storage_entry(3, false),
                    storage_entry(4, false),
                    storage_entry(5, false),
                    ReadCounts::layout_entry(6),
                ],
            ),
            pyramid: bind_group_layout(
                device,
                "pvsm_pyramid_layout",
                &[uniform_entry(0), storage_entry(1, true), storage_entry(2, false), ReadCounts::layout_entry(3)],
            ),
            common: bind_group_layout(
                device,
                "pvsm_filter_common_layout",
                &[
                    uniform_entry(0),
                    uniform_entry(1),
                    storage_entry(2, true),
                    storage_entry(3, false),
                    storage_entry(4, false),
                    storage_entry(5, false),
                    ReadCounts::layout_entry(6),
                ],
            ),
            tile: bind_group_layout(
                device,
                "pvsm_tile_layout",
                &[uniform_entry(0), texture_entry(1), texture_entry(3), uint_texture_entry(4)],
            ),
            tile_pyramid_tile: bind_group_layout(device, "pvsm_tile_pyramid_tile_layout", &[uniform_entry(0)]),
            tile_pyramid_level: bind_group_layout(
                device,
                "pvsm_tile_pyramid_level_layout",
                &[
                    uniform_entry(0),
                    texture_entry(1),
                    write_storage_texture_entry(2, TILE_PYRAMID_FORMAT),
                    ReadCounts::layout_entry(3),
                    uint_texture_entry(4),
                    write_storage_texture_entry(5, TILE_PYRAMID_COUNTS_FORMAT),
                ],
            ),
            cull: bind_group_layout(
                device,
                "pvsm_tile_cull_layout",
                &[uniform_entry(0), storage_entry(1, true), storage_entry(2, true), storage_entry(3, false), storage_entry(4, false)],
            ),
            resolve: bind_group_layout(
                device,
                "pvsm_resolve_layout",
                &[wgpu::BindGroupLayoutEntry { binding: 2, ..visibility_storage_entry(2) }],
            ),
        }
    }
}

impl Pipelines {
    fn new(
        setup: &TechniqueSetup<'_>,
        layouts: &Layouts,
        gbuffer_layout: &wgpu::BindGroupLayout,
        read_counts: &ReadCounts,
        hardware: bool,
    ) -> Result<Self> {
        let gpu = setup.gpu;
        // COUNT_READS: the counting code compiled in only with count_reads.
        let counting = read_counts.pipeline_constants();
        let device = &gpu.device;
        let module = |label: &str, source: &str| create_shader_with_imports(gpu, label, source, LOCAL_SHADERS);
        let conservative = module("pvsm_conservative_shader", CONSERVATIVE_SHADER)?;
        let low_res_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pvsm_low_res_pipeline_layout"),
            bind_group_layouts: &[Some(gpu.uniform_layout()), Some(&layouts.low_res)],
            immediate_size: 0,
        });
        let low_res = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("pvsm_low_res_pipeline"),
            layout: Some(&low_res_layout),
            vertex: wgpu::VertexState {
                module: &conservative,
                entry_point: Some("pvsm_conservative_vertex"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState { conservative: hardware, ..Default::default() },
            depth_stencil: Some(LightDepthMap::depth_test(false)),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &conservative,
                entry_point: Some("pvsm_conservative_fragment"),
                compilation_options: Default::default(),
                targets: &[Some(LightDepthMap::FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let screen = [gpu.uniform_layout(), gbuffer_layout];
        let kernel_module = module("pvsm_kernel_shader", KERNEL_SHADER)?;
        let pyramid_module = module("pvsm_pyramid_shader", PYRAMID_SHADER)?;
        let filter_module = module("pvsm_filter_shader", FILTER_SHADER)?;
        let mip_module = module("pvsm_mips_shader", MIPS_SHADER)?;
        let cull_module = module("pvsm_cull_shader", CULL_SHADER)?;
        let tile_pyramid_module = module("pvsm_tile_pyramid_shader", TILE_PYRAMID_SHADER)?;
        Ok(Self {
            low_res,
            mip: compute_pipeline(device, "pvsm_low_res_mip_pipeline", &mip_module, "pvsm_low_res_mip", &[&layouts.mip], &counting),
            kernel: compute_pipeline(
                device,
                "pvsm_kernel_pipeline",
                &kernel_module,
                "pvsm_kernel",
                &[screen[0], screen[1], &layouts.kernel],
                &counting,
            ),
            pyramid: compute_pipeline(device, "pvsm_pyramid_pipeline", &pyramid_module, "pvsm_pyramid", &[&layouts.pyramid], &counting),
            filter: compute_pipeline(
                device,
                "pvsm_tile_filter_pipeline",
                &filter_module,
                "pvsm_tile_filter",
                &[screen[0], screen[1], &layouts.common, &layouts.tile],
                &counting,
            ),
            resolve: compute_pipeline(
                device,
                "pvsm_resolve_pipeline",
                &filter_module,
                "pvsm_resolve",
                &[screen[0], screen[1], &layouts.common, &layouts.resolve],
                &counting,
            ),
            cull: compute_pipeline(
                device,
                "pvsm_tile_cull_pipeline",
                &cull_module,
                "pvsm_tile_cull",
                &[gpu.uniform_layout(), &layouts.cull],
                &[],
            ),
            tile_pyramid: compute_pipeline(
                device,
                "pvsm_tile_pyramid_pipeline",
                &tile_pyramid_module,
                "pvsm_tile_pyramid",
                &[&layouts.tile_pyramid_tile, &layouts.tile_pyramid_level],
                &counting,
            ),
        })
    }
}

impl ShadowTechnique for PredictedVirtualShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, _output: &wgpu::TextureView) -> Result<()> {
        let no_light = || Error::Technique { technique: NAME.into(), message: format!("no light {light}") };
        let resolve_group = self.resolve_groups.get(light).ok_or_else(no_light)?.clone();
        frame.clear_buffer("pvsm_clear_grid", &self.buffers.grid, 0, None);
        if light == 0 {
            // The counters sum over the frame's lights; the renderer renders light 0 first.
            frame.clear_buffer("pvsm_clear_counters", &self.buffers.counters, 0, None);
            self.last.readback_wait_ms = 0.0;
        }
        self.read_counts.clear(frame, light);
        frame.clear_buffer("pvsm_clear_accumulated", &self.buffers.accumulated, 0, None);
        frame.clear_buffer("pvsm_clear_capped", &self.buffers.capped, 0, None);
        // Step 2: the conservative low-resolution map.
        {
            let light_group = &frame.scene.light_bind_groups[light];
            let mut pass = frame.render_pass(
                "pvsm_low_res_map",
                &[ssm_core::passes::color_attachment(
                    &self.low_res.level0,
                    Some(wgpu::Color { r: f64::from(ssm_core::NO_SURFACE), g: 0.0, b: 0.0, a: 0.0 }),
                )],
                Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.low_res.depth,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Discard }),
                    stencil_ops: None,
                }),
            );
            pass.set_pipeline(&self.pipelines.low_res);
            pass.set_bind_group(0, light_group, &[]);
            pass.set_bind_group(1, &self.low_res_group, &[]);
            pass.draw(0..self.triangle_count * 3, 0..1);
        }
        for (group, side) in &self.low_res.mips {
            let mut pass = frame.compute_pass("pvsm_low_res_mips");
            pass.set_pipeline(&self.pipelines.mip);
            pass.set_bind_group(0, group, &[]);
            pass.dispatch_workgroups(side.div_ceil(8), side.div_ceil(8), 1);
        }
        // Steps 3 and 4.
        self.dispatch(frame, "pvsm_kernel_shape", &self.pipelines.kernel, &[&self.kernel_group], light);
        // Steps 5 and 6.
        let tiling = self.tiling(frame)?;
        if self.settings.prediction != Prediction::Fixed {
            self.last.readback_wait_ms += frame.last_read_back_wait_ms();
        }
        // Steps 7 and 8, tile by tile.
        let light_frame = frame.scene.light_frames.get(light).ok_or_else(no_light)?;
        let slots = self.slots.get(light).ok_or_else(no_light)?;
        let constant_bias = self.settings.bias.constant_bias * light_frame.scene_diagonal;
        for (tile, slot) in tiling.tiles.iter().zip(slots) {
            let queue = &frame.gpu.queue;
            queue.write_buffer(&slot.frame, 0, bytemuck::bytes_of(&light_frame.tile_uniform(tile.uv_min, tile.uv_max)));
            let bias = DepthBiasUniform::new(constant_bias, self.settings.bias.slope_bias, tile.size.x, tile.size.y);
            queue.write_buffer(&slot.bias, 0, bytemuck::bytes_of(&bias));
            queue.write_buffer(&slot.settings, 0, bytemuck::bytes_of(&TileSettingsUniform::from(tile)));
            let class = self
                .tile_maps
                .iter()
                .position(|map| map.linear_depth.width() >= tile.size.max_element())
                .unwrap_or(self.tile_maps.len() - 1);
            let (Some(map), Some(filter_group)) = (self.tile_maps.get(class), slot.filter_groups.get(class)) else {
                return Err(Error::Technique { technique: NAME.into(), message: "no tile map".into() });
            };
            let region = Some((tile.size.x, tile.size.y));
            if self.settings.tile_culling {
                self.cull_to_tile(frame, &slot.frame_group);
                let draw = (&self.buffers.culled_indices, &self.buffers.tile_draw);
                map.encode_region_indirect(frame, &slot.frame_group, &slot.bias_group, region, "pvsm_tile_map", draw);
            } else {
                map.encode_region(frame, &slot.frame_group, &slot.bias_group, region, "pvsm_tile_map");
            }
            if self.settings.walks_hierarchy() {
                self.build_tile_pyramid(frame, slot, class, tile.size)?;
            }
            self.dispatch(frame, "pvsm_tile_filter", &self.pipelines.filter, &[&self.common_group, filter_group], light);
        }
        self.dispatch(frame, "pvsm_resolve", &self.pipelines.resolve, &[&self.common_group, &resolve_group], light);
        if self.last.tilings.len() <= light {
            self.last.tilings.resize(light + 1, Tiling::default());
        }
        self.last.tilings[light] = tiling;
        Ok(())
    }

    /// Tiles, their resolutions and the texels rendered into them, the finest tile's resolution,
    /// the cap; over the frame's lights, the pixels filtered, the share skipped as fully lit, the
    /// pixels whose filter's walk reached its cap and those no tile covered, and the mid-frame
    /// readbacks' wait for the GPU; with `count_reads`, each pass's counted work per pixel and the
    /// texels the filter read (`pvsm_texels_filtered`).
    fn diagnostics(&mut self, gpu: &GpuContext) -> Vec<(String, f64)> {
        let tiles: Vec<&Tile> = self.last.tilings.iter().flat_map(|t| &t.tiles).collect();
        let texels: f64 = tiles.iter().map(|t| f64::from(t.size.x) * f64::from(t.size.y)).sum();
        let mut out = vec![
            ("pvsm_tiles".to_owned(), tiles.len() as f64),
            ("pvsm_texels_rendered".to_owned(), texels),
            ("pvsm_largest_tile".to_owned(), tiles.iter().map(|t| f64::from(t.size.max_element())).fold(0.0, f64::max)),
            ("pvsm_tile_cap_reached".to_owned(), f64::from(u8::from(self.last.tilings.iter().any(|t| t.cap_reached)))),
            ("pvsm_clamped_tiles".to_owned(), tiles.iter().filter(|t| t.clamped).count() as f64),
            ("pvsm_finest_resolution".to_owned(), tiles.iter().map(|t| f64::from(t.resolution())).fold(0.0, f64::max)),
        ];
        for (index, tile) in tiles.iter().enumerate().take(16) {
            out.push((format!("pvsm_tile{index}_size"), f64::from(tile.size.x.max(tile.size.y))));
        }
        if let Ok(bytes) = ssm_core::readback::read_buffer(gpu, &self.buffers.counters, COUNTER_BYTES, "PVSM counters") {
            let counts: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
            if let [filtered, lit, capped, uncovered] = counts[..] {
                let total = f64::from(filtered) + f64::from(lit);
                if total > 0.0 {
                    out.push(("pvsm_lit_skipped".to_owned(), f64::from(lit) / total));
                }
                out.push(("pvsm_filtered_pixels".to_owned(), f64::from(filtered)));
                out.push(("pvsm_capped_pixels".to_owned(), f64::from(capped)));
                out.push(("pvsm_uncovered_pixels".to_owned(), f64::from(uncovered)));
            }
        }
        if self.settings.prediction != Prediction::Fixed {
            out.push(("pvsm_smtg_readback_wait_ms".to_owned(), self.last.readback_wait_ms));
        }
        // Step 7's culling: the share of the triangles the last tile drew.
        if self.settings.tile_culling
            && !tiles.is_empty()
            && self.cull_triangles > 0
            && let Ok(bytes) = ssm_core::readback::read_buffer(gpu, &self.buffers.tile_draw, 20, "PVSM tile draw")
        {
            let arguments: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
            if let Some(indices) = arguments.first() {
                out.push(("pvsm_last_tile_triangle_share".to_owned(), f64::from(*indices) / 3.0 / f64::from(self.cull_triangles)));
            }
        }
        let counted = self.read_counts.diagnostics(gpu);
        // The texels the filter's walks read over the frame: per evaluation times the evaluations
        // (a pixel's filter is evaluated once per tile it reaches); 0 when no pixel was filtered.
        let per_evaluation = counted.iter().find(|(key, _)| key == "pvsm_tile_filter_walk_texels_per_pixel").map(|(_, v)| *v);
        let evaluations = counted.iter().find(|(key, _)| key == "pvsm_tile_filter_walk_pixels").map(|(_, v)| *v);
        if self.counting {
            let texels_filtered = (per_evaluation.unwrap_or(0.0) * evaluations.unwrap_or(0.0)).round();
            out.push(("pvsm_texels_filtered".to_owned(), texels_filtered));
            // Fig. 10's cost per filtered pixel: the walk's reads (over every tile the filter
            // reaches) against the texels the pixel's own predicted resolution puts under its
            // filter. Above 1 where a tile is finer than the pixel needs (a neighbour in the tile
            // asked for more: the tile takes its cells' finest, Sec. 5.3) or where the hierarchy
            // cannot stop early; below where it settles whole blocks at once.
            let predicted = counted.iter().find(|(key, _)| key == "pvsm_predicted_texels_under_filter_per_pixel").map(|(_, v)| *v);
            let filtered_pixels = counted.iter().find(|(key, _)| key == "pvsm_predicted_pixels").map(|(_, v)| *v);
            if let (Some(predicted), Some(pixels)) = (predicted, filtered_pixels)
                && pixels > 0.0
                && predicted > 0.0
            {
                let per_pixel = texels_filtered / pixels;
                out.push(("pvsm_filter_reads_per_filtered_pixel".to_owned(), per_pixel));
                out.push(("pvsm_filter_reads_over_predicted".to_owned(), per_pixel / predicted));
            }
        }
        out.extend(counted);
        out
    }

    /// The shaders' counts (`READ_COUNTERS`). The tile maps' texels rendered (the paper's measure
    /// of the tiles' cost, Fig. 10) are the `pvsm_texels_rendered` diagnostic only: `pvsm_tile_map`
    /// is a render pass, whose fragments the pipeline statistics count and whose stores to its
    /// attachments the framework counts as target bytes.
    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ssm_core::ShaderWork>>> {
        self.read_counts.work(gpu)
    }

    /// `tiles`: each pixel shaded by the tile its filter's centre falls in (Fig. 10's inset), of the
    /// last light; `blocker_depth` and `predicted_resolution`: steps 3 and 4 per pixel;
    /// `low_res_coverage`: the texels of the conservative low-resolution map that hold a surface (1)
    /// or none (0).
    fn debug_outputs(&mut self, gpu: &GpuContext, requested: &[&str]) -> Result<Vec<ExtraImage>> {
        let mut images = Vec::new();
        let kernels = if requested.iter().any(|name| KERNEL_OUTPUTS.contains(name)) { self.read_kernels(gpu)? } else { Vec::new() };
        if requested.contains(&"tiles") {
            images.push(self.tile_image(&kernels));
        }
        if requested.contains(&"blocker_depth") {
            images.push(self.kernel_image(&kernels, "blocker_depth", false, |k| k.blocker_depth / k.depth.max(f32::MIN_POSITIVE)));
        }
        if requested.contains(&"predicted_resolution") {
            images.push(self.kernel_image(&kernels, "predicted_resolution", false, |k| {
                (1.0 / k.texel[0].min(k.texel[1]).max(f32::MIN_POSITIVE)).log2() / PREDICTED_RESOLUTION_SCALE
            }));
        }
        if requested.contains(&"low_res_coverage") {
            let side = self.settings.low_res_size;
            let depth: Vec<f32> =
                bytemuck::pod_collect_to_vec(&ssm_core::readback::read_texture(gpu, &self.low_res.texture, 4, "PVSM low-res map")?);
            let coverage = depth.iter().map(|d| f32::from(u8::from(*d < ssm_core::NO_SURFACE))).collect();
            images.push(ExtraImage { name: "low_res_coverage".into(), width: side, height: side, values: coverage, overlay: false });
        }
        Ok(images)
    }
}

impl PredictedVirtualShadowMaps {
    /// Step 3's per-pixel filters, of the last light rendered.
    fn read_kernels(&self, gpu: &GpuContext) -> Result<Vec<KernelRecord>> {
        let bytes = ssm_core::readback::read_buffer(gpu, &self.buffers.kernels, self.buffers.kernels.size(), "PVSM kernels")?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// A debug image of `name` with `value` of each pixel that has a filter, 0 elsewhere.
    fn kernel_image(&self, kernels: &[KernelRecord], name: &str, overlay: bool, value: impl Fn(&KernelRecord) -> f32) -> ExtraImage {
        let values = kernels.iter().map(|kernel| if kernel.is_active() { value(kernel) } else { 0.0 }).collect();
        ExtraImage { name: name.into(), width: self.width, height: self.height, values, overlay }
    }

    /// The `tiles` debug output.
    fn tile_image(&self, kernels: &[KernelRecord]) -> ExtraImage {
        let tiles = self.last.tilings.last().map(|t| t.tiles.clone()).unwrap_or_default();
        self.kernel_image(kernels, "tiles", true, |kernel| {
            let centre = Vec2::from_array(kernel.centre);
            tiles
                .iter()
                .position(|t| centre.cmpge(t.uv_min).all() && centre.cmplt(t.uv_max).all())
                .map_or(0.0, |index| (index + 1) as f32 / tiles.len() as f32)
        })
    }
}

/// The debug outputs read from step 3's kernel buffer.
const KERNEL_OUTPUTS: [&str; 3] = ["tiles", "blocker_depth", "predicted_resolution"];

/// `predicted_resolution` is log2 of the texels across the light frame ÷ this (1 = 16384²).
const PREDICTED_RESOLUTION_SCALE: f32 = 14.0;

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(PredictedVirtualShadowMaps::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    let settings = PvsmSettings::from_params(params)?;
    let features =
        if settings.conservative == Conservative::Hardware { wgpu::Features::CONSERVATIVE_RASTERIZATION } else { wgpu::Features::empty() };
    // Tile maps are clamped to the device's limit; only the low-resolution map must fit.
    Ok(Requirements { gbuffer: true, features, max_texture_size: settings.low_res_size, ..Requirements::NONE })
}

/// The paper's configuration, which every reproduction of its figures and tables runs: its
/// analytic anti-aliasing (Sec. 4.2), so that the prediction sizes texels for the footprint-averaged
/// visibility (Eq. 5) and `hard_texels` plays no part.
const PAPER_MODE: &str = "pvsm.antialiasing=true";

/// The ground truth that the paper's anti-aliased visibility is judged against: each pixel's
/// visibility averaged over its footprint.
const PAPER_TRUTH: &[&str] = &["reference.footprint=pixel"];

/// Shen et al.'s evaluations, as sweeps, in the paper's configuration.
const PRESETS: &[Preset] = &[
    Preset {
        name: "pvsm-fig10",
        summary: "Shen et al., Fig. 10: tiles, texels and frame time as the light grows from nearly a point (softer shadows need fewer tiles and render faster), in the paper's configuration (anti-aliasing on, against the pixel-footprint truth), on leaves, the forest's foliage and the dragon (scripts/fetch-models.sh); with --count-work, every pass's reads, and per filtered pixel the filter's reads against the texels the pixel's own predicted resolution puts under its filter (pvsm_filter_reads_per_filtered_pixel, pvsm_predicted_texels_under_filter_per_pixel in sweep.csv); pvsm_tiles and pvsm_texels_rendered besides",
        scenes: &["leaves", "forest", "models/dragon.toml"],
        varies: &["scene.light_scale=0.02,0.1,0.25,0.5,1,2", "pvsm.prediction=dynamic", PAPER_MODE],
        x_axis: "scene.light_scale",
        y_axis: "time",
        settings: PAPER_TRUTH,
        ..Preset::DEFAULT
    },
    Preset {
        name: "pvsm-fig11",
        summary: "Shen et al., Fig. 11: analytic anti-aliasing against 8×8 and 32×32 screen-space supersampling (a 1024² map: prediction=fixed, fixed_size=1024); compare the error of each against the 32×32 image",
        scenes: &["bar-grid"],
        varies: &["pvsm.antialiasing:supersampling=true:1,false:1,false:8,false:32", "pvsm.prediction:fixed_size=fixed:1024"],
        ..Preset::DEFAULT
    },
    Preset {
        name: "pvsm-table2",
        summary: "Shen et al., Table 2: a 782 K-triangle forest under a small and a large light (1:8, as 10 and 80), adaptive against one fixed 4096² map (anti-aliasing on, against the pixel-footprint truth), against 64 hard maps (multi-sm) and against VSSM on a 4096² map (the paper's Yang et al. row); frame time",
        scenes: &["forest:triangles=782000,trees=64"],
        varies: &[
            "scene.light_scale=0.25,2",
            "pvsm.prediction=dynamic,fixed",
            PAPER_MODE,
            "multi-sm.samples=64",
            "vssm.shadow_map_size=4096",
        ],
        x_axis: "scene.light_scale",
        y_axis: "time",
        settings: PAPER_TRUTH,
        ..Preset::DEFAULT
    },
    Preset {
        name: "pvsm-prediction",
        summary: "Shen et al., Fig. 8: the perceptual models (dynamic, static, linear) against a single fixed 4096² map, anti-aliasing on, against the pixel-footprint truth",
        scenes: &["leaves"],
        varies: &["pvsm.prediction=dynamic,static,linear,fixed", PAPER_MODE],
        settings: PAPER_TRUTH,
        ..Preset::DEFAULT
    },
];

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "predicted virtual soft shadow maps: perceptual resolution prediction, kd-tree tiles, texel-as-quad filtering, analytic anisotropic anti-aliasing",
    paper: "Shen, Guennebaud, Yang and Feng 2011, Predicted Virtual Soft Shadow Maps with High Quality Filtering (CGF 30(2), Eurographics)",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Frame,
    params: PvsmSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("max_tile_size=512,1024,2048,4096"),
    debug_outputs: &[
        DebugOutput {
            name: "tiles",
            doc: "each pixel shaded by the tile its filter's centre falls in, (index + 1) / tiles, of the last light; 0 where skipped as fully lit (Fig. 10's inset)",
            overlay: true,
        },
        DebugOutput {
            name: "blocker_depth",
            doc: "step 3's average occluder depth over the receiver's, z_o / z_y (both from the light's plane): 1 at the receiver (a hard shadow), small near the light (a wide penumbra); 0 where no filter is evaluated",
            overlay: false,
        },
        DebugOutput {
            name: "predicted_resolution",
            doc: "step 4's prediction (Eq. 5): log2 of the texels across the light frame the pixel asks for along its finer axis, / 14 (1 = 16384); 0 where no filter is evaluated",
            overlay: false,
        },
        DebugOutput {
            name: "low_res_coverage",
            doc: "the conservative low-resolution map's texels: 1 where a surface was drawn, 0 where none (its side, not the frame's)",
            overlay: false,
        },
    ],
    uniforms: &[
        UniformCheck { wgsl_struct: "PvsmSettings", wgsl_source: KERNEL_SHADER, imports: LOCAL_SHADERS, rust: PvsmSettingsUniform::LAYOUT },
        UniformCheck { wgsl_struct: "RasterSettings", wgsl_source: CONSERVATIVE_SHADER, imports: &[], rust: RasterSettingsUniform::LAYOUT },
        UniformCheck { wgsl_struct: "PyramidSettings", wgsl_source: PYRAMID_SHADER, imports: &[], rust: PyramidSettingsUniform::LAYOUT },
        UniformCheck { wgsl_struct: "TileSettings", wgsl_source: FILTER_SHADER, imports: LOCAL_SHADERS, rust: TileSettingsUniform::LAYOUT },
        UniformCheck { wgsl_struct: "CullSettings", wgsl_source: CULL_SHADER, imports: &[], rust: CullSettingsUniform::LAYOUT },
        UniformCheck { wgsl_struct: "PyramidLevel", wgsl_source: TILE_PYRAMID_SHADER, imports: &[], rust: TilePyramidLevelUniform::LAYOUT },
        UniformCheck { wgsl_struct: "TileSettings", wgsl_source: TILE_PYRAMID_SHADER, imports: &[], rust: TileSettingsUniform::LAYOUT },
        UniformCheck { wgsl_struct: "Kernel", wgsl_source: KERNEL_SHADER, imports: LOCAL_SHADERS, rust: KernelRecord::LAYOUT },
    ],
    limits: &[
        ssm_core::KnownLimit {
            case: "thin bars under a near-point light",
            mean_error: 0.12,
            reason: "where the penumbra is under a pixel the prediction asks for the lowest resolution without visible artefacts, a 1:1 mapping of pixels to texels for hard shadows (Shen et al. 2011, Sec. 5; here hard_texels = 4 texels a pixel): at 96x72 its finest tile resolves 1,269 texels across this frame (the diagnostic pvsm_finest_resolution) where hard's map has 2,048, and a sharp edge is placed only to within half a texel (0.0994 against 0.0212 where either shadows; hard_texels = 16 gives 0.0212, a fixed 4096² map 0.0014)",
        },
        ssm_core::KnownLimit {
            case: "light resting on the receiver",
            mean_error: 0.25,
            reason: "past the light frame's widest angle (84 degrees off the light's normal) the framework answers with a hard shadow from the light's centre (counted: pixels_beyond_frame): the predicted resolutions are gathered in one tile grid on the shadow map plane, whose kd-tree tiles are the virtual shadow maps (Shen et al. 2011, Sec. 5.2); that plane cannot reach 90 degrees off its axis, and a hemicube's side faces would need a grid, a pyramid and a kd-tree each",
        },
    ],
    paper_configuration: ssm_core::PaperConfiguration {
        // Sec. 4.2's analytic anti-aliasing, judged against the visibility averaged over each
        // pixel's footprint, which it computes.
        settings: &["antialiasing=true"],
        scenes: &["leaves", "bar-grid"],
        truth: &["footprint=pixel"],
        averaged_over: None,
    },
};

register_technique!(INFO);

#[cfg(test)]
mod tests {
    /// The kernel shader bounds predicted texels by the coarsest tile the kd-tree makes.
    #[test]
    fn the_shaders_smallest_tile_is_the_kd_trees() {
        let line = format!("const MIN_TILE_SIZE: f32 = {}.0;", super::kdtree::MIN_TILE_SIZE);
        assert!(super::KERNEL_SHADER.contains(&line), "pvsm_kernel.wgsl lacks `{line}`");
    }

    /// Each shader indexes its ReadCounts counters as `READ_COUNTERS` orders them.
    #[test]
    fn the_read_counters_are_numbered_as_the_shaders_number_them() {
        for (index, (name, shader, _, _)) in super::READ_COUNTERS.iter().enumerate() {
            let line = format!("const {name}: u32 = {index}u;");
            assert!(shader.contains(&line), "the shader counting {name} lacks `{line}`");
        }
    }

    /// Every pass that counts its reads counts their bytes too.
    #[test]
    fn every_pass_that_counts_reads_counts_their_bytes() {
        for (_, _, pass, unit) in super::READ_COUNTERS {
            if unit == "reads" {
                let bytes = super::READ_COUNTERS.iter().filter(|(_, _, p, u)| *p == pass && *u == "read_bytes").count();
                assert_eq!(bytes, 1, "{pass} counts reads, and {bytes} read_bytes counters");
            }
        }
    }

    /// The bytes the shaders count per read are the sizes of what they read: the textures' texel
    /// sizes (their formats here and in ssm-core) and the storage elements' (the records and cells
    /// the buffers are sized by).
    #[test]
    fn the_shaders_byte_sizes_are_the_formats_and_records() {
        use super::{FILTER_SHADER, KERNEL_SHADER, LOCAL_SHADERS, MIPS_SHADER, PYRAMID_SHADER, TILE_PYRAMID_SHADER};
        let texel = |format: wgpu::TextureFormat| u64::from(format.block_copy_size(None).unwrap());
        let low_res = texel(ssm_core::LightDepthMap::FORMAT);
        let tile_map = texel(ssm_core::LightDepthMap::FORMAT);
        let pyramid = texel(super::TILE_PYRAMID_FORMAT);
        let counts = texel(super::TILE_PYRAMID_COUNTS_FORMAT);
        let gbuffer = texel(ssm_core::GBuffer::POSITION_FORMAT);
        assert_eq!(gbuffer, texel(ssm_core::GBuffer::NORMAL_FORMAT));
        let common = LOCAL_SHADERS[0].1;
        let expected: [(&str, &str, u64); 13] = [
            (common, "GBUFFER_TEXEL_BYTES", gbuffer),
            (common, "KERNEL_RECORD_BYTES", super::KERNEL_BYTES),
            (MIPS_SHADER, "LOW_RES_TEXEL_BYTES", low_res),
            (KERNEL_SHADER, "LOW_RES_TEXEL_BYTES", low_res),
            (PYRAMID_SHADER, "SMTG_CELL_BYTES", super::SMTG_CELL_BYTES),
            (TILE_PYRAMID_SHADER, "TILE_MAP_TEXEL_BYTES", tile_map),
            (TILE_PYRAMID_SHADER, "TILE_PYRAMID_TEXEL_BYTES", pyramid),
            (TILE_PYRAMID_SHADER, "TILE_PYRAMID_COUNTS_TEXEL_BYTES", counts),
            (FILTER_SHADER, "TILE_MAP_TEXEL_BYTES", tile_map),
            (FILTER_SHADER, "TILE_PYRAMID_TEXEL_BYTES", pyramid),
            (FILTER_SHADER, "TILE_PYRAMID_COUNTS_TEXEL_BYTES", counts),
            (FILTER_SHADER, "ACCUMULATED_BYTES", super::ACCUMULATED_BYTES),
            (FILTER_SHADER, "CAPPED_BYTES", super::CAPPED_BYTES),
        ];
        for (shader, name, bytes) in expected {
            let line = format!("const {name}: u32 = {bytes}u;");
            assert!(shader.contains(&line), "a shader lacks `{line}`");
        }
    }

    /// The diagnostics read the counters in the order the WGSL numbers them.
    #[test]
    fn the_counters_are_numbered_as_the_shaders_number_them() {
        let common = super::LOCAL_SHADERS[0].1;
        assert!(common.contains(&format!("const COUNTERS: u32 = {}u;", super::COUNTER_NAMES.len())));
        for (index, name) in super::COUNTER_NAMES.iter().enumerate() {
            let line = format!("const {name}: u32 = {index}u;");
            assert!(common.contains(&line), "pvsm_common.wgsl lacks `{line}`");
        }
    }
}
