//! Buades, Gumbau and Chover, *Separable soft shadow mapping*, The Visual
//! Computer, 2015.
//!
//! PCSS's two O(n²) filters made separable (Sec. 3, 4): the blocker search
//! sums n×1 rows of the depth map per pixel, then each pixel adds up the n
//! rows of its window by reusing the row of the pixel that sees it when their
//! light depths differ by less than α (else reading the row); the penumbra from
//! Eq. 1 sizes a separable screen-space blur of the hard shadow, whose vertical
//! half reuses each tap pixel's horizontal result when its normal-adjusted
//! depth differs by less than β (else re-sampling the shadow map). Three
//! passes after the depth map, as the paper's Table 1.

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{bind_group, bind_group_layout, labelled_view, render_texture, texture_entry, uniform_buffer, uniform_entry};
use ssm_core::read_counts::ReadCounts;
use ssm_core::readback::read_texture;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    Choice, ExtraImage, Frame, GpuContext, LightDepthMap, ParamValues, ReceiverModel, Requirements, Result, SHADOW_MAP_MAX_SIZE,
    SHADOW_MAP_MIN_SIZE, ScreenPass, Settings, ShadowMapBias, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck,
    UniformStruct, VISIBILITY_FORMAT, register_technique, screen_space_requirements,
};

/// The registered name.
pub const NAME: &str = "sssm";

/// WGSL files the SSSM passes import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] = &[("sssm/sssm_common.wgsl", include_str!("../../../shaders/sssm/sssm_common.wgsl"))];
/// Step 1: hard shadow and horizontal partial blocker sums.
const HORIZONTAL_BLOCKER_SHADER: &str = include_str!("../../../shaders/sssm/sssm_horizontal_blocker.wgsl");
/// Step 2: blocker average, penumbra size, horizontal blur.
const BLOCKER_BLUR_SHADER: &str = include_str!("../../../shaders/sssm/sssm_blocker_blur.wgsl");
/// Step 3: vertical blur.
const VERTICAL_BLUR_SHADER: &str = include_str!("../../../shaders/sssm/sssm_vertical_blur.wgsl");

/// The blur's weights (Sec. 4.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum BlurFilter {
    /// Gaussian weights of standard deviation `sigma` half-widths.
    Gaussian,
    /// Equal weights: the box filter PCSS applies.
    Mean,
}

/// Settings of [`SeparableSoftShadowMaps`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct SssmSettings {
    /// Side of the square shadow map, texels.
    #[param(default = 1024, min = SHADOW_MAP_MIN_SIZE, max = SHADOW_MAP_MAX_SIZE)]
    pub shadow_map_size: u32,
    /// n: samples per axis of the blocker search window.
    #[param(default = 7, min = 1, max = 64)]
    pub blocker_kernel: u32,
    /// m: taps per axis of the screen-space blur.
    #[param(default = 15, min = 1, max = 128)]
    pub blur_kernel: u32,
    /// α: blocker rows are reused when light depths differ by less than this fraction of the scene's diagonal (0: never).
    #[param(default = 0.01, min = 0.0, max = 1.0)]
    pub alpha: f32,
    /// β: blur rows are reused when normal-adjusted camera depths differ by less than this fraction of the scene's diagonal (0: never).
    #[param(default = 0.01, min = 0.0, max = 1.0)]
    pub beta: f32,
    /// Blur weights (Sec. 4.4).
    #[param(choice, default = "gaussian")]
    pub filter: BlurFilter,
    /// Gaussian standard deviation in units of the blur's half-width (the paper's N(0, 0.5)).
    #[param(default = 0.5, min = 0.05, max = 4.0)]
    pub sigma: f32,
    /// What the blocker taps are compared with (as pcss's).
    #[param(flatten)]
    pub receiver: ReceiverModel,
    /// Blur taps are weighted by exp(-(Δ/t)²) for a camera-distance gap Δ to this pixel's tangent plane, t this fraction of the scene's diagonal, and by their normals' agreement, so shadow does not leak across silhouettes (0: the paper's unweighted blur).
    #[param(default = 0.005, min = 0.0, max = 1.0)]
    pub bilateral_depth: f32,
    /// Count each pass's texture reads per pixel (diagnostics `sssm_<pass>_reads_per_pixel`); the atomics cost time, so off when timing.
    #[param(default = false)]
    pub count_reads: bool,
    /// Depth bias and normal offset.
    #[param(flatten)]
    pub bias: ShadowMapBias,
}

/// `SssmSettings` of `shaders/sssm/sssm_common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct SssmSettingsUniform {
    blocker_kernel: u32,
    blur_kernel: u32,
    gaussian: u32,
    receiver_plane: u32,
    alpha: f32,
    beta: f32,
    sigma: f32,
    normal_offset: f32,
    bilateral_depth: f32,
    count_reads: u32,
    _pad1: f32,
    _pad2: f32,
}

impl From<&SssmSettings> for SssmSettingsUniform {
    fn from(settings: &SssmSettings) -> Self {
        Self {
            blocker_kernel: settings.blocker_kernel,
            blur_kernel: settings.blur_kernel,
            gaussian: u32::from(settings.filter == BlurFilter::Gaussian),
            receiver_plane: u32::from(settings.receiver.receiver_plane),
            alpha: settings.alpha,
            beta: settings.beta,
            sigma: settings.sigma,
            normal_offset: settings.bias.normal_offset,
            bilateral_depth: settings.bilateral_depth,
            count_reads: u32::from(settings.count_reads),
            _pad1: 0.0,
            _pad2: 0.0,
        }
    }
}

/// Separable soft shadow mapping.
pub struct SeparableSoftShadowMaps {
    depth_map: LightDepthMap,
    horizontal_blocker: ScreenPass,
    blocker_blur: ScreenPass,
    vertical_blur: ScreenPass,
    /// The three passes' own bind groups (the light frame is the screen pass's group 0).
    groups: [wgpu::BindGroup; 3],
    horizontal_blocker_view: wgpu::TextureView,
    horizontal_blur_view: wgpu::TextureView,
    reuse: wgpu::Texture,
    read_counts: ReadCounts,
}

/// The names of the passes whose reads are counted, in the shaders' order.
const COUNTED_PASSES: &[&str] = &["sssm_horizontal_blocker", "sssm_blocker_and_horizontal_blur", "sssm_vertical_blur"];

/// The intermediate targets between the three passes.
struct Targets {
    horizontal_blocker: wgpu::TextureView,
    horizontal_blur: wgpu::TextureView,
    reuse: wgpu::Texture,
    reuse_view: wgpu::TextureView,
}

impl Targets {
    fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let target = |label: &str| {
            let texture = render_texture(device, label, width, height, wgpu::TextureFormat::Rgba32Float, wgpu::TextureUsages::empty());
            labelled_view(&texture, label)
        };
        let reuse = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("sssm_reuse_share"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        Self {
            horizontal_blocker: target("sssm_horizontal_blocker_target"),
            horizontal_blur: target("sssm_horizontal_blur_target"),
            reuse_view: labelled_view(&reuse, "sssm_reuse_share"),
            reuse,
        }
    }
}

impl SeparableSoftShadowMaps {
    /// Builds the depth map, the intermediate targets and the three passes.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = SssmSettings::from_params(setup.params)?;
        let device = &setup.gpu.device;
        let depth_map = settings.bias.depth_map(setup, "sssm_shadow_map", settings.shadow_map_size)?;
        let targets = Targets::new(device, setup.scene.width, setup.scene.height);
        let settings_buffer = uniform_buffer(device, "sssm_settings_uniform", &SssmSettingsUniform::from(&settings));
        let layouts = Self::layouts(device);
        let read_counts = ReadCounts::new(device, "sssm_read_counts", COUNTED_PASSES, settings.count_reads);
        let groups = Self::bind_groups(setup, &layouts, (&settings_buffer, &depth_map, read_counts.buffer()), &targets);
        let module = |label: &str, source: &str| create_shader_with_imports(setup.gpu, label, source, LOCAL_SHADERS);
        let rgba = wgpu::ColorTargetState::from(wgpu::TextureFormat::Rgba32Float);
        let [layout_a, layout_b, layout_c] = &layouts;
        let horizontal_blocker = ScreenPass::new(
            setup,
            NAME,
            "sssm_horizontal_blocker",
            (&module("sssm_horizontal_blocker_shader", HORIZONTAL_BLOCKER_SHADER)?, "sssm_horizontal_blocker"),
            Some(layout_a),
            rgba.clone(),
        )?;
        let blocker_blur = ScreenPass::new(
            setup,
            NAME,
            "sssm_blocker_and_horizontal_blur",
            (&module("sssm_blocker_blur_shader", BLOCKER_BLUR_SHADER)?, "sssm_blocker_blur"),
            Some(layout_b),
            rgba,
        )?;
        let vertical_blur = ScreenPass::new(
            setup,
            NAME,
            "sssm_vertical_blur",
            (&module("sssm_vertical_blur_shader", VERTICAL_BLUR_SHADER)?, "sssm_vertical_blur"),
            Some(layout_c),
            VISIBILITY_FORMAT.into(),
        )?;
        Ok(Self {
            depth_map,
            horizontal_blocker,
            blocker_blur,
            vertical_blur,
            groups,
            horizontal_blocker_view: targets.horizontal_blocker,
            horizontal_blur_view: targets.horizontal_blur,
            reuse: targets.reuse,
            read_counts,
        })
    }

    /// The three passes' own layouts: camera, settings and depth map, then what each reads and writes.
    fn layouts(device: &wgpu::Device) -> [wgpu::BindGroupLayout; 3] {
        let common = [uniform_entry(0), uniform_entry(1), texture_entry(2), ReadCounts::layout_entry(3)];
        let layout = |label: &str, extra: &[wgpu::BindGroupLayoutEntry]| {
            let entries: Vec<wgpu::BindGroupLayoutEntry> = common.iter().chain(extra).copied().collect();
            bind_group_layout(device, label, &entries)
        };
        let reuse_storage = wgpu::BindGroupLayoutEntry {
            binding: 6,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::R32Float,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        };
        [
            layout("sssm_horizontal_blocker_layout", &[]),
            layout("sssm_blocker_blur_layout", &[texture_entry(4)]),
            layout("sssm_vertical_blur_layout", &[texture_entry(4), texture_entry(5), reuse_storage]),
        ]
    }

    fn bind_groups(
        setup: &TechniqueSetup<'_>,
        [layout_a, layout_b, layout_c]: &[wgpu::BindGroupLayout; 3],
        (settings_buffer, depth_map, read_counts): (&wgpu::Buffer, &LightDepthMap, &wgpu::Buffer),
        targets: &Targets,
    ) -> [wgpu::BindGroup; 3] {
        let device = &setup.gpu.device;
        let group = |label: &str, layout: &wgpu::BindGroupLayout, extra: &[wgpu::BindingResource<'_>]| {
            let mut resources = vec![
                setup.scene.camera_buffer.as_entire_binding(),
                settings_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&depth_map.linear_depth_view),
                read_counts.as_entire_binding(),
            ];
            resources.extend_from_slice(extra);
            bind_group(device, label, layout, &resources)
        };
        [
            group("sssm_horizontal_blocker_bind_group", layout_a, &[]),
            group("sssm_blocker_blur_bind_group", layout_b, &[wgpu::BindingResource::TextureView(&targets.horizontal_blocker)]),
            group(
                "sssm_vertical_blur_bind_group",
                layout_c,
                &[
                    wgpu::BindingResource::TextureView(&targets.horizontal_blocker),
                    wgpu::BindingResource::TextureView(&targets.horizontal_blur),
                    wgpu::BindingResource::TextureView(&targets.reuse_view),
                ],
            ),
        ]
    }

    /// The reuse share per pixel of the last light rendered (-1 where nothing was computed).
    fn reuse_share(&self, gpu: &GpuContext) -> Result<Vec<f32>> {
        let bytes = read_texture(gpu, &self.reuse, 4, "SSSM reuse share")?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

impl ShadowTechnique for SeparableSoftShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let [group_a, group_b, group_c] = &self.groups;
        self.read_counts.clear(frame, light);
        self.depth_map.encode(frame, light);
        self.horizontal_blocker.encode(frame, light, &self.horizontal_blocker_view, Some(group_a), Some(wgpu::Color::TRANSPARENT));
        self.blocker_blur.encode(frame, light, &self.horizontal_blur_view, Some(group_b), Some(wgpu::Color::TRANSPARENT));
        self.vertical_blur.encode(frame, light, output, Some(group_c), None);
        Ok(())
    }

    /// `sssm_reuse_share`: the mean share of rows reused, over the pixels computed (the paper's Fig. 10).
    fn diagnostics(&mut self, gpu: &GpuContext) -> Vec<(String, f64)> {
        let Ok(share) = self.reuse_share(gpu) else { return Vec::new() };
        let computed: Vec<f64> = share.iter().filter(|v| **v >= 0.0).map(|v| f64::from(*v)).collect();
        if computed.is_empty() {
            return Vec::new();
        }
        let mut out = vec![("sssm_reuse_share".to_owned(), computed.iter().sum::<f64>() / computed.len() as f64)];
        out.extend(self.read_counts.diagnostics(gpu));
        out
    }

    fn extra_images(&mut self, gpu: &GpuContext) -> Result<Vec<ExtraImage>> {
        let values = self.reuse_share(gpu)?.into_iter().map(|v| v.max(0.0)).collect();
        Ok(vec![ExtraImage { name: "reuse_share".into(), width: self.reuse.width(), height: self.reuse.height(), values, overlay: false }])
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(SeparableSoftShadowMaps::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    Ok(screen_space_requirements(SssmSettings::from_params(params)?.shadow_map_size))
}

/// Buades et al.'s evaluations, as sweeps.
const PRESETS: &[ssm_core::Preset] = &[ssm_core::Preset {
    name: "sssm-table4",
    summary: "Buades et al., Table 4: PCSS and SSSM at kernel pairs 7/15, 11/21, 29/41, SSSM with alpha = beta from little to much reuse; both with the receiver-plane model (on leaves, the plant scene's nearest)",
    scenes: &["leaves"],
    varies: &[
        "pcss.blocker_kernel:pcf_kernel=7:15,11:21,29:41",
        "sssm.blocker_kernel:blur_kernel=7:15,11:21,29:41",
        "sssm.alpha:beta=0.001:0.001,0.01:0.01,0.02:0.02,0.05:0.05,0.2:0.2",
    ],
    ..ssm_core::Preset::DEFAULT
}];

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "separable soft shadow mapping: separable blocker search reusing rows (α) and separable screen-space blur (β)",
    paper: "Buades, Gumbau and Chover 2015, Separable soft shadow mapping (The Visual Computer)",
    kind: TechniqueKind::Realtime,
    params: SssmSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("blocker_kernel:blur_kernel=3:5,7:15,11:21,29:41"),
    uniforms: &[UniformCheck {
        wgsl_struct: "SssmSettings",
        wgsl_source: HORIZONTAL_BLOCKER_SHADER,
        imports: LOCAL_SHADERS,
        rust: SssmSettingsUniform::LAYOUT,
    }],
};

register_technique!(INFO);
