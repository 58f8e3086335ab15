//! Baseline: hard shadow mapping (Williams 1978, *Casting curved shadows on
//! curved surfaces*), with a slope-scaled depth bias.
//!
//! One depth map from the light's centre over all geometry, then one
//! comparison per pixel: visibility is 0 or 1. It is the fast end of every
//! speed/accuracy plot and the limit every soft technique must reach as the
//! light shrinks to a point.

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{texture_entry, uniform_entry};
use ssm_core::shader::create_shader;
use ssm_core::{
    Frame, LightDepthMap, ParamSpec, Result, ScreenPass, ShadowMapSettings, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup,
    VISIBILITY_FORMAT, register_technique,
};
use wgpu::util::DeviceExt;

/// The registered name.
pub const NAME: &str = "hard";

/// Parameters of [`HardShadowMapping`].
pub const PARAMS: &[ParamSpec] = &[
    ShadowMapSettings::size_param(2048),
    ShadowMapSettings::BIAS_PARAMS[0],
    ShadowMapSettings::BIAS_PARAMS[1],
    ShadowMapSettings::BIAS_PARAMS[2],
];

/// The lookup settings, as `shaders/hard/hard.wgsl` reads them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct HardSettingsUniform {
    normal_offset: f32,
    padding: [f32; 3],
}

/// Hard shadow mapping.
pub struct HardShadowMapping {
    depth_map: LightDepthMap,
    lookup: ScreenPass,
    map_bind_group: wgpu::BindGroup,
}

impl HardShadowMapping {
    /// Builds the depth map and the lookup pipeline.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = ShadowMapSettings::from_params(setup.params)?;
        let device = &setup.gpu.device;
        let depth_map = settings.depth_map(setup, "hard_shadow_map")?;
        let uniform = HardSettingsUniform { normal_offset: settings.normal_offset, padding: [0.0; 3] };
        let settings_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("hard_settings_uniform"),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let map_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("hard_map_layout"),
            entries: &[texture_entry(0), uniform_entry(1)],
        });
        let map_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("hard_map_bind_group"),
            layout: &map_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&depth_map.linear_depth_view) },
                wgpu::BindGroupEntry { binding: 1, resource: settings_buffer.as_entire_binding() },
            ],
        });
        let module = create_shader(setup.gpu, "hard_lookup_shader", include_str!("../../../shaders/hard/hard.wgsl"))?;
        let lookup = ScreenPass::new(setup, NAME, "hard_lookup", (&module, "hard_lookup"), Some(&map_layout), VISIBILITY_FORMAT.into())?;
        Ok(Self { depth_map, lookup, map_bind_group })
    }
}

impl ShadowTechnique for HardShadowMapping {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.depth_map.encode(frame, light);
        self.lookup.encode(frame, light, output, Some(&self.map_bind_group), None);
        Ok(())
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(HardShadowMapping::new(setup)?))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "hard shadow mapping from the light's centre, slope-scaled bias (baseline)",
    paper: "Williams 1978, Casting curved shadows on curved surfaces",
    kind: TechniqueKind::Realtime,
    params: PARAMS,
    requirements: ShadowMapSettings::screen_space_requirements,
    create,
};

register_technique!(INFO);
