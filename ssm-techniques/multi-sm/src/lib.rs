//! Baseline: the average of K hard shadow maps rendered from stratified points
//! on the rectangular light. It converges to the exact visibility as K grows
//! (up to each map's own discretisation), at K times the cost of a hard
//! shadow: the reference of Shen et al. (2011, Table 2) and of Buades et al.
//! (2015, Fig. 13).
//!
//! # Example
//!
//! From the command line: `ssm render --scene contact --technique multi-sm --set
//! multi-sm.samples=4 --out out` (`ssm list` gives every parameter). From Rust, through the
//! framework, as every technique crate is used (`ssm_multi_sm::link()` keeps its registration in
//! the binary; `ssm_techniques::link_all()` links every crate of the workspace):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_multi_sm::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("contact")?.build();
//! let info = Registry::global()?.get("multi-sm")?;
//! let params = info.params_from([("samples", "4")])?;
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
use glam::Vec2;
use ssm_core::passes::{
    bind_group, bind_group_layout, color_attachment, compute_pipeline, labelled_view, render_texture, texture_entry, uniform_buffer,
    uniform_entry, visibility_storage_entry,
};
use ssm_core::read_counts::ReadCounts;
use ssm_core::shader::create_shader_with_imports;
use ssm_core::ssm_scene::RectLight;
use ssm_core::{
    Error, Frame, GpuContext, LightDepthMap, LightFrame, LightFrameUniform, ParamValues, Requirements, Result, SHADOW_MAP_MAX_SIZE,
    SHADOW_MAP_MIN_SIZE, Settings, ShadowMapBias, ShadowTechnique, SideFaceFrames, SideFaceMaps, TechniqueInfo, TechniqueKind,
    TechniqueSetup, UniformCheck, UniformStruct, register_technique, screen_space_requirements,
};

/// The registered name.
pub const NAME: &str = "multi-sm";

/// The accumulation shader.
const SHADER: &str = ssm_shaders::multi_sm::MULTI_SM;
/// What the shader imports besides `common/`: its settings struct, written from the Rust one.
const LOCAL_SHADERS: &[(&str, &str)] = &[(MultiSmSettingsUniform::WGSL_IMPORT, MultiSmSettingsUniform::WGSL)];
/// The accumulation pass's label.
const ACCUMULATE_PASS: &str = "multi_sm_accumulate";
/// What the accumulation counts in a counting frame, in the order its shader indexes them: texel
/// reads, bytes stored and the bytes the reads fetched (the clears and the K shadow-map passes
/// read no texel).
const COUNTERS: &[(&str, &str)] = &[(ACCUMULATE_PASS, "reads"), (ACCUMULATE_PASS, "storage_bytes"), (ACCUMULATE_PASS, "read_bytes")];

/// Settings of [`MultiShadowMaps`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct MultiSmSettings {
    /// K, the number of shadow maps: a perfect square, one per stratum of a √K×√K grid on the light.
    #[param(default = 16, min = 1, max = 1024)]
    pub samples: u32,
    /// Side of each square shadow map, texels.
    #[param(default = 1024, min = SHADOW_MAP_MIN_SIZE, max = SHADOW_MAP_MAX_SIZE)]
    pub shadow_map_size: u32,
    /// Depth bias and normal offset.
    #[param(flatten)]
    pub bias: ShadowMapBias,
}

/// The accumulation settings as `shaders/multi-sm/multi_sm.wgsl` reads them: the WGSL struct
/// `MultiSmSettings`, which the derive writes and the shader imports (`// #import rust/MultiSmSettings`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct MultiSmSettingsUniform {
    /// 1 / K.
    weight: f32,
    /// Normal offset of the lookup point, in shadow-map texels.
    normal_offset: f32,
    /// Half the sides of one stratum of the light, world units (along its first and second axes).
    stratum_half_size: [f32; 2],
    /// The texels of the receiver's own depth change the side faces' bias allows.
    side_face_bias_texels: f32,
    padding_0: f32,
    padding_1: f32,
    padding_2: f32,
}

impl MultiSmSettingsUniform {
    /// The settings for a light of half sides `half_size` cut into `per_axis` × `per_axis` strata.
    fn new(settings: &MultiSmSettings, half_size: Vec2, per_axis: u32) -> Self {
        Self {
            weight: 1.0 / settings.samples.max(1) as f32,
            normal_offset: settings.bias.normal_offset,
            stratum_half_size: (half_size / per_axis.max(1) as f32).to_array(),
            side_face_bias_texels: SIDE_FACE_BIAS_TEXELS,
            padding_0: 0.0,
            padding_1: 0.0,
            padding_2: 0.0,
        }
    }
}

/// Texels of the receiver's own depth change across a side face's texel that its bias allows, as
/// the framework's hard answer past the frame (`shaders/common/side_faces.wgsl`).
const SIDE_FACE_BIAS_TEXELS: f32 = 0.75;

/// The centres of the strata of a `per_axis` × `per_axis` grid on the light, in `[-1, 1]²`.
#[must_use]
pub fn stratum_centres(per_axis: u32) -> Vec<Vec2> {
    let n = per_axis.max(1);
    (0..n * n).map(|k| (Vec2::new((k % n) as f32, (k / n) as f32) + 0.5) / n as f32 * 2.0 - Vec2::ONE).collect()
}

/// K hard shadow maps from stratified points on the light, averaged.
pub struct MultiShadowMaps {
    depth_map: LightDepthMap,
    /// Past a sample's frame's widest angle, a hemicube's side faces around the sample, drawn for
    /// one sample after another (`None` when no light reaches that angle).
    side_faces: Option<SideFaceMaps>,
    /// Per light, per sample: the frame of a point light at the sample.
    sample_frames: Vec<Vec<SampleFrame>>,
    accumulate: wgpu::ComputePipeline,
    gbuffer_bind_group: wgpu::BindGroup,
    /// Per light: the group binding the shadow map, the settings and that light's target.
    own_groups: Vec<wgpu::BindGroup>,
    /// The accumulation's counts, made in a counting frame only ([`TechniqueSetup::count_work`]).
    read_counts: ReadCounts,
    width: u32,
    height: u32,
}

impl MultiShadowMaps {
    /// Builds the sample frames, the depth map and the accumulation pipeline.
    ///
    /// # Errors
    /// A parameter error, K not a perfect square, or a GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = MultiSmSettings::from_params(setup.params)?;
        let per_axis = settings.samples.isqrt();
        if per_axis * per_axis != settings.samples {
            return Err(Error::Technique {
                technique: NAME.into(),
                message: format!("samples = {} is not a perfect square (1, 4, 9, 16, ...): the strata form a √K×√K grid", settings.samples),
            });
        }
        let device = &setup.gpu.device;
        let gbuffer = setup.shared.gbuffer(NAME)?;
        let depth_map = settings.bias.depth_map(setup, "multi_sm_shadow_map", settings.shadow_map_size)?;
        let read_counts = ReadCounts::with_units(device, "multi_sm_read_counts", COUNTERS, setup.count_work);
        let own_layout = bind_group_layout(
            device,
            "multi_sm_own_layout",
            &[
                texture_entry(0),
                uniform_entry(1),
                visibility_storage_entry(2),
                ReadCounts::layout_entry(3),
                texture_entry(4),
                texture_entry(5),
                texture_entry(6),
                texture_entry(7),
            ],
        );
        let sample_frames = sample_frames(setup, per_axis);
        // A light gets side faces where one of its samples' frames reaches the widest angle; the
        // four maps serve every sample in turn.
        let any_faces = sample_frames.iter().flatten().any(|sample| sample.side_face_frames.is_some());
        let side_faces = if any_faces { Some(SideFaceMaps::new(setup.gpu, setup.scene, "multi_sm_side")?) } else { None };
        // Without faces the bindings hold a texel that is never read: no sample's frame reaches
        // the widest angle, which is what the shader asks before it reads a face.
        let unused_face = labelled_view(
            &render_texture(device, "multi_sm_no_side_face", 1, 1, wgpu::TextureFormat::R32Float, wgpu::TextureUsages::empty()),
            "multi_sm_no_side_face",
        );
        let face_views =
            side_faces.as_ref().map_or([&unused_face; 4], SideFaceMaps::linear_depth_views).map(wgpu::BindingResource::TextureView);
        let own_groups = setup
            .outputs
            .iter()
            .enumerate()
            .map(|(light, output)| {
                let half_size = setup.scene.light_frames.get(light).map_or(Vec2::ZERO, |frame| frame.light.half_size);
                let settings_buffer = uniform_buffer(
                    device,
                    &format!("multi_sm_settings_uniform_{light}"),
                    &MultiSmSettingsUniform::new(&settings, half_size, per_axis),
                );
                let [plus_u, minus_u, plus_v, minus_v] = face_views.clone();
                bind_group(
                    device,
                    &format!("multi_sm_own_bind_group_{light}"),
                    &own_layout,
                    &[
                        wgpu::BindingResource::TextureView(&depth_map.linear_depth_view),
                        settings_buffer.as_entire_binding(),
                        wgpu::BindingResource::TextureView(output),
                        read_counts.buffer().as_entire_binding(),
                        plus_u,
                        minus_u,
                        plus_v,
                        minus_v,
                    ],
                )
            })
            .collect();
        let module = create_shader_with_imports(setup.gpu, "multi_sm_shader", SHADER, LOCAL_SHADERS)?;
        let accumulate = compute_pipeline(
            device,
            "multi_sm_accumulate_pipeline",
            &module,
            "multi_sm_accumulate",
            &[setup.gpu.uniform_layout(), &gbuffer.layout, &own_layout],
            &read_counts.pipeline_constants(),
        );
        Ok(Self {
            depth_map,
            side_faces,
            sample_frames,
            accumulate,
            gbuffer_bind_group: gbuffer.bind_group.clone(),
            own_groups,
            read_counts,
            width: setup.scene.width,
            height: setup.scene.height,
        })
    }
}

/// The light frame of a point light at one stratum's centre, its uniform buffer and bind group.
struct SampleFrame {
    frame: LightFrame,
    buffer: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    /// The side faces' frames around the sample, where its frame reaches the widest angle.
    side_face_frames: Option<SideFaceFrames>,
}

/// Per light, per stratum: the light frame of a point light at the stratum's centre, sealed
/// from the camera when the whole light is ([`LightFrame::sealed`]: every stratum is then too).
fn sample_frames(setup: &TechniqueSetup<'_>, per_axis: u32) -> Vec<Vec<SampleFrame>> {
    let device = &setup.gpu.device;
    let bounds = setup.scene.bounds;
    setup
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
                    let sample = LightFrame { sealed: frame.sealed, enclosed: frame.enclosed, ..LightFrame::fit(&point_light, &bounds) };
                    let buffer = wgpu::util::DeviceExt::create_buffer_init(
                        device,
                        &wgpu::util::BufferInitDescriptor {
                            label: Some(&format!("multi_sm_sample_frame_{light_index}_{k}")),
                            contents: bytemuck::bytes_of(&LightFrameUniform::from(&sample)),
                            // COPY_DST: the camera may move across the closed mesh that seals the light.
                            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                        },
                    );
                    let bind_group = bind_group(
                        device,
                        &format!("multi_sm_sample_frame_bind_group_{light_index}_{k}"),
                        setup.gpu.uniform_layout(),
                        &[buffer.as_entire_binding()],
                    );
                    let side_face_frames = sample
                        .reaches_widest_angle()
                        .then(|| SideFaceFrames::new(setup.gpu, &sample, &format!("multi_sm_side_light{light_index}_sample{k}")));
                    SampleFrame { frame: sample, buffer, bind_group, side_face_frames }
                })
                .collect()
        })
        .collect()
}

impl ShadowTechnique for MultiShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let no_light = || Error::Technique { technique: NAME.into(), message: format!("no light {light}") };
        let own_group = self.own_groups.get(light).ok_or_else(no_light)?;
        let frames = self.sample_frames.get_mut(light).ok_or_else(no_light)?;
        let sealed = frame.scene.light_frames.get(light).ok_or_else(no_light)?.sealed;
        for sample in frames.iter_mut().filter(|sample| sample.frame.sealed != sealed) {
            sample.frame.sealed = sealed;
            frame.gpu.queue.write_buffer(&sample.buffer, 0, bytemuck::bytes_of(&LightFrameUniform::from(&sample.frame)));
        }
        self.read_counts.clear(frame, light);
        // The sum starts at 0, not at the framework's 1.
        drop(frame.render_pass("multi_sm_clear", &[color_attachment(output, Some(wgpu::Color::TRANSPARENT))], None));
        for sample in frames.iter() {
            self.depth_map.encode_with(frame, &sample.bind_group);
            if let (Some(faces), Some(face_frames)) = (&self.side_faces, &sample.side_face_frames) {
                faces.encode(frame, face_frames);
            }
            let mut pass = frame.compute_pass(ACCUMULATE_PASS);
            pass.set_pipeline(&self.accumulate);
            pass.set_bind_group(0, &sample.bind_group, &[]);
            pass.set_bind_group(1, &self.gbuffer_bind_group, &[]);
            pass.set_bind_group(2, own_group, &[]);
            pass.dispatch_workgroups(self.width.div_ceil(8), self.height.div_ceil(8), 1);
        }
        Ok(())
    }

    fn counted_work(&mut self, gpu: &GpuContext) -> Result<Option<Vec<ssm_core::ShaderWork>>> {
        self.read_counts.work(gpu)
    }
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(MultiShadowMaps::new(setup)?))
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    Ok(screen_space_requirements(MultiSmSettings::from_params(params)?.shadow_map_size))
}

/// Sweeps of the multi-sm baseline.
const PRESETS: &[ssm_core::Preset] = &[ssm_core::Preset {
    name: "multi-sm-samples",
    summary: "multi-sm with K = 1, 4, 16, 64, 256 shadow maps",
    scenes: &["sphere-cube"],
    varies: &["multi-sm.samples=1,4,16,64,256"],
    ..ssm_core::Preset::DEFAULT
}];

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "average of K hard shadow maps from stratified points on the light (baseline; converges as K grows)",
    paper: "Heckbert and Herf 1997, Simulating soft shadows with graphics hardware (the reference of Shen et al. 2011 and Buades et al. 2015)",
    kind: TechniqueKind::Realtime,
    // A map per light sample, each with the shared rules for that point light (multi_sm.wgsl):
    // the own surface's share is in its answer, not charged twice.
    light_sampling: ssm_core::LightSampling::PerSample,
    // Past a sample's frame, that sample's hard shadow through a hemicube's side faces around it.
    light_view: ssm_core::LightView::SideFaces,
    params: MultiSmSettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("samples=1,4,16,64"),
    debug_outputs: &[],
    uniforms: &[UniformCheck {
        wgsl_struct: MultiSmSettingsUniform::WGSL_NAME,
        wgsl_source: SHADER,
        imports: LOCAL_SHADERS,
        rust: MultiSmSettingsUniform::LAYOUT,
    }],
    limits: &[],
    paper_configuration: ssm_core::PaperConfiguration::DEFAULTS,
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
