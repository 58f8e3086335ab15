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
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique pcss --set
//! pcss.pcf_kernel=21 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_pcss::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_pcss::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("pcss")?;
//! let params = info.params_from([("pcf_kernel", "21")])?;
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

mod side_faces;

use bytemuck::{Pod, Zeroable};
pub use side_faces::{PcssSideFaceSettings, SIDE_FACES_PASS};
use ssm_core::passes::{
    bind_group, bind_group_layout, compute_pipeline, storage_buffer, storage_entry, texture_entry, uniform_buffer, uniform_entry,
    visibility_storage_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    Choice, Frame, GpuContext, LightDepthMap, ParamValues, ReceiverModel, Requirements, Result, SHADOW_MAP_MAX_SIZE, SHADOW_MAP_MIN_SIZE,
    ScreenPass, Settings, ShadowMapBias, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct,
    VISIBILITY_FORMAT, register_technique, screen_space_requirements,
};

/// The registered name.
pub const NAME: &str = "pcss";

/// What both passes share: the settings, the bindings, the blocker search and the filter.
const COMMON_SHADER: &str = ssm_shaders::pcss::PCSS_COMMON;
/// The fragment pass.
const SHADER: &str = ssm_shaders::pcss::PCSS;
/// The compute pass whose workgroups share the texels they read.
const TILED_SHADER: &str = ssm_shaders::pcss::PCSS_TILED;
/// WGSL files the PCSS shaders import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] =
    &[(PcssSettingsUniform::WGSL_IMPORT, PcssSettingsUniform::WGSL), ("pcss/pcss_common.wgsl", COMMON_SHADER)];
/// The label of the pass (both implementations), and of its read counts.
const PASS: &str = "pcss_blocker_search_and_filter";
/// What the pass counts, in the order its shaders index them (`record_pcss_reads_of` in
/// `shaders/pcss/pcss_common.wgsl`): its texel reads and the bytes they fetched.
const COUNTERS: &[(&str, &str)] = &[(PASS, "reads"), (PASS, "read_bytes")];

/// Where a tap's depth comes from (the same texels, so the same pixels, either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum TapSource {
    /// A full-screen fragment pass: every tap reads the shadow map.
    Texture,
    /// A compute pass whose 8×8 workgroups load the union of their pixels' search windows into
    /// workgroup memory once, when it holds at most 4,080 texels (windows a few dozen texels
    /// wide: a small light, or a coarse map), and read every tap from there; groups with a
    /// larger union read the shadow map. The implementation, not the algorithm: beside
    /// `texture`, it tells what PCSS's taps cost from what their number costs.
    WorkgroupTile,
}

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
    /// Count each pass's texel reads per pixel of the screen, the G-buffer's included (diagnostics `pcss_blocker_search_and_filter_reads_per_pixel`); the atomics cost time, so off when timing.
    #[param(default = false)]
    pub count_reads: bool,
    /// Where taps read their depth: texture (a fragment pass reading the shadow map) or workgroup_tile (a compute pass whose workgroups share the texels their pixels read, when they fit; the same pixels).
    #[param(choice, default = "texture")]
    pub tap_source: TapSource,
    /// What the taps are compared with.
    #[param(flatten)]
    pub receiver: ReceiverModel,
    /// Depth bias and normal offset.
    #[param(flatten)]
    pub bias: ShadowMapBias,
}

/// The kernel sizes as `shaders/pcss/pcss_common.wgsl` reads them for both tap sources: the WGSL struct
/// `PcssSettings`, which the derive writes and the shader imports (`// #import rust/PcssSettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct PcssSettingsUniform {
    /// Samples per axis of the blocker search (n).
    blocker_kernel: u32,
    /// Samples per axis of the filter (m).
    pcf_kernel: u32,
    /// 1: compare taps with the receiver's tangent plane; 0: with its depth.
    receiver_plane: u32,
    /// Normal offset of the lookup point, in shadow-map texels.
    normal_offset: f32,
}

impl From<&PcssSettings> for PcssSettingsUniform {
    fn from(settings: &PcssSettings) -> Self {
        Self {
            blocker_kernel: settings.blocker_kernel,
            pcf_kernel: settings.pcf_kernel,
            receiver_plane: u32::from(settings.receiver.receiver_plane),
            normal_offset: settings.bias.normal_offset,
        }
    }
}

/// The blocker search and filter, as one of [`TapSource`]'s passes.
enum SearchAndFilter {
    Fragment(ScreenPass),
    /// The compute pass, its G-buffer group, per light its output group, and the counts of
    /// workgroups that used their tile.
    Tiled {
        pipeline: wgpu::ComputePipeline,
        gbuffer_group: wgpu::BindGroup,
        output_groups: Vec<wgpu::BindGroup>,
        tile_counts: wgpu::Buffer,
    },
}

/// PCSS.
pub struct Pcss {
    depth_map: LightDepthMap,
    search_and_filter: SearchAndFilter,
    /// The receivers past the frame's widest angle, on a hemicube's side faces; `None` when no
    /// light's frame reaches it.
    side_faces: Option<side_faces::SideFaces>,
    map_bind_group: wgpu::BindGroup,
    read_counts: ReadCounts,
    width: u32,
    height: u32,
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
        // Counting pipelines for count_reads, and for the framework's counting frame (--count-work).
        let read_counts = ReadCounts::with_units(device, "pcss_read_counts", COUNTERS, settings.count_reads || setup.count_work);
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
        // Blocker search, penumbra estimate and filtering are one pass: each needs only the previous one's result at the same pixel.
        let search_and_filter = match settings.tap_source {
            TapSource::Texture => {
                let module = create_shader_with_imports(setup.gpu, "pcss_filter_shader", SHADER, LOCAL_SHADERS)?;
                SearchAndFilter::Fragment(ScreenPass::new(
                    setup,
                    NAME,
                    PASS,
                    (&module, "pcss_filter"),
                    Some(&map_layout),
                    VISIBILITY_FORMAT.into(),
                    &read_counts.pipeline_constants(),
                )?)
            }
            TapSource::WorkgroupTile => Self::tiled(setup, &map_layout, &read_counts)?,
        };
        let side_faces = side_faces::SideFaces::new(setup, &settings)?;
        Ok(Self {
            depth_map,
            search_and_filter,
            side_faces,
            map_bind_group,
            read_counts,
            width: setup.scene.width,
            height: setup.scene.height,
        })
    }

    /// The compute pass of [`TapSource::WorkgroupTile`].
    fn tiled(setup: &TechniqueSetup<'_>, map_layout: &wgpu::BindGroupLayout, read_counts: &ReadCounts) -> Result<SearchAndFilter> {
        let device = &setup.gpu.device;
        let gbuffer = setup.shared.gbuffer(NAME)?;
        let module = create_shader_with_imports(setup.gpu, "pcss_filter_tiled_shader", TILED_SHADER, LOCAL_SHADERS)?;
        let output_layout = bind_group_layout(device, "pcss_tiled_output_layout", &[visibility_storage_entry(0), storage_entry(1, false)]);
        let pipeline = compute_pipeline(
            device,
            "pcss_filter_tiled_pipeline",
            &module,
            "pcss_filter_tiled",
            &[&setup.scene.uniform_layout, &gbuffer.layout, map_layout, &output_layout],
            &read_counts.pipeline_constants(),
        );
        let tile_counts = storage_buffer(device, "pcss_tile_counts", 8);
        let output_groups = setup
            .outputs
            .iter()
            .enumerate()
            .map(|(light, output)| {
                bind_group(
                    device,
                    &format!("pcss_tiled_output_bind_group_{light}"),
                    &output_layout,
                    &[wgpu::BindingResource::TextureView(output), tile_counts.as_entire_binding()],
                )
            })
            .collect();
        Ok(SearchAndFilter::Tiled { pipeline, gbuffer_group: gbuffer.bind_group.clone(), output_groups, tile_counts })
    }
}

impl ShadowTechnique for Pcss {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.read_counts.clear(frame, light);
        self.depth_map.encode(frame, light);
        match &self.search_and_filter {
            SearchAndFilter::Fragment(pass) => pass.encode(frame, light, output, Some(&self.map_bind_group), None),
            SearchAndFilter::Tiled { pipeline, gbuffer_group, output_groups, tile_counts } => {
                let output_group = output_groups
                    .get(light)
                    .ok_or_else(|| ssm_core::Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
                frame.clear_buffer("pcss_clear_tile_counts", tile_counts, 0, None);
                let light_group = &frame.scene.light_bind_groups[light];
                let mut pass = frame.compute_pass(PASS);
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, light_group, &[]);
                pass.set_bind_group(1, gbuffer_group, &[]);
                pass.set_bind_group(2, &self.map_bind_group, &[]);
                pass.set_bind_group(3, output_group, &[]);
                pass.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
            }
        }
        if let Some(side_faces) = &self.side_faces {
            side_faces.encode(frame, light);
        }
        Ok(())
    }

    /// The pass's texel reads and invocations, when built for counting: one invocation per pixel
    /// of the screen, each reading the G-buffer's two texels (trivial pixels included), and a
    /// computed pixel one texel per shadow-map tap; in the tiled pass a tap read from workgroup
    /// memory is not a texel read, and the tile's loads are (one per texel of the union). Each
    /// read's bytes too: 16 per G-buffer texel (`Rgba32Float`), 4 per shadow-map texel (`R32Float`).
    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ssm_core::ShaderWork>>> {
        let Some(mut work) = self.read_counts.work(gpu)? else {
            return Ok(None);
        };
        if let Some(side_faces) = &self.side_faces {
            work.extend(side_faces.work(gpu)?.unwrap_or_default());
        }
        Ok(Some(work))
    }

    /// With `count_reads`: texel reads per pixel of the screen, and the pixels; with `tap_source =
    /// workgroup_tile`, `pcss_tiled_share`: the share of the last light's workgroups (with a pixel
    /// to compute) whose union of windows fitted their tile.
    fn diagnostics(&mut self, gpu: &GpuContext) -> Vec<(String, f64)> {
        let mut out = self.read_counts.diagnostics(gpu);
        if let SearchAndFilter::Tiled { tile_counts, .. } = &self.search_and_filter
            && let Ok(bytes) = ssm_core::readback::read_buffer(gpu, tile_counts, 8, "PCSS tile counts")
            && let [tiled, groups] = bytemuck::pod_collect_to_vec::<u8, u32>(&bytes)[..]
            && groups > 0
        {
            out.push(("pcss_tiled_share".to_owned(), f64::from(tiled) / f64::from(groups)));
        }
        out
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
        name: "pcss-taps",
        summary: "PCSS's taps from the shadow map or from workgroup memory (tap_source; the same pixels) at the kernel pairs of Buades et al., Table 4: what the implementation costs beside what the algorithm does",
        scenes: &["leaves"],
        varies: &["pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41", "pcss.tap_source=texture,workgroup_tile"],
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
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    // Past the frame's widest angle, its own search and filter on a hemicube's side faces.
    light_view: ssm_core::LightView::SideFaces,
    params: PcssSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("blocker_kernel:pcf_kernel=3:5,7:15,11:21,29:41"),
    debug_outputs: &[],
    uniforms: &[
        UniformCheck {
            wgsl_struct: PcssSettingsUniform::WGSL_NAME,
            wgsl_source: SHADER,
            imports: LOCAL_SHADERS,
            rust: PcssSettingsUniform::LAYOUT,
        },
        UniformCheck {
            wgsl_struct: "PcssSideFaceSettings",
            wgsl_source: ssm_shaders::pcss::PCSS_SIDE_FACES,
            imports: &[],
            rust: PcssSideFaceSettings::LAYOUT,
        },
    ],
    limits: &[],
    paper_configuration: ssm_core::PaperConfiguration {
        // Fernando's sketch compares each tap with the receiver's own depth.
        settings: &["receiver_plane=false"],
        scenes: &["contact", "parallel-square"],
        truth: &[],
        averaged_over: None,
    },
};

register_technique!(INFO);
