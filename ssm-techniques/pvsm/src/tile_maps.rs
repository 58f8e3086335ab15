//! Step 7 of Sec. 5.2 ("high res. SMs" in the paper's Table 1): per tile of the kd-tree, a depth
//! map of the predicted resolution over the tile's rectangle (`pvsm_tile_map`, drawn by
//! ssm-core's `LightDepthMap` into the smallest of the power-of-two tile maps that holds it). With
//! `tile_culling`, a compute pass first keeps the triangles that can touch the tile's sub-frustum
//! and compacts their indices for an indirect draw (`pvsm_tile_cull`,
//! `shaders/pvsm/pvsm_tile_maps.wgsl`).

use bytemuck::{Pod, Zeroable};
use glam::UVec2;
use ssm_core::passes::{bind_group, uniform_buffer};
use ssm_core::{Frame, Geometry, GpuContext, LightDepthMap, LightDepthMapDesc, Result, TechniqueSetup, UniformStruct};

use crate::PredictedVirtualShadowMaps;
use crate::gpu::{Buffers, Layouts, TileSlot};

/// Step 7's culling to the tile.
pub(crate) const TILE_MAPS_SHADER: &str = ssm_shaders::pvsm::PVSM_TILE_MAPS;

/// `CullSettings` of `shaders/pvsm/pvsm_tile_maps.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct CullSettingsUniform {
    /// First index of the map's range in the scene's index buffer.
    first_index: u32,
    /// Triangles in that range.
    triangle_count: u32,
    _pad0: u32,
    _pad1: u32,
}

/// The sides of the tile maps: 64, 128, ... below `largest`, then `largest`.
fn tile_map_sides(largest: u32) -> Vec<u32> {
    let mut sides: Vec<u32> = (6..15).map(|k| 1u32 << k).take_while(|side| *side < largest).collect();
    sides.push(largest);
    sides
}

impl PredictedVirtualShadowMaps {
    /// Step 7's depth maps: one per power-of-two side up to the atlas's, each tile drawn into the
    /// smallest that holds it.
    pub(crate) fn tile_maps(setup: &TechniqueSetup<'_>, atlas_side: u32) -> Result<Vec<LightDepthMap>> {
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

    /// Step 7's culling resources: the bind group of the scene's triangles in the tile maps' index
    /// range, and how many triangles that is.
    pub(crate) fn cull_group(
        setup: &TechniqueSetup<'_>,
        layouts: &Layouts,
        buffers: &Buffers,
        tile_maps: &[LightDepthMap],
    ) -> (wgpu::BindGroup, u32) {
        let device = &setup.gpu.device;
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
        (cull_group, cull_triangles)
    }

    /// The size class of a tile of `size` texels: the smallest tile map that holds it, else the largest.
    pub(crate) fn tile_map_class(&self, size: UVec2) -> usize {
        self.tile_maps.iter().position(|map| map.linear_depth.width() >= size.max_element()).unwrap_or(self.tile_maps.len() - 1)
    }

    /// Step 7 for one tile: its map, drawn over its `region` from the triangles step 7's culling
    /// kept (with `tile_culling`), or from every triangle.
    pub(crate) fn render_tile_map(&self, frame: &mut Frame<'_>, map: &LightDepthMap, slot: &TileSlot, region: Option<(u32, u32)>) {
        if self.settings.tile_culling {
            self.cull_to_tile(frame, &slot.frame_group);
            let draw = (&self.buffers.culled_indices, &self.buffers.tile_draw);
            map.encode_region_indirect(frame, &slot.frame_group, &slot.bias_group, region, "pvsm_tile_map", draw);
        } else {
            map.encode_region(frame, &slot.frame_group, &slot.bias_group, region, "pvsm_tile_map");
        }
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

    /// Step 7's culling: the share of the triangles the last tile drew.
    pub(crate) fn culling_diagnostics(&self, gpu: &GpuContext) -> Option<(String, f64)> {
        let tiles = self.last.tilings.iter().any(|t| !t.tiles.is_empty());
        if self.settings.tile_culling
            && tiles
            && self.cull_triangles > 0
            && let Ok(bytes) = ssm_core::readback::read_buffer(gpu, &self.buffers.tile_draw, 20, "PVSM tile draw")
        {
            let arguments: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
            if let Some(indices) = arguments.first() {
                return Some(("pvsm_last_tile_triangle_share".to_owned(), f64::from(*indices) / 3.0 / f64::from(self.cull_triangles)));
            }
        }
        None
    }
}
