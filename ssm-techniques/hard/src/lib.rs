//! Baseline: hard shadow mapping (Williams 1978, *Casting curved shadows on
//! curved surfaces*), with a slope-scaled depth bias.
//!
//! One depth map from the light's centre over all geometry, then one
//! comparison per pixel: visibility is 0 or 1. It is the fast end of every
//! speed/accuracy plot and the limit every soft technique must reach as the
//! light shrinks to a point.
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique hard --set
//! hard.shadow_map_size=1024 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_hard::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_hard::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("hard")?;
//! let params = info.params_from([("shadow_map_size", "1024")])?;
//! let mut renderer = Renderer::new(&gpu, &scene, 64, 48, &(info.requirements)(&params)?)?;
//! let mut technique = renderer.create_technique(info, &params)?;
//! let timings = renderer.render(technique.as_mut(), info.name)?;
//! // One value per pixel for the scene's first light: 1 lit, 0 in shadow.
//! let visibility = renderer.read_visibility(0, info.name)?;
//! assert_eq!(visibility.len(), 64 * 48);
//! assert!(visibility.iter().all(|v| (0.0..=1.0).contains(v)));
//! println!("{} in {:.2} ms", info.name, timings.frame_ms());
//! # Ok(())
//! # }
//! ```

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{bind_group, bind_group_layout, texture_entry, uniform_buffer, uniform_entry};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    Frame, GpuContext, LightDepthMap, ParamValues, Requirements, Result, SHADOW_MAP_MAX_SIZE, SHADOW_MAP_MIN_SIZE, ScreenPass, Settings,
    ShadowMapBias, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct, VISIBILITY_FORMAT,
    register_technique, screen_space_requirements,
};

/// The registered name.
pub const NAME: &str = "hard";

/// The lookup shader.
const SHADER: &str = ssm_shaders::hard::HARD;
/// What the shader imports besides `common/`: its settings struct, written from the Rust one.
const LOCAL_SHADERS: &[(&str, &str)] = &[(HardSettingsUniform::WGSL_IMPORT, HardSettingsUniform::WGSL)];
/// The lookup pass's label, and its read counters'.
const LOOKUP_PASS: &str = "hard_lookup";
/// What the lookup counts in a counting frame, in the order its shader indexes them: its texel
/// reads and the bytes they fetched.
const COUNTERS: &[(&str, &str)] = &[(LOOKUP_PASS, "reads"), (LOOKUP_PASS, "read_bytes")];

/// Settings of [`HardShadowMapping`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct HardSettings {
    /// Side of the square shadow map, texels.
    #[param(default = 2048, min = SHADOW_MAP_MIN_SIZE, max = SHADOW_MAP_MAX_SIZE)]
    pub shadow_map_size: u32,
    /// Depth bias and normal offset.
    #[param(flatten)]
    pub bias: ShadowMapBias,
}

/// The lookup settings as `shaders/hard/hard.wgsl` reads them: the WGSL struct `HardSettings`, which
/// the derive writes and the shader imports (`// #import rust/HardSettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct HardSettingsUniform {
    /// Normal offset of the lookup point, in shadow-map texels.
    normal_offset: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

impl From<&HardSettings> for HardSettingsUniform {
    fn from(settings: &HardSettings) -> Self {
        Self { normal_offset: settings.bias.normal_offset, _pad0: 0.0, _pad1: 0.0, _pad2: 0.0 }
    }
}

/// Hard shadow mapping.
pub struct HardShadowMapping {
    depth_map: LightDepthMap,
    lookup: ScreenPass,
    map_bind_group: wgpu::BindGroup,
    /// The lookup's texel reads and their bytes, counted in a counting frame only ([`TechniqueSetup::count_work`]).
    read_counts: ReadCounts,
}

impl HardShadowMapping {
    /// Builds the depth map and the lookup pipeline.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = HardSettings::from_params(setup.params)?;
        let device = &setup.gpu.device;
        let depth_map = settings.bias.depth_map(setup, "hard_shadow_map", settings.shadow_map_size)?;
        let settings_buffer = uniform_buffer(device, "hard_settings_uniform", &HardSettingsUniform::from(&settings));
        // The shadow-map pass reads no texel (it rasterises the scene); the lookup reads the
        // G-buffer and the map (shaders/hard/hard.wgsl says what it counts, in texels and bytes).
        let read_counts = ReadCounts::with_units(device, "hard_read_counts", COUNTERS, setup.count_work);
        let map_layout = bind_group_layout(device, "hard_map_layout", &[texture_entry(0), uniform_entry(1), ReadCounts::layout_entry(2)]);
        let map_bind_group = bind_group(
            device,
            "hard_map_bind_group",
            &map_layout,
            &[
                wgpu::BindingResource::TextureView(&depth_map.linear_depth_view),
                settings_buffer.as_entire_binding(),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        let module = create_shader_with_imports(setup.gpu, "hard_lookup_shader", SHADER, LOCAL_SHADERS)?;
        let lookup = ScreenPass::new(
            setup,
            NAME,
            LOOKUP_PASS,
            (&module, "hard_lookup"),
            Some(&map_layout),
            VISIBILITY_FORMAT.into(),
            &read_counts.pipeline_constants(),
        )?;
        Ok(Self { depth_map, lookup, map_bind_group, read_counts })
    }
}

impl ShadowTechnique for HardShadowMapping {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.read_counts.clear(frame, light);
        self.depth_map.encode(frame, light);
        self.lookup.encode(frame, light, output, Some(&self.map_bind_group), None);
        Ok(())
    }

    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ssm_core::ShaderWork>>> {
        self.read_counts.work(gpu)
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(HardShadowMapping::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    Ok(screen_space_requirements(HardSettings::from_params(params)?.shadow_map_size))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "hard shadow mapping from the light's centre, slope-scaled bias (baseline)",
    paper: "Williams 1978, Casting curved shadows on curved surfaces",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Frame,
    params: HardSettings::PARAMS,
    requirements,
    create,
    presets: &[],
    trade: Some("shadow_map_size=512,1024,2048,4096"),
    debug_outputs: &[],
    uniforms: &[UniformCheck {
        wgsl_struct: HardSettingsUniform::WGSL_NAME,
        wgsl_source: SHADER,
        imports: LOCAL_SHADERS,
        rust: HardSettingsUniform::LAYOUT,
    }],
    limits: &[],
    paper_configuration: ssm_core::PaperConfiguration::DEFAULTS,
};

register_technique!(INFO);
