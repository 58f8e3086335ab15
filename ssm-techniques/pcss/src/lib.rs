//! Baseline: percentage-closer soft shadows (Fernando 2005, *Percentage-closer
//! soft shadows*, SIGGRAPH sketch), with the regular n×n blocker-search and
//! m×m filter grids used as the PCSS reference by Buades et al. (2015) and
//! Shen et al. (2011).
//!
//! Per pixel: average the depths of the shadow-map texels nearer than the
//! receiver inside the light's back-projection through the near plane, take
//! the penumbra width from that average by similar triangles, and filter the
//! shadow test over it. Cost grows with n² + m² per pixel: the reason
//! separable and predicted variants exist.

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{texture_entry, uniform_entry};
use ssm_core::shader::create_shader;
use ssm_core::{
    Frame, LightDepthMap, ParamKind, ParamSpec, Result, ScreenPass, ShadowMapSettings, ShadowTechnique, TechniqueInfo, TechniqueKind,
    TechniqueSetup, VISIBILITY_FORMAT, register_technique,
};
use wgpu::util::DeviceExt;

/// The registered name.
pub const NAME: &str = "pcss";

/// Parameters of [`Pcss`].
pub const PARAMS: &[ParamSpec] = &[
    ShadowMapSettings::size_param(1024),
    ParamSpec {
        name: "blocker_kernel",
        kind: ParamKind::Int { default: 7, min: 1, max: 64 },
        doc: "samples per axis of the blocker search (n; n² taps per pixel)",
    },
    ParamSpec {
        name: "pcf_kernel",
        kind: ParamKind::Int { default: 15, min: 1, max: 128 },
        doc: "samples per axis of the PCF filter (m; m² taps per pixel)",
    },
    ShadowMapSettings::RECEIVER_PLANE_PARAM,
    ShadowMapSettings::BIAS_PARAMS[0],
    ShadowMapSettings::BIAS_PARAMS[1],
    ShadowMapSettings::BIAS_PARAMS[2],
];

/// The kernel sizes, as `shaders/pcss/pcss.wgsl` reads them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct PcssSettingsUniform {
    blocker_kernel: u32,
    pcf_kernel: u32,
    receiver_plane: u32,
    normal_offset: f32,
}

/// PCSS.
pub struct Pcss {
    depth_map: LightDepthMap,
    search_and_filter: ScreenPass,
    map_bind_group: wgpu::BindGroup,
}

impl Pcss {
    /// Builds the depth map and the filter pipeline.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let params = setup.params;
        let map_settings = ShadowMapSettings::from_params(params)?;
        let kernel = |name| params.int(name).map(|v| u32::try_from(v).unwrap_or(1));
        let uniform = PcssSettingsUniform {
            blocker_kernel: kernel("blocker_kernel")?,
            pcf_kernel: kernel("pcf_kernel")?,
            receiver_plane: u32::from(params.bool("receiver_plane")?),
            normal_offset: map_settings.normal_offset,
        };
        let device = &setup.gpu.device;
        let depth_map = map_settings.depth_map(setup, "pcss_shadow_map")?;
        let settings_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("pcss_settings_uniform"),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let map_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pcss_map_layout"),
            entries: &[texture_entry(0), uniform_entry(1)],
        });
        let map_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pcss_map_bind_group"),
            layout: &map_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&depth_map.linear_depth_view) },
                wgpu::BindGroupEntry { binding: 1, resource: settings_buffer.as_entire_binding() },
            ],
        });
        let module = create_shader(setup.gpu, "pcss_filter_shader", include_str!("../../../shaders/pcss/pcss.wgsl"))?;
        // Blocker search, penumbra estimate and filtering are one pass: each needs only the previous one's result at the same pixel.
        let search_and_filter = ScreenPass::new(
            setup,
            NAME,
            "pcss_blocker_search_and_filter",
            (&module, "pcss_filter"),
            Some(&map_layout),
            VISIBILITY_FORMAT.into(),
        )?;
        Ok(Self { depth_map, search_and_filter, map_bind_group })
    }
}

impl ShadowTechnique for Pcss {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.depth_map.encode(frame, light);
        self.search_and_filter.encode(frame, light, output, Some(&self.map_bind_group), None);
        Ok(())
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(Pcss::new(setup)?))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "percentage-closer soft shadows: n×n blocker search, m×m PCF sized by the penumbra estimate (baseline)",
    paper: "Fernando 2005, Percentage-closer soft shadows (SIGGRAPH sketch)",
    kind: TechniqueKind::Realtime,
    params: PARAMS,
    requirements: ShadowMapSettings::screen_space_requirements,
    create,
};

register_technique!(INFO);
