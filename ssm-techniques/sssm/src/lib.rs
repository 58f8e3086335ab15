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
use ssm_core::passes::{labelled_view, render_texture, texture_entry, uniform_entry};
use ssm_core::readback::read_texture;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    ExtraImage, Frame, GpuContext, LightDepthMap, ParamKind, ParamSpec, ParamValues, Result, ScreenPass, ShadowMapSettings,
    ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, VISIBILITY_FORMAT, register_technique,
};
use wgpu::util::DeviceExt;

/// The registered name.
pub const NAME: &str = "sssm";

/// Parameters of [`SeparableSoftShadowMaps`].
pub const PARAMS: &[ParamSpec] = &[
    ShadowMapSettings::size_param(1024),
    ParamSpec {
        name: "blocker_kernel",
        kind: ParamKind::Int { default: 7, min: 1, max: 64 },
        doc: "n: samples per axis of the blocker search window",
    },
    ParamSpec {
        name: "blur_kernel",
        kind: ParamKind::Int { default: 15, min: 1, max: 128 },
        doc: "m: taps per axis of the screen-space blur",
    },
    ParamSpec {
        name: "alpha",
        kind: ParamKind::Float { default: 0.01, min: 0.0, max: 1.0 },
        doc: "α: blocker rows are reused when light depths differ by less than this fraction of the scene's diagonal (0: never)",
    },
    ParamSpec {
        name: "beta",
        kind: ParamKind::Float { default: 0.01, min: 0.0, max: 1.0 },
        doc: "β: blur rows are reused when normal-adjusted camera depths differ by less than this fraction of the scene's diagonal (0: never)",
    },
    ParamSpec {
        name: "filter",
        kind: ParamKind::Choice { default: "gaussian", options: &["gaussian", "mean"] },
        doc: "blur weights (Sec. 4.4)",
    },
    ParamSpec {
        name: "sigma",
        kind: ParamKind::Float { default: 0.5, min: 0.05, max: 4.0 },
        doc: "Gaussian standard deviation in units of the blur's half-width (the paper's N(0, 0.5))",
    },
    ShadowMapSettings::RECEIVER_PLANE_PARAM,
    ParamSpec {
        name: "bilateral_depth",
        kind: ParamKind::Float { default: 0.005, min: 0.0, max: 1.0 },
        doc: "blur taps are weighted by exp(-(Δ/t)²) for a camera-distance gap Δ to this pixel's tangent plane, t this fraction of the scene's diagonal, and by their normals' agreement, so shadow does not leak across silhouettes (0: the paper's unweighted blur)",
    },
    ShadowMapSettings::BIAS_PARAMS[0],
    ShadowMapSettings::BIAS_PARAMS[1],
    ShadowMapSettings::BIAS_PARAMS[2],
];

/// WGSL files the SSSM passes import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] = &[("sssm/sssm_common.wgsl", include_str!("../../../shaders/sssm/sssm_common.wgsl"))];

/// `SssmSettings` of `shaders/sssm/sssm_common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct SssmSettingsUniform {
    blocker_kernel: u32,
    blur_kernel: u32,
    gaussian: u32,
    receiver_plane: u32,
    alpha: f32,
    beta: f32,
    sigma: f32,
    normal_offset: f32,
    pixel_scale: f32,
    light_half_size: f32,
    bilateral_depth: f32,
    padding: f32,
}

/// Separable soft shadow mapping.
pub struct SeparableSoftShadowMaps {
    depth_map: LightDepthMap,
    horizontal_blocker: ScreenPass,
    blocker_blur: ScreenPass,
    vertical_blur: ScreenPass,
    /// Per light: the three passes' own bind groups (the settings hold the light's size).
    groups: Vec<[wgpu::BindGroup; 3]>,
    horizontal_blocker_view: wgpu::TextureView,
    horizontal_blur_view: wgpu::TextureView,
    reuse: wgpu::Texture,
}

impl SeparableSoftShadowMaps {
    /// Builds the depth map, the intermediate targets and the three passes.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let params = setup.params;
        let map_settings = ShadowMapSettings::from_params(params)?;
        let device = &setup.gpu.device;
        let (width, height) = (setup.scene.width, setup.scene.height);
        let depth_map = map_settings.depth_map(setup, "sssm_shadow_map")?;
        let target = |label: &str| {
            let texture = render_texture(device, label, width, height, wgpu::TextureFormat::Rgba32Float, wgpu::TextureUsages::empty());
            labelled_view(&texture, label)
        };
        let horizontal_blocker_view = target("sssm_horizontal_blocker_target");
        let horizontal_blur_view = target("sssm_horizontal_blur_target");
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
        let reuse_view = labelled_view(&reuse, "sssm_reuse_share");

        let common = [uniform_entry(0), uniform_entry(1), texture_entry(2)];
        let layout = |label: &str, extra: &[wgpu::BindGroupLayoutEntry]| {
            let entries: Vec<wgpu::BindGroupLayoutEntry> = common.iter().chain(extra).copied().collect();
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
        };
        let layout_a = layout("sssm_horizontal_blocker_layout", &[]);
        let layout_b = layout("sssm_blocker_blur_layout", &[texture_entry(3)]);
        let storage = wgpu::BindGroupLayoutEntry {
            binding: 5,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::R32Float,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        };
        let layout_c = layout("sssm_vertical_blur_layout", &[texture_entry(3), texture_entry(4), storage]);

        let diagonal = setup.scene.bounds.size().length();
        let camera = &setup.cpu_scene.camera;
        let gaussian = u32::from(params.choice("filter")? == "gaussian");
        let kernel = |name| params.int(name).map(|v| u32::try_from(v).unwrap_or(1));
        let (blocker_kernel, blur_kernel) = (kernel("blocker_kernel")?, kernel("blur_kernel")?);
        let (alpha, beta, sigma) =
            (params.float("alpha")? as f32 * diagonal, params.float("beta")? as f32 * diagonal, params.float("sigma")? as f32);
        let receiver_plane = u32::from(params.bool("receiver_plane")?);
        let bilateral_depth = params.float("bilateral_depth")? as f32 * diagonal;
        let mut groups = Vec::new();
        for (light_index, light_frame) in setup.scene.light_frames.iter().enumerate() {
            let uniform = SssmSettingsUniform {
                blocker_kernel,
                blur_kernel,
                gaussian,
                receiver_plane,
                alpha,
                beta,
                sigma,
                normal_offset: map_settings.normal_offset,
                pixel_scale: 2.0 * (camera.fov_y * 0.5).tan() / height as f32,
                light_half_size: 0.5 * (light_frame.light.half_size.x + light_frame.light.half_size.y),
                bilateral_depth,
                padding: 0.0,
            };
            let settings_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("sssm_settings_uniform_{light_index}")),
                contents: bytemuck::bytes_of(&uniform),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let group = |label: &str, layout: &wgpu::BindGroupLayout, extra: &[wgpu::BindingResource<'_>]| {
                let mut entries = vec![
                    wgpu::BindGroupEntry { binding: 0, resource: setup.scene.camera_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: settings_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&depth_map.linear_depth_view) },
                ];
                for (index, resource) in extra.iter().enumerate() {
                    entries.push(wgpu::BindGroupEntry { binding: 3 + index as u32, resource: resource.clone() });
                }
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&format!("{label}_{light_index}")),
                    layout,
                    entries: &entries,
                })
            };
            groups.push([
                group("sssm_horizontal_blocker_bind_group", &layout_a, &[]),
                group("sssm_blocker_blur_bind_group", &layout_b, &[wgpu::BindingResource::TextureView(&horizontal_blocker_view)]),
                group(
                    "sssm_vertical_blur_bind_group",
                    &layout_c,
                    &[
                        wgpu::BindingResource::TextureView(&horizontal_blocker_view),
                        wgpu::BindingResource::TextureView(&horizontal_blur_view),
                        wgpu::BindingResource::TextureView(&reuse_view),
                    ],
                ),
            ]);
        }
        let module = |file: &str, source: &str| create_shader_with_imports(setup.gpu, file, source, LOCAL_SHADERS);
        let rgba = wgpu::ColorTargetState::from(wgpu::TextureFormat::Rgba32Float);
        let horizontal_blocker = ScreenPass::new(
            setup,
            NAME,
            "sssm_horizontal_blocker",
            (
                &module("sssm_horizontal_blocker_shader", include_str!("../../../shaders/sssm/sssm_horizontal_blocker.wgsl"))?,
                "sssm_horizontal_blocker",
            ),
            Some(&layout_a),
            rgba.clone(),
        )?;
        let blocker_blur = ScreenPass::new(
            setup,
            NAME,
            "sssm_blocker_and_horizontal_blur",
            (&module("sssm_blocker_blur_shader", include_str!("../../../shaders/sssm/sssm_blocker_blur.wgsl"))?, "sssm_blocker_blur"),
            Some(&layout_b),
            rgba,
        )?;
        let vertical_blur = ScreenPass::new(
            setup,
            NAME,
            "sssm_vertical_blur",
            (&module("sssm_vertical_blur_shader", include_str!("../../../shaders/sssm/sssm_vertical_blur.wgsl"))?, "sssm_vertical_blur"),
            Some(&layout_c),
            VISIBILITY_FORMAT.into(),
        )?;
        Ok(Self {
            depth_map,
            horizontal_blocker,
            blocker_blur,
            vertical_blur,
            groups,
            horizontal_blocker_view,
            horizontal_blur_view,
            reuse,
        })
    }

    /// The reuse share per pixel of the last light rendered (-1 where nothing was computed).
    fn reuse_share(&self, gpu: &GpuContext) -> Result<Vec<f32>> {
        let bytes = read_texture(gpu, &self.reuse, 4, "SSSM reuse share")?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

impl ShadowTechnique for SeparableSoftShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let Some([group_a, group_b, group_c]) = self.groups.get(light) else {
            return Err(ssm_core::Error::Technique { technique: NAME.into(), message: format!("no light {light}") });
        };
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
        vec![("sssm_reuse_share".to_owned(), computed.iter().sum::<f64>() / computed.len() as f64)]
    }

    fn extra_images(&mut self, gpu: &GpuContext) -> Result<Vec<ExtraImage>> {
        let values = self.reuse_share(gpu)?.into_iter().map(|v| v.max(0.0)).collect();
        Ok(vec![ExtraImage { name: "reuse_share".into(), width: self.reuse.width(), height: self.reuse.height(), values }])
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(SeparableSoftShadowMaps::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<ssm_core::Requirements> {
    ShadowMapSettings::screen_space_requirements(params)
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "separable soft shadow mapping: separable blocker search reusing rows (α) and separable screen-space blur (β)",
    paper: "Buades, Gumbau and Chover 2015, Separable soft shadow mapping (The Visual Computer)",
    kind: TechniqueKind::Realtime,
    params: PARAMS,
    requirements,
    create,
};

register_technique!(INFO);
