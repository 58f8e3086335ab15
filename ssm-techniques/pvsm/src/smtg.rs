//! Step 5 of Sec. 5.2 ("SMTG & tiling" in the paper's Table 1, with step 6): the max pyramid of
//! the shadow-map tile grid (SMTG) that step 4 filled, built on the GPU (the paper's one change to
//! Giegl and Wimmer 2007; pass `pvsm_smtg_pyramid`, `shaders/pvsm/pvsm_smtg.wgsl`) and read back in
//! the middle of the frame (`pvsm_smtg_readback`, a CPU scope) for step 6's kd-tree
//! ([`crate::kdtree`]).

use bytemuck::{Pod, Zeroable};
use glam::{UVec2, Vec2};
use ssm_core::{Error, Frame, Result, UniformStruct};

use crate::kdtree::{self, Pyramid, Tile, Tiling};
use crate::{NAME, PredictedVirtualShadowMaps, Prediction};

/// Step 5: the grid's pyramid.
pub(crate) const SMTG_SHADER: &str = ssm_shaders::pvsm::PVSM_SMTG;

/// `PyramidSettings` of `shaders/pvsm/pvsm_smtg.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct PyramidSettingsUniform {
    /// Side of level 0, a power of two.
    pub(crate) grid_size: u32,
    pub(crate) _pad0: u32,
    pub(crate) _pad1: u32,
    pub(crate) _pad2: u32,
}

/// Bytes of one cell of the tile grid (its resolutions along u and v, two u32) and of its pyramid
/// (the same, as a `vec2<f32>`).
pub(crate) const SMTG_CELL_BYTES: u64 = 8;

impl PredictedVirtualShadowMaps {
    /// Steps 5 and 6: the pyramid, its readback, the kd-tree.
    pub(crate) fn tiling(&self, frame: &mut Frame<'_>) -> Result<Tiling> {
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
