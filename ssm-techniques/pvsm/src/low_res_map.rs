//! Step 2 of Sec. 5.2 ("low res. SM" in the paper's Table 1): a `low_res_size`² shadow map
//! rendered *conservatively*, so that no occluder thinner than a texel is lost (the adapter's
//! `CONSERVATIVE_RASTERIZATION` where it has it; otherwise the paper's choice, Hasselgren et al.
//! 2005, Alg. 2), then its minimum-depth mip chain; step 3's blocker search and the fully-lit test
//! read them. Passes `pvsm_low_res_map` (`shaders/pvsm/pvsm_low_res_map.wgsl`) and
//! `pvsm_low_res_mips` (`shaders/pvsm/pvsm_low_res_map_mips.wgsl`).

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::bind_group;
use ssm_core::read_counts::ReadCounts;
use ssm_core::{Choice, ExtraImage, Frame, GpuContext, LightDepthMap, Result, UniformStruct};

use crate::PredictedVirtualShadowMaps;

/// Step 2: the conservative low-resolution map.
pub(crate) const LOW_RES_MAP_SHADER: &str = ssm_shaders::pvsm::PVSM_LOW_RES_MAP;
/// Step 2's minimum-depth mip chain.
pub(crate) const LOW_RES_MAP_MIPS_SHADER: &str = ssm_shaders::pvsm::PVSM_LOW_RES_MAP_MIPS;

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

/// `RasterSettings` of `shaders/pvsm/pvsm_low_res_map.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct RasterSettingsUniform {
    /// Half a texel in NDC (1 / side along each axis).
    pub(crate) half_texel: [f32; 2],
    /// Side of the map, texels.
    pub(crate) size: [f32; 2],
    /// 1: enlarge triangles (software conservative rasterization); 0: the rasterizer is conservative itself.
    pub(crate) enlarge: u32,
    pub(crate) _pad0: u32,
    pub(crate) _pad1: u32,
    pub(crate) _pad2: u32,
}

/// The conservative low-resolution map and its minimum-depth mip chain.
pub(crate) struct LowResMap {
    texture: wgpu::Texture,
    /// Level 0, rendered into.
    level0: wgpu::TextureView,
    depth: wgpu::TextureView,
    /// Per level from 1: the group reading the level above and writing this one, and its size.
    mips: Vec<(wgpu::BindGroup, u32)>,
    /// Every level, for the blocker search.
    pub(crate) all_levels: wgpu::TextureView,
}

impl LowResMap {
    pub(crate) fn new(device: &wgpu::Device, side: u32, mip_layout: &wgpu::BindGroupLayout, read_counts: &ReadCounts) -> Self {
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

impl PredictedVirtualShadowMaps {
    /// Step 2: the conservative low-resolution map of `light`, then its minimum-depth mip chain.
    pub(crate) fn render_low_res_map(&self, frame: &mut Frame<'_>, light: usize) {
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
    }

    /// The `low_res_coverage` debug output: the texels of the conservative low-resolution map that
    /// hold a surface (1) or none (0).
    pub(crate) fn low_res_coverage(&self, gpu: &GpuContext) -> Result<ExtraImage> {
        let side = self.settings.low_res_size;
        let depth: Vec<f32> =
            bytemuck::pod_collect_to_vec(&ssm_core::readback::read_texture(gpu, &self.low_res.texture, 4, "PVSM low-res map")?);
        let coverage = depth.iter().map(|d| f32::from(u8::from(*d < ssm_core::NO_SURFACE))).collect();
        Ok(ExtraImage { name: "low_res_coverage".into(), width: side, height: side, values: coverage, overlay: false })
    }
}
