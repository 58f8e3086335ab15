//! Step 8 of Sec. 5.2 ("filtering" in the paper's Table 1; Sec. 4.1, Eq. 2, and Sec. 4.2): per
//! tile, first the two-layer min/max depth pyramid of its map (`pvsm_tile_pyramid`, one pass per
//! level, `shaders/pvsm/pvsm_filter_pyramid.wgsl`; not the paper's, whose filter walks every texel),
//! then every active pixel whose filter reaches the tile integrates the filter over the tile's
//! texels, each texel a quad weighted by its exact overlap with the filter, each one-texel-wide
//! column of the parallelogram taken as a box as Sec. 4.2 does (`pvsm_tile_filter`), walked
//! top-down over that pyramid (blocks settled at once) or texel by texel. Pixels keep Σ c·o and
//! Σ c, so that filters straddling tiles merge exactly (Sec. 5.2's V·A and A); `pvsm_resolve`
//! divides. Both passes: `shaders/pvsm/pvsm_filter.wgsl`.

use bytemuck::{Pod, Zeroable};
use glam::UVec2;
use ssm_core::passes::{bind_group, uniform_buffer};
use ssm_core::read_counts::ReadCounts;
use ssm_core::{Choice, Error, Frame, LightDepthMap, Result, UniformStruct};

use crate::gpu::TileSlot;
use crate::{NAME, PredictedVirtualShadowMaps, Tile};

/// Step 8 and the merge.
pub(crate) const FILTER_SHADER: &str = ssm_shaders::pvsm::PVSM_FILTER;
/// Step 8's min/max pyramid of a tile's map.
pub(crate) const FILTER_PYRAMID_SHADER: &str = ssm_shaders::pvsm::PVSM_FILTER_PYRAMID;

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

/// `TileSettings` of `shaders/pvsm/pvsm_filter.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct TileSettingsUniform {
    /// The tile's rectangle of the light frame's shadow-map coordinates.
    pub(crate) uv_min: [f32; 2],
    pub(crate) uv_max: [f32; 2],
    /// Texels of its map (the top-left part of the tile atlas).
    pub(crate) size: [f32; 2],
    pub(crate) _pad0: f32,
    pub(crate) _pad1: f32,
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

/// Bytes of one pixel's accumulated sums, (Σ c·o, Σ c) as a `vec2<f32>`.
pub(crate) const ACCUMULATED_BYTES: u64 = 8;
/// Bytes of one pixel's capped flag, a `u32`.
pub(crate) const CAPPED_BYTES: u64 = 4;

/// `PyramidLevel` of `shaders/pvsm/pvsm_filter_pyramid.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
#[wgsl(name = "PyramidLevel")]
pub struct TilePyramidLevelUniform {
    /// The level written (1 or more); its texels are in mip level - 1 of the pyramid.
    pub(crate) level: u32,
    /// 1: the level below is the tile map (one depth per texel); 0: a pyramid level.
    pub(crate) from_map: u32,
    pub(crate) _pad0: u32,
    pub(crate) _pad1: u32,
}

/// Step 8's two-layer min/max depth pyramid of the current tile's map: mip m holds level m + 1
/// (blocks of 2^(m+1) texels a side) as (nearest, farthest, near_max, far_min), its near
/// cluster's texels per child in a second texture of the same mips, for the tile's region only
/// (`pvsm_filter_pyramid.wgsl`). One
/// pair serves every tile, rebuilt before each tile's filter; its side is half the largest tile
/// map's side rounded up to a power of two, so that level l holds ceil(size / 2^l) texels of any
/// region.
pub(crate) struct TilePyramid {
    /// Every mip, for the filter.
    pub(crate) view: wgpu::TextureView,
    /// Every mip of the near counts, for the filter.
    pub(crate) counts_view: wgpu::TextureView,
    /// Per tile map size: level 1's group, reading that map.
    first_level: Vec<wgpu::BindGroup>,
    /// Levels 2, 3...: each reading the mip below.
    upper_levels: Vec<wgpu::BindGroup>,
}

/// The format of the tile pyramid's depths: (nearest, farthest, near_max, far_min).
pub(crate) const TILE_PYRAMID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The format of its near counts: the near cluster's texels in each of the four children.
pub(crate) const TILE_PYRAMID_COUNTS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

impl TilePyramid {
    /// The pyramid for maps up to `largest` texels a side, and its level groups; 1×1 textures that
    /// no pass reads when the filter does not walk it (`built` false).
    pub(crate) fn new(
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

impl PredictedVirtualShadowMaps {
    /// Step 8's min/max pyramid of the tile map of size class `class`, over the tile's `size`
    /// texels: levels 1 to ceil(log2 of the longer side), each a pass reading the one below.
    pub(crate) fn build_tile_pyramid(&self, frame: &mut Frame<'_>, slot: &TileSlot, class: usize, size: UVec2) -> Result<()> {
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

    /// With counting: the texels the filter's walks read over the frame (`pvsm_texels_filtered`),
    /// and per filtered pixel against the texels its predicted resolution puts under its filter.
    pub(crate) fn filter_work_diagnostics(&self, counted: &[(String, f64)]) -> Vec<(String, f64)> {
        let mut out = Vec::new();
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
        out
    }
}
