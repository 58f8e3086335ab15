//! Shen, Guennebaud, Yang and Feng, *Predicted Virtual Soft Shadow Maps with
//! High Quality Filtering*, Computer Graphics Forum 30(2) (Eurographics
//! 2011).
//!
//! The eight steps of the paper's Sec. 5.2, each a named, timed pass, and each
//! step's host code in the module named after it, beside its shaders
//! (`shaders/pvsm/pvsm_<module>*.wgsl`); what several steps share (layouts,
//! pipelines, buffers) is built in one module of its own (`gpu.rs`):
//! 1. the G-buffer (shared);
//! 2. a low-resolution shadow map rendered conservatively (`pvsm_low_res_map`),
//!    and its minimum-depth mip chain (`pvsm_low_res_mips`; [`low_res_map`]);
//! 3. per pixel, the average occluder depth, the soft-shadowing filter, the
//!    pixel's warped footprint and the anti-aliased filter h (`pvsm_kernel_shape`;
//!    [`kernel`]);
//! 4. in the same pass, the perceptual resolution prediction and its
//!    accumulation into the shadow-map tile grid ([`prediction`]: its CPU twins);
//! 5. the grid's pyramid on the GPU (`pvsm_smtg_pyramid`), read back in the
//!    middle of the frame (`pvsm_smtg_readback`, the mapping timed on the CPU;
//!    the wait for the GPU before it is the `pvsm_smtg_readback_wait_ms`
//!    diagnostic; [`smtg`]);
//! 6. the kd-tree on the CPU (`pvsm_kdtree`, [`kdtree`]);
//! 7. per tile, a shadow map of the predicted resolution (`pvsm_tile_map`;
//!    [`tile_maps`]);
//! 8. per tile, the min/max depth pyramid of its map (`pvsm_tile_pyramid`)
//!    and the texel-as-quad filtering of the pixels whose filter reaches it,
//!    walked top-down over that pyramid (`pvsm_tile_filter`), merged per
//!    pixel, then the ratio (`pvsm_resolve`; [`filter`]).
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

pub mod filter;
mod gpu;
pub mod kdtree;
pub mod kernel;
pub mod low_res_map;
pub mod prediction;
pub mod smtg;
pub mod tile_maps;
#[cfg(test)]
mod wgsl_tests;

use bytemuck::{Pod, Zeroable};
use ssm_core::read_counts::ReadCounts;
use ssm_core::{
    DebugOutput, DepthBiasUniform, Error, ExtraImage, Frame, GpuContext, LightDepthMap, ParamValues, Preset, ReceiverModel, Requirements,
    Result, Settings, ShadowMapBias, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct,
    register_technique,
};

pub use filter::{FilterTexels, FilterWalk, Integration, TilePyramidLevelUniform, TileSettingsUniform};
pub use kdtree::{Pyramid, Tile, Tiling};
pub use kernel::KernelRecord;
pub use low_res_map::{Conservative, RasterSettingsUniform};
pub use prediction::Prediction;
pub use smtg::PyramidSettingsUniform;
pub use tile_maps::CullSettingsUniform;

use filter::{FILTER_PYRAMID_SHADER, FILTER_SHADER, TilePyramid};
use gpu::{Buffers, LOCAL_SHADERS, Pipelines, TileSlot};
use kernel::KERNEL_SHADER;
use low_res_map::{LOW_RES_MAP_SHADER, LowResMap};
use smtg::SMTG_SHADER;
use tile_maps::TILE_MAPS_SHADER;

/// The registered name.
pub const NAME: &str = "pvsm";

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
    /// Side of the shadow-map tile grid (SMTG), cells.
    grid_size: u32,
    /// Samples per axis of the blocker search on the low-resolution map.
    blocker_kernel: u32,
    /// ρ model: 0 dynamic, 1 static, 2 linear, 3 fixed (no prediction).
    prediction: u32,
    /// 1: the filter is convolved with the pixel's footprint (Sec. 4.2).
    antialiasing: u32,
    /// k: k×k screen-space sub-samples per pixel (the supersampling of Fig. 11); 1: none.
    supersampling: u32,
    /// 1: texels compare with the receiver's tangent plane along their ray; 0: with its depth.
    receiver_plane: u32,
    /// Normal offset of the lookup point, in texels of the resolution the pixel asked for.
    normal_offset: f32,
    /// Constant depth bias, a fraction of the scene's diagonal (scene_length).
    constant_bias: f32,
    /// Side of the shadow map of prediction = fixed, texels.
    fixed_size: f32,
    /// 1: each texel a point sample, weighted fully when its centre is inside the filter (classic
    /// PCF, Fig. 4(a)); 0: each texel a quad weighted by its exact overlap (Eq. 2, Fig. 4(c)).
    point_samples: u32,
    /// 1: a tile finer than the pixel's predicted texel is read at every k-th texel (k the ratio);
    /// 0: at every texel (the paper).
    predicted_stride: u32,
    /// With antialiasing off: texels per pixel, along each axis, for a shadow sharper than a pixel.
    hard_texels: f32,
    /// 1: the filter reads every texel under it (filter_walk = texels); 0: it walks the tile's min/max
    /// pyramid (filter_walk = hierarchy), the same sum.
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
        self.render_low_res_map(frame, light);
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
            let class = self.tile_map_class(tile.size);
            let (Some(map), Some(filter_group)) = (self.tile_maps.get(class), slot.filter_groups.get(class)) else {
                return Err(Error::Technique { technique: NAME.into(), message: "no tile map".into() });
            };
            let region = Some((tile.size.x, tile.size.y));
            self.render_tile_map(frame, map, slot, region);
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
        let mut out = kdtree::tiling_diagnostics(&self.last.tilings);
        out.extend(self.counter_diagnostics(gpu));
        if self.settings.prediction != Prediction::Fixed {
            out.push(("pvsm_smtg_readback_wait_ms".to_owned(), self.last.readback_wait_ms));
        }
        // Step 7's culling: the share of the triangles the last tile drew.
        out.extend(self.culling_diagnostics(gpu));
        let counted = self.read_counts.diagnostics(gpu);
        out.extend(self.filter_work_diagnostics(&counted));
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
        let mut images = self.kernel_images(gpu, requested)?;
        if requested.contains(&"low_res_coverage") {
            images.push(self.low_res_coverage(gpu)?);
        }
        Ok(images)
    }
}

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
        UniformCheck {
            wgsl_struct: PvsmSettingsUniform::WGSL_NAME,
            wgsl_source: KERNEL_SHADER,
            imports: LOCAL_SHADERS,
            rust: PvsmSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: RasterSettingsUniform::WGSL_NAME,
            wgsl_source: LOW_RES_MAP_SHADER,
            imports: LOCAL_SHADERS,
            rust: RasterSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: PyramidSettingsUniform::WGSL_NAME,
            wgsl_source: SMTG_SHADER,
            imports: LOCAL_SHADERS,
            rust: PyramidSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: TileSettingsUniform::WGSL_NAME,
            wgsl_source: FILTER_SHADER,
            imports: LOCAL_SHADERS,
            rust: TileSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: CullSettingsUniform::WGSL_NAME,
            wgsl_source: TILE_MAPS_SHADER,
            imports: LOCAL_SHADERS,
            rust: CullSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: TilePyramidLevelUniform::WGSL_NAME,
            wgsl_source: FILTER_PYRAMID_SHADER,
            imports: LOCAL_SHADERS,
            rust: TilePyramidLevelUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: TileSettingsUniform::WGSL_NAME,
            wgsl_source: FILTER_PYRAMID_SHADER,
            imports: LOCAL_SHADERS,
            rust: TileSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: KernelRecord::WGSL_NAME,
            wgsl_source: KERNEL_SHADER,
            imports: LOCAL_SHADERS,
            rust: KernelRecord::LAYOUT,
        },
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
