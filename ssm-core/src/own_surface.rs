//! The surface's own share of the light, applied by the framework after every technique that
//! samples the light from its centre ([`LightSampling::Centre`](crate::LightSampling::Centre)).
//!
//! On a closed mesh, where the light straddles the surface's tangent plane, the solid hides the
//! part of the light behind that plane: the ground truth counts it (its rays that leave behind
//! the plane are blocked), but a map seen from the light's centre cannot, and every single-centre
//! technique was off by the same 0.33–0.38 there. The share in front of the plane is
//! known in closed form from the light's rectangle and the plane
//! (`light_share_in_front` in `shaders/common/light_frame.wgsl`), so the framework answers it for
//! every such technique alike, in one compute pass per light after the technique's
//! (`shaders/core/own_surface_share.wgsl`, which states the rule and its limit), and the error
//! left is each technique's own. Techniques that sample the light per point
//! ([`LightSampling::PerSample`](crate::LightSampling::PerSample)) apply the shared rules per
//! sample already and are not charged twice.

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::passes::{bind_group, bind_group_layout, compute_pipeline, visibility_storage_entry};
use crate::read_counts::ReadCounts;
use crate::shader::create_shader;
use crate::technique::TechniqueSetup;
use crate::work::ShaderWork;

/// The pass's name after the technique's: `<technique>_own_surface_share`.
pub const OWN_SURFACE_SHARE_PASS: &str = "own_surface_share";

/// The label of the own-surface share pass run after technique `technique`, as its timings and
/// counted work name it: `<technique>_own_surface_share`, the name's dashes made underscores as
/// the techniques' own pass labels have them (`multi_sm_accumulate`).
#[must_use]
pub fn own_surface_share_label(technique: &str) -> String {
    format!("{}_{OWN_SURFACE_SHARE_PASS}", technique.replace('-', "_"))
}

/// What the pass counts in a counting frame, in the order its shader indexes them (renamed after
/// the technique when read back): its texel reads, the bytes it stores, and the bytes its reads
/// fetched (the G-buffer's Rgba32Float texels, 16 bytes each, and the visibility's R32Float, 4).
const COUNTERS: &[(&str, &str)] =
    &[(OWN_SURFACE_SHARE_PASS, "reads"), (OWN_SURFACE_SHARE_PASS, "storage_bytes"), (OWN_SURFACE_SHARE_PASS, "read_bytes")];

/// The pass, built for one technique's visibility targets.
pub(crate) struct OwnSurfaceShare {
    /// `<technique>_own_surface_share`.
    label: String,
    pipeline: wgpu::ComputePipeline,
    gbuffer_bind_group: wgpu::BindGroup,
    /// Per light: its visibility target (read-write) and the counters.
    groups: Vec<wgpu::BindGroup>,
    read_counts: ReadCounts,
    width: u32,
    height: u32,
}

impl OwnSurfaceShare {
    pub(crate) fn new(setup: &TechniqueSetup<'_>, technique: &str) -> Result<Self> {
        let gpu = setup.gpu;
        let gbuffer = setup.shared.gbuffer(technique)?;
        let read_counts = ReadCounts::with_units(&gpu.device, "own_surface_share_read_counts", COUNTERS, setup.count_work);
        // The counting frame's pipeline has the counting compiled in (a pipeline constant).
        let key = if setup.count_work { "own_surface_share_counting_pipeline" } else { "own_surface_share_pipeline" };
        let constants = read_counts.pipeline_constants();
        let pipeline = gpu.cached_compute_pipeline(key, |gpu| {
            let module = create_shader(gpu, "own_surface_share_shader", ssm_shaders::core::OWN_SURFACE_SHARE)?;
            let own_layout =
                bind_group_layout(&gpu.device, "own_surface_share_own_layout", &[visibility_storage_entry(0), ReadCounts::layout_entry(1)]);
            Ok(compute_pipeline(
                &gpu.device,
                key,
                &module,
                "own_surface_share",
                &[gpu.uniform_layout(), gpu.gbuffer_layout(), &own_layout],
                &constants,
            ))
        })?;
        let own_layout = pipeline.get_bind_group_layout(2);
        let groups = setup
            .outputs
            .iter()
            .enumerate()
            .map(|(light, output)| {
                bind_group(
                    &gpu.device,
                    &format!("own_surface_share_bind_group_{light}"),
                    &own_layout,
                    &[wgpu::BindingResource::TextureView(output), read_counts.buffer().as_entire_binding()],
                )
            })
            .collect();
        Ok(Self {
            label: own_surface_share_label(technique),
            pipeline,
            gbuffer_bind_group: gbuffer.bind_group.clone(),
            groups,
            read_counts,
            width: setup.scene.width,
            height: setup.scene.height,
        })
    }

    /// Records the pass for `light`, after the technique's.
    pub(crate) fn encode(&self, frame: &mut Frame<'_>, light: usize) -> Result<()> {
        let no_light = || Error::Technique { technique: self.label.clone(), message: format!("no light {light}") };
        let group = self.groups.get(light).ok_or_else(no_light)?;
        let light_frame = frame.scene.light_bind_groups.get(light).ok_or_else(no_light)?;
        self.read_counts.clear(frame, light);
        let mut pass = frame.compute_pass(&self.label);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.gbuffer_bind_group, &[]);
        pass.set_bind_group(2, group, &[]);
        pass.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
        Ok(())
    }

    /// What the pass counted in the last frame, under its label; `None` when not counting.
    pub(crate) fn work(&self, gpu: &GpuContext) -> Result<Option<Vec<ShaderWork>>> {
        let mut work = self.read_counts.work(gpu)?;
        for pass in work.iter_mut().flatten() {
            pass.pass.clone_from(&self.label);
        }
        Ok(work)
    }
}

#[cfg(test)]
mod tests {
    use crate::{GBuffer, VISIBILITY_FORMAT};

    /// The shader counts each texel it reads at its format's size.
    #[test]
    fn the_shaders_texel_bytes_are_the_formats_sizes() {
        let constants = [
            ("GBUFFER_TEXEL_BYTES", GBuffer::POSITION_FORMAT),
            ("GBUFFER_TEXEL_BYTES", GBuffer::NORMAL_FORMAT),
            ("VISIBILITY_TEXEL_BYTES", VISIBILITY_FORMAT),
        ];
        let missing = crate::read_counts::missing_texel_byte_constants(ssm_shaders::core::OWN_SURFACE_SHARE, &constants);
        assert!(missing.is_empty(), "own_surface_share.wgsl lacks {missing:?}");
    }
}
