//! Steps 3 and 4 of Sec. 5.2, one pass (`pvsm_kernel_shape`, `shaders/pvsm/pvsm_kernel.wgsl`):
//! step 3 ("Z-avg" in the paper's Table 1; Sec. 4), per pixel, the average occluder depth on the
//! conservative map (no occluder: the pixel is fully lit and skipped from then on, Sec. 5.2's
//! fully-lit optimisation), the soft filter s_α, the pixel's footprint φ warped onto the map
//! (Fig. 5) and, with `antialiasing`, h = M(φ) ⊗ s_α (Sec. 4.2 and the appendix); step 4, the
//! perceptual prediction (Sec. 5.1, Eqs. 4 and 5; CPU twins in [`crate::prediction`]), of which
//! every cell of the shadow-map tile grid that the filter can read keeps the finest. Here: the
//! pixel's record that the pass writes, and the debug outputs read from it.

use bytemuck::{Pod, Zeroable};
use glam::Vec2;
use ssm_core::{ExtraImage, GpuContext, Result, UniformStruct};

use crate::PredictedVirtualShadowMaps;

/// Steps 3–4: the kernel shape and the prediction.
pub(crate) const KERNEL_SHADER: &str = ssm_shaders::pvsm::PVSM_KERNEL;

/// `Kernel` of `shaders/pvsm/pvsm_common.wgsl`: one pixel's filter from step 3, read back for the
/// debug outputs.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
#[wgsl(name = "Kernel")]
pub struct KernelRecord {
    /// Shadow-map coordinates of the pixel's point (before the normal offset).
    centre: [f32; 2],
    /// The filter h as a parallelogram (Sec. 4.2): half-axis u (any direction) and half-axis v,
    /// vertical (only its height), in shadow-map coordinates.
    u_axis: [f32; 2],
    v_height: f32,
    /// Light depth of the pixel's point.
    depth: f32,
    /// KERNEL_* flags.
    flags: u32,
    /// The largest normal offset the lookup point may get, world units.
    offset: f32,
    /// The texel size the prediction asked for along each axis (shadow-map coordinates): tiles finer
    /// than that (a neighbour needed more) are integrated at about this resolution.
    texel: [f32; 2],
    /// The average occluder depth z_o the filter's size came from (the receiver's own depth where no
    /// blocker was seen, with prediction = fixed).
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

/// Bytes of one [`KernelRecord`].
pub(crate) const KERNEL_BYTES: u64 = std::mem::size_of::<KernelRecord>() as u64;

/// The debug outputs read from step 3's kernel buffer.
const KERNEL_OUTPUTS: [&str; 3] = ["tiles", "blocker_depth", "predicted_resolution"];

/// `predicted_resolution` is log2 of the texels across the light frame ÷ this (1 = 16384²).
const PREDICTED_RESOLUTION_SCALE: f32 = 14.0;

impl PredictedVirtualShadowMaps {
    /// The debug outputs read from the kernel buffer, in this order where requested: `tiles`,
    /// `blocker_depth`, `predicted_resolution`.
    pub(crate) fn kernel_images(&self, gpu: &GpuContext, requested: &[&str]) -> Result<Vec<ExtraImage>> {
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
        Ok(images)
    }

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

#[cfg(test)]
mod tests {
    /// The kernel shader bounds predicted texels by the coarsest tile the kd-tree makes.
    #[test]
    fn the_shaders_smallest_tile_is_the_kd_trees() {
        let line = format!("const MIN_TILE_SIZE: f32 = {}.0;", crate::kdtree::MIN_TILE_SIZE);
        assert!(super::KERNEL_SHADER.contains(&line), "pvsm_kernel.wgsl lacks `{line}`");
    }
}
