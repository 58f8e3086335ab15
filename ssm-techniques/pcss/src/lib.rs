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
use ssm_core::passes::{bind_group, bind_group_layout, texture_entry, uniform_buffer, uniform_entry};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader;
use ssm_core::{
    Frame, GpuContext, LightDepthMap, ParamValues, ReceiverModel, Requirements, Result, SHADOW_MAP_MAX_SIZE, SHADOW_MAP_MIN_SIZE,
    ScreenPass, Settings, ShadowMapBias, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct,
    VISIBILITY_FORMAT, register_technique, screen_space_requirements,
};

/// The registered name.
pub const NAME: &str = "pcss";

/// The blocker search and filter shader.
const SHADER: &str = include_str!("../../../shaders/pcss/pcss.wgsl");

/// Settings of [`Pcss`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct PcssSettings {
    /// Side of the square shadow map, texels.
    #[param(default = 1024, min = SHADOW_MAP_MIN_SIZE, max = SHADOW_MAP_MAX_SIZE)]
    pub shadow_map_size: u32,
    /// Samples per axis of the blocker search (n; n² taps per pixel).
    #[param(default = 7, min = 1, max = 64)]
    pub blocker_kernel: u32,
    /// Samples per axis of the PCF filter (m; m² taps per pixel).
    #[param(default = 15, min = 1, max = 128)]
    pub pcf_kernel: u32,
    /// Count each pass's texture reads per pixel (diagnostics `pcss_blocker_search_and_filter_reads_per_pixel`); the atomics cost time, so off when timing.
    #[param(default = false)]
    pub count_reads: bool,
    /// What the taps are compared with.
    #[param(flatten)]
    pub receiver: ReceiverModel,
    /// Depth bias and normal offset.
    #[param(flatten)]
    pub bias: ShadowMapBias,
}

/// The kernel sizes, as `shaders/pcss/pcss.wgsl` reads them (`PcssSettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct PcssSettingsUniform {
    blocker_kernel: u32,
    pcf_kernel: u32,
    receiver_plane: u32,
    normal_offset: f32,
    count_reads: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

impl From<&PcssSettings> for PcssSettingsUniform {
    fn from(settings: &PcssSettings) -> Self {
        Self {
            blocker_kernel: settings.blocker_kernel,
            pcf_kernel: settings.pcf_kernel,
            receiver_plane: u32::from(settings.receiver.receiver_plane),
            normal_offset: settings.bias.normal_offset,
            count_reads: u32::from(settings.count_reads),
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        }
    }
}

/// PCSS.
pub struct Pcss {
    depth_map: LightDepthMap,
    search_and_filter: ScreenPass,
    map_bind_group: wgpu::BindGroup,
    read_counts: ReadCounts,
}

impl Pcss {
    /// Builds the depth map and the filter pipeline.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = PcssSettings::from_params(setup.params)?;
        let device = &setup.gpu.device;
        let depth_map = settings.bias.depth_map(setup, "pcss_shadow_map", settings.shadow_map_size)?;
        let settings_buffer = uniform_buffer(device, "pcss_settings_uniform", &PcssSettingsUniform::from(&settings));
        let read_counts = ReadCounts::new(device, "pcss_read_counts", &["pcss_blocker_search_and_filter"], settings.count_reads);
        let map_layout = bind_group_layout(device, "pcss_map_layout", &[texture_entry(0), uniform_entry(1), ReadCounts::layout_entry(2)]);
        let map_bind_group = bind_group(
            device,
            "pcss_map_bind_group",
            &map_layout,
            &[
                wgpu::BindingResource::TextureView(&depth_map.linear_depth_view),
                settings_buffer.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        let module = create_shader(setup.gpu, "pcss_filter_shader", SHADER)?;
        // Blocker search, penumbra estimate and filtering are one pass: each needs only the previous one's result at the same pixel.
        let search_and_filter = ScreenPass::new(
            setup,
            NAME,
            "pcss_blocker_search_and_filter",
            (&module, "pcss_filter"),
            Some(&map_layout),
            VISIBILITY_FORMAT.into(),
        )?;
        Ok(Self { depth_map, search_and_filter, map_bind_group, read_counts })
    }
}

impl ShadowTechnique for Pcss {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.read_counts.clear(frame, light);
        self.depth_map.encode(frame, light);
        self.search_and_filter.encode(frame, light, output, Some(&self.map_bind_group), None);
        Ok(())
    }

    /// With `count_reads`: texture reads per computed pixel, and the pixels.
    fn diagnostics(&mut self, gpu: &GpuContext) -> Vec<(String, f64)> {
        self.read_counts.diagnostics(gpu)
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(Pcss::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    Ok(screen_space_requirements(PcssSettings::from_params(params)?.shadow_map_size))
}

/// Sweeps of the PCSS baseline.
const PRESETS: &[ssm_core::Preset] = &[
    ssm_core::Preset {
        name: "pcss-kernels",
        summary: "PCSS with the kernel pairs of Buades et al., Table 4 (7/15, 11/21, 29/41)",
        scenes: &["leaves"],
        varies: &["pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41"],
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "shadow-map-size",
        summary: "hard and PCSS against shadow-map resolution",
        scenes: &["sphere-cube"],
        varies: &["hard.shadow_map_size=256,512,1024,2048,4096", "pcss.shadow_map_size=256,512,1024,2048,4096"],
        ..ssm_core::Preset::DEFAULT
    },
];

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "percentage-closer soft shadows: n×n blocker search, m×m PCF sized by the penumbra estimate (baseline)",
    paper: "Fernando 2005, Percentage-closer soft shadows (SIGGRAPH sketch)",
    kind: TechniqueKind::Realtime,
    params: PcssSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("blocker_kernel:pcf_kernel=3:5,7:15,11:21,29:41"),
    debug_outputs: &[],
    uniforms: &[UniformCheck { wgsl_struct: "PcssSettings", wgsl_source: SHADER, imports: &[], rust: PcssSettingsUniform::LAYOUT }],
};

register_technique!(INFO);
