//! Baseline: the average of K hard shadow maps rendered from stratified points
//! on the rectangular light. It converges to the exact visibility as K grows
//! (up to each map's own discretisation), at K times the cost of a hard
//! shadow: the reference of Shen et al. (2011, Table 2) and of Buades et al.
//! (2015, Fig. 13).

use std::collections::HashMap;

use bytemuck::{Pod, Zeroable};
use glam::Vec2;
use ssm_core::passes::{color_attachment, compute_pipeline, texture_entry, uniform_entry, visibility_storage_entry};
use ssm_core::shader::create_shader;
use ssm_core::ssm_scene::RectLight;
use ssm_core::{
    Error, Frame, LightDepthMap, LightFrame, LightFrameUniform, ParamKind, ParamSpec, Result, ShadowMapSettings, ShadowTechnique,
    TechniqueInfo, TechniqueKind, TechniqueSetup, register_technique,
};
use wgpu::util::DeviceExt;

/// The registered name.
pub const NAME: &str = "multi-sm";

/// Parameters of [`MultiShadowMaps`].
pub const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "samples",
        kind: ParamKind::Int { default: 16, min: 1, max: 1024 },
        doc: "K, the number of shadow maps: a perfect square, one per stratum of a √K×√K grid on the light",
    },
    ShadowMapSettings::size_param(1024),
    ShadowMapSettings::BIAS_PARAMS[0],
    ShadowMapSettings::BIAS_PARAMS[1],
    ShadowMapSettings::BIAS_PARAMS[2],
];

/// The accumulation settings, as `shaders/multi-sm/multi_sm.wgsl` reads them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct MultiSmSettingsUniform {
    weight: f32,
    normal_offset: f32,
    padding: [f32; 2],
}

/// The centres of the strata of a `per_axis` × `per_axis` grid on the light, in `[-1, 1]²`.
#[must_use]
pub fn stratum_centres(per_axis: u32) -> Vec<Vec2> {
    let n = per_axis.max(1);
    (0..n * n).map(|k| (Vec2::new((k % n) as f32, (k / n) as f32) + 0.5) / n as f32 * 2.0 - Vec2::ONE).collect()
}

/// K hard shadow maps from stratified points on the light, averaged.
pub struct MultiShadowMaps {
    depth_map: LightDepthMap,
    /// Per light, per sample: the frame of a point light at the sample.
    sample_frames: Vec<Vec<wgpu::BindGroup>>,
    accumulate: wgpu::ComputePipeline,
    gbuffer_bind_group: wgpu::BindGroup,
    own_layout: wgpu::BindGroupLayout,
    settings_buffer: wgpu::Buffer,
    map_view: wgpu::TextureView,
    /// Per light: the group binding the shadow map, the settings and that light's target (made on first use).
    own_groups: HashMap<usize, wgpu::BindGroup>,
    width: u32,
    height: u32,
}

impl MultiShadowMaps {
    /// Builds the sample frames, the depth map and the accumulation pipeline.
    ///
    /// # Errors
    /// A parameter error, K not a perfect square, or a GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let params = setup.params;
        let samples = u32::try_from(params.int("samples")?).unwrap_or(1);
        let per_axis = samples.isqrt();
        if per_axis * per_axis != samples {
            return Err(Error::Technique {
                technique: NAME.into(),
                message: format!("samples = {samples} is not a perfect square (1, 4, 9, 16, ...): the strata form a √K×√K grid"),
            });
        }
        let map_settings = ShadowMapSettings::from_params(params)?;
        let device = &setup.gpu.device;
        let gbuffer = setup.shared.gbuffer(NAME)?;
        let depth_map = map_settings.depth_map(setup, "multi_sm_shadow_map")?;
        let bounds = setup.scene.bounds;
        let sample_frames = setup
            .scene
            .light_frames
            .iter()
            .enumerate()
            .map(|(light_index, frame)| {
                stratum_centres(per_axis)
                    .iter()
                    .enumerate()
                    .map(|(k, s)| {
                        let light = frame.light;
                        let point_light = RectLight { centre: light.point(s.x, s.y), half_size: Vec2::ZERO, ..light };
                        let uniform = LightFrameUniform::from(&LightFrame::fit(&point_light, &bounds));
                        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some(&format!("multi_sm_sample_frame_{light_index}_{k}")),
                            contents: bytemuck::bytes_of(&uniform),
                            usage: wgpu::BufferUsages::UNIFORM,
                        });
                        device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some(&format!("multi_sm_sample_frame_bind_group_{light_index}_{k}")),
                            layout: &setup.scene.uniform_layout,
                            entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
                        })
                    })
                    .collect()
            })
            .collect();
        let settings =
            MultiSmSettingsUniform { weight: 1.0 / samples as f32, normal_offset: map_settings.normal_offset, padding: [0.0; 2] };
        let settings_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("multi_sm_settings_uniform"),
            contents: bytemuck::bytes_of(&settings),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let own_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("multi_sm_own_layout"),
            entries: &[texture_entry(0), uniform_entry(1), visibility_storage_entry(2)],
        });
        let module = create_shader(setup.gpu, "multi_sm_shader", include_str!("../../../shaders/multi-sm/multi_sm.wgsl"))?;
        let accumulate = compute_pipeline(
            device,
            "multi_sm_accumulate_pipeline",
            &module,
            "multi_sm_accumulate",
            &[&setup.scene.uniform_layout, &gbuffer.layout, &own_layout],
        );
        Ok(Self {
            map_view: depth_map.linear_depth_view.clone(),
            depth_map,
            sample_frames,
            accumulate,
            gbuffer_bind_group: gbuffer.bind_group.clone(),
            own_layout,
            settings_buffer,
            own_groups: HashMap::new(),
            width: setup.scene.width,
            height: setup.scene.height,
        })
    }
}

impl ShadowTechnique for MultiShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let device = &frame.gpu.device;
        let own_group = self.own_groups.entry(light).or_insert_with(|| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&format!("multi_sm_own_bind_group_{light}")),
                layout: &self.own_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&self.map_view) },
                    wgpu::BindGroupEntry { binding: 1, resource: self.settings_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(output) },
                ],
            })
        });
        // The sum starts at 0, not at the framework's 1.
        drop(frame.render_pass("multi_sm_clear", &[color_attachment(output, Some(wgpu::Color::TRANSPARENT))], None));
        let frames = self
            .sample_frames
            .get(light)
            .ok_or_else(|| Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
        for sample_frame in frames {
            self.depth_map.encode_with(frame, sample_frame);
            let mut pass = frame.compute_pass("multi_sm_accumulate");
            pass.set_pipeline(&self.accumulate);
            pass.set_bind_group(0, sample_frame, &[]);
            pass.set_bind_group(1, &self.gbuffer_bind_group, &[]);
            pass.set_bind_group(2, &*own_group, &[]);
            pass.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
        }
        Ok(())
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(MultiShadowMaps::new(setup)?))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "average of K hard shadow maps from stratified points on the light (baseline; converges as K grows)",
    paper: "Heckbert and Herf 1997, Simulating soft shadows with graphics hardware (the reference of Shen et al. 2011 and Buades et al. 2015)",
    kind: TechniqueKind::Realtime,
    params: PARAMS,
    requirements: ShadowMapSettings::screen_space_requirements,
    create,
};

register_technique!(INFO);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strata_centres_tile_the_light() {
        assert_eq!(stratum_centres(1), vec![Vec2::ZERO]);
        let four = stratum_centres(2);
        assert_eq!(four, vec![Vec2::new(-0.5, -0.5), Vec2::new(0.5, -0.5), Vec2::new(-0.5, 0.5), Vec2::new(0.5, 0.5)]);
        let sixteen = stratum_centres(4);
        assert_eq!(sixteen.len(), 16);
        assert!(sixteen.iter().sum::<Vec2>().length() < 1e-5, "centred on the light");
    }
}
