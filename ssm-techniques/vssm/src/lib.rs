//! Baseline: variance soft shadow mapping (Yang, Dong, Feng, Seidel and Kautz 2010, *Variance
//! Soft Shadow Mapping*, Computer Graphics Forum 29(7), Pacific Graphics).
//!
//! PCSS's blocker search, penumbra estimate and filter (Fernando 2005), each region answered in
//! constant time by the shadow map's first two moments (Donnelly and Lauritzen 2006, variance
//! shadow maps) read from their summed-area table: the average blocker depth from Chebyshev's
//! one-tailed bound on the fraction of non-blockers, the fraction lit from the same bound; the
//! kernel subdivided into sub-regions to avoid VSM's incorrectly lit pixels. Each sub-region is
//! compared with the receiver's tangent plane where it lies, texels with no surface are counted
//! apart, and the blocker search is kept to the map, retried over smaller regions and refined
//! (README: "What differs"). Passes: the depth map, the table (rows, then columns: exact 128-bit
//! fixed-point sums of the two moments and of the texels with a surface), the filter.
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique vssm --set
//! vssm.subdivision=2 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_vssm::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_vssm::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("vssm")?;
//! let params = info.params_from([("subdivision", "2")])?;
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
use ssm_core::passes::{
    bind_group, bind_group_layout, compute_pipeline, labelled_view, texture_entry, uniform_buffer, uniform_entry,
    write_storage_texture_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    Frame, GpuContext, LightDepthMap, ParamValues, Preset, Requirements, Result, ScreenPass, Settings, ShadowMapBias, ShadowTechnique,
    TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct, VISIBILITY_FORMAT, register_technique,
    screen_space_requirements,
};

/// The registered name.
pub const NAME: &str = "vssm";

/// What the table and filter passes share.
const COMMON_SHADER: &str = ssm_shaders::vssm::VSSM_COMMON;
/// The summed-area table's two passes.
const SAT_SHADER: &str = ssm_shaders::vssm::VSSM_SAT;
/// The blocker search, penumbra estimate and filter.
const FILTER_SHADER: &str = ssm_shaders::vssm::VSSM;
/// WGSL files the VSSM shaders import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] =
    &[(VssmSettingsUniform::WGSL_IMPORT, VssmSettingsUniform::WGSL), ("vssm/vssm_common.wgsl", COMMON_SHADER)];

/// What the shaders count in a counting frame, in the order they index the counters: the table's
/// two passes their texel reads, the bytes those fetched and the bytes stored (vssm_sat.wgsl), the
/// filter its texel reads and their bytes (vssm.wgsl). The depth map's pass reads no texel.
const COUNTERS: &[(&str, &str)] = &[
    ("vssm_sat_rows", "reads"),
    ("vssm_sat_rows", "read_bytes"),
    ("vssm_sat_rows", "storage_bytes"),
    ("vssm_sat_columns", "reads"),
    ("vssm_sat_columns", "read_bytes"),
    ("vssm_sat_columns", "storage_bytes"),
    ("vssm_filter", "reads"),
    ("vssm_filter", "read_bytes"),
];

/// The table's texel format: one 128-bit integer of three fixed-point sums (Σz², Σz, the texels with a surface) as four 32-bit words.
const TABLE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

/// Largest shadow map whose table the 128-bit sums hold exactly (4096² = 2^24 texels of moments
/// below 2^27 sum to below 2^51, each field's width; shaders/vssm/vssm_common.wgsl) and that fits
/// a device's textures.
const MAX_SIZE: u32 = 4096;

/// Settings of [`VarianceSoftShadowMaps`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct VssmSettings {
    /// Side of the square shadow map and of its summed-area table, texels.
    #[param(default = 1024, min = 16, max = 4096)]
    pub shadow_map_size: u32,
    /// Sub-regions per axis of the blocker search's and the filter's regions (1: each region one VSM query; the paper subdivides the kernel against incorrectly lit pixels).
    #[param(default = 4, min = 1, max = 8)]
    pub subdivision: u32,
    /// Smallest variance Chebyshev's bound uses, in units of (depth / far)².
    #[param(default = 1e-7, min = 0.0, max = 0.01)]
    pub min_variance: f32,
    /// Lookup point moved off the surface along its normal, in shadow-map texels; 0 by default: the bound is continuous in depth, so there is no acne to push away from, and the offset would put the receiver nearer the light than its own texels, where the bound is loose.
    #[param(default = 0.0, min = 0.0, max = 8.0)]
    pub normal_offset: f32,
}

impl VssmSettings {
    /// The depth map's bias: none. Chebyshev's bound needs the texels' true depths, and the
    /// receiver is compared with its own tangent plane's depth, where its texels lie: a bias would
    /// only move the texels off it (or, added to the receiver's depth too, shift every depth alike
    /// and change nothing).
    fn bias(&self) -> ShadowMapBias {
        ShadowMapBias { constant_bias: 0.0, slope_bias: 0.0, normal_offset: self.normal_offset }
    }
}

/// The filter's settings as `shaders/vssm/vssm.wgsl` reads them: the WGSL struct `VssmSettings`, which the
/// derive writes and the shader imports (`// #import rust/VssmSettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct VssmSettingsUniform {
    /// Side of the shadow map and its summed-area table, texels.
    size: f32,
    /// Sub-regions per axis of each region (1: plain VSM).
    subdivision: u32,
    /// Smallest variance the bound uses, in z² units (z = depth / far): keeps it finite on a flat
    /// region, where it is 0, and absorbs the rounding of the table's sums to f32.
    min_variance: f32,
    /// Normal offset of the lookup point, in shadow-map texels.
    normal_offset: f32,
}

impl VssmSettingsUniform {
    /// The uniform of `settings`.
    fn new(settings: &VssmSettings) -> Self {
        Self {
            size: settings.shadow_map_size as f32,
            subdivision: settings.subdivision,
            min_variance: settings.min_variance,
            normal_offset: settings.normal_offset,
        }
    }
}

/// Variance soft shadow mapping.
pub struct VarianceSoftShadowMaps {
    depth_map: LightDepthMap,
    rows: wgpu::ComputePipeline,
    columns: wgpu::ComputePipeline,
    rows_group: wgpu::BindGroup,
    columns_group: wgpu::BindGroup,
    filter: ScreenPass,
    filter_group: wgpu::BindGroup,
    /// The passes' counts, made in a counting frame only ([`TechniqueSetup::count_work`]).
    read_counts: ReadCounts,
    size: u32,
}

impl VarianceSoftShadowMaps {
    /// Builds the depth map, the table and the pipelines.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = VssmSettings::from_params(setup.params)?;
        let gpu = setup.gpu;
        let device = &gpu.device;
        let size = settings.shadow_map_size;
        let depth_map = settings.bias().depth_map(setup, "vssm_shadow_map", size)?;
        let table_texture = |label: &str| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: TABLE_FORMAT,
                usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let row_sums = labelled_view(&table_texture("vssm_row_sums"), "vssm_row_sums");
        let table = labelled_view(&table_texture("vssm_moment_table"), "vssm_moment_table");
        let uint_texture_entry = |binding: u32| wgpu::BindGroupLayoutEntry {
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            ..texture_entry(binding)
        };
        let read_counts = ReadCounts::with_units(device, "vssm_read_counts", COUNTERS, setup.count_work);
        let rows_layout = bind_group_layout(
            device,
            "vssm_sat_rows_layout",
            &[texture_entry(0), write_storage_texture_entry(1, TABLE_FORMAT), ReadCounts::layout_entry(4)],
        );
        let columns_layout = bind_group_layout(
            device,
            "vssm_sat_columns_layout",
            &[uint_texture_entry(2), write_storage_texture_entry(3, TABLE_FORMAT), ReadCounts::layout_entry(4)],
        );
        let sat_module = create_shader_with_imports(gpu, "vssm_sat_shader", SAT_SHADER, LOCAL_SHADERS)?;
        let frame_layout = &setup.scene.uniform_layout;
        let constants = read_counts.pipeline_constants();
        let rows =
            compute_pipeline(device, "vssm_sat_rows_pipeline", &sat_module, "vssm_sat_rows", &[frame_layout, &rows_layout], &constants);
        let columns = compute_pipeline(
            device,
            "vssm_sat_columns_pipeline",
            &sat_module,
            "vssm_sat_columns",
            &[frame_layout, &columns_layout],
            &constants,
        );
        let rows_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("vssm_sat_rows_bind_group"),
            layout: &rows_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&depth_map.linear_depth_view) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&row_sums) },
                wgpu::BindGroupEntry { binding: 4, resource: read_counts.buffer().as_entire_binding() },
            ],
        });
        let columns_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("vssm_sat_columns_bind_group"),
            layout: &columns_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&row_sums) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&table) },
                wgpu::BindGroupEntry { binding: 4, resource: read_counts.buffer().as_entire_binding() },
            ],
        });
        let filter_layout = bind_group_layout(
            device,
            "vssm_filter_layout",
            &[uint_texture_entry(0), uniform_entry(1), texture_entry(2), ReadCounts::layout_entry(3)],
        );
        let filter_group = bind_group(
            device,
            "vssm_filter_bind_group",
            &filter_layout,
            &[
                wgpu::BindingResource::TextureView(&table),
                uniform_buffer(device, "vssm_settings_uniform", &VssmSettingsUniform::new(&settings)).as_entire_binding(),
                wgpu::BindingResource::TextureView(&depth_map.linear_depth_view),
                read_counts.buffer().as_entire_binding(),
            ],
        );
        let filter_module = create_shader_with_imports(gpu, "vssm_filter_shader", FILTER_SHADER, LOCAL_SHADERS)?;
        let filter = ScreenPass::new(
            setup,
            NAME,
            "vssm_filter",
            (&filter_module, "vssm_filter"),
            Some(&filter_layout),
            VISIBILITY_FORMAT.into(),
            &constants,
        )?;
        Ok(Self { depth_map, rows, columns, rows_group, columns_group, filter, filter_group, read_counts, size })
    }
}

impl ShadowTechnique for VarianceSoftShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        self.read_counts.clear(frame, light);
        self.depth_map.encode(frame, light);
        let groups = self.size.div_ceil(64);
        {
            let light_group = &frame.scene.light_bind_groups[light];
            let mut pass = frame.compute_pass("vssm_sat_rows");
            pass.set_pipeline(&self.rows);
            pass.set_bind_group(0, light_group, &[]);
            pass.set_bind_group(1, &self.rows_group, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        {
            let light_group = &frame.scene.light_bind_groups[light];
            let mut pass = frame.compute_pass("vssm_sat_columns");
            pass.set_pipeline(&self.columns);
            pass.set_bind_group(0, light_group, &[]);
            pass.set_bind_group(1, &self.columns_group, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        self.filter.encode(frame, light, output, Some(&self.filter_group), None);
        Ok(())
    }

    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ssm_core::ShaderWork>>> {
        self.read_counts.work(gpu)
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(VarianceSoftShadowMaps::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    let settings = VssmSettings::from_params(params)?;
    Ok(screen_space_requirements(settings.shadow_map_size.min(MAX_SIZE)))
}

/// Sweeps of the VSSM baseline.
const PRESETS: &[Preset] = &[Preset {
    name: "vssm-subdivision",
    summary: "VSSM's kernel subdivision (1 = plain VSM regions) against the error and the light bleeding (mean_signed_error, umbra_leak), on sphere-cube",
    scenes: &["sphere-cube"],
    varies: &["vssm.subdivision=1,2,4,8"],
    x_axis: "vssm.subdivision",
    ..Preset::DEFAULT
}];

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "variance soft shadow mapping: PCSS's search and filter from the moments' summed-area table, Chebyshev's blocker estimate, the kernel subdivided (baseline)",
    paper: "Yang, Dong, Feng, Seidel and Kautz 2010, Variance Soft Shadow Mapping (CGF 29(7), Pacific Graphics)",
    kind: TechniqueKind::Realtime,
    // One view of the light from its centre: the framework adds the own surface's share.
    light_sampling: ssm_core::LightSampling::Centre,
    light_view: ssm_core::LightView::Frame,
    params: VssmSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("subdivision=1,2,4"),
    debug_outputs: &[],
    uniforms: &[UniformCheck {
        wgsl_struct: VssmSettingsUniform::WGSL_NAME,
        wgsl_source: FILTER_SHADER,
        imports: LOCAL_SHADERS,
        rust: VssmSettingsUniform::LAYOUT,
    }],
    limits: &[
        ssm_core::KnownLimit {
            case: "thin bars under a near-point light",
            mean_error: 0.1,
            reason: "the penumbra is under a texel (0.43 texels of its 1024² map), and variance shadow maps answer a region from its depth moments, never a point (Donnelly and Lauritzen 2006, on which Yang et al. 2010 build): its least region is one texel, a bilinear ramp across the edge, whose mean |error| over the edge's place in the texel is 4/3 of a hard step's (1/4 + 1/12 texel against 1/4): 0.0745 where either shadows, against hard shadows' 0.0212 from a 1024² map and 0.0679 over the texel grid's phase (96x72, lavapipe). A region under a texel sees its texel's depth up to half a texel's depth change off the receiver's plane: quarter-texel regions shadow the corridor's floor from its walls (0.3327 against 0.0264); the texel under the point gives 0.0212 here but shadows the floor along the corridor's walls (0.0395 against hard shadows' 0.0369)",
        },
        ssm_core::KnownLimit {
            case: "light resting on the receiver",
            mean_error: 0.25,
            reason: "past the light frame's widest angle (84 degrees off the light's normal) the framework answers with a hard shadow from the light's centre (counted: pixels_beyond_frame): its search and filter are rectangles of one summed-area table (Yang et al. 2010), the light's back-projection only while the map is parallel to the light; on a hemicube's side faces, perpendicular to it, the light's image is a tilted quadrilateral reaching the whole face, which a rectangle query would blur over (pcss's side faces tap the quadrilateral point by point instead)",
        },
    ],
    paper_configuration: ssm_core::PaperConfiguration::DEFAULTS,
};

register_technique!(INFO);

#[cfg(test)]
mod tests {
    /// The filter shader's largest subdivision is the parameter's.
    #[test]
    fn the_shaders_largest_subdivision_is_the_parameters() {
        let Some(ssm_core::ParamSpec { kind: ssm_core::ParamKind::Int { max, .. }, .. }) =
            <super::VssmSettings as ssm_core::Settings>::PARAMS.iter().find(|p| p.name == "subdivision")
        else {
            panic!("no integer parameter `subdivision`");
        };
        let line = format!("const MAX_SUBDIVISION: u32 = {max}u;");
        assert!(super::FILTER_SHADER.contains(&line), "vssm.wgsl lacks `{line}`");
    }

    /// The shaders count each texel they read at its format's size: the depth map's, the table's
    /// and the G-buffer's.
    #[test]
    fn the_shaders_texel_bytes_are_the_formats_sizes() {
        for (shader, constant, format) in [
            (super::SAT_SHADER, "DEPTH_TEXEL_BYTES", ssm_core::LightDepthMap::FORMAT),
            (super::COMMON_SHADER, "TABLE_TEXEL_BYTES", super::TABLE_FORMAT),
            (super::FILTER_SHADER, "GBUFFER_TEXEL_BYTES", ssm_core::GBuffer::POSITION_FORMAT),
            (super::FILTER_SHADER, "GBUFFER_TEXEL_BYTES", ssm_core::GBuffer::NORMAL_FORMAT),
        ] {
            let missing = ssm_core::read_counts::missing_texel_byte_constants(shader, &[(constant, format)]);
            assert!(missing.is_empty(), "the VSSM shaders lack {missing:?}");
        }
    }
}
