//! Atty, Holzschuch, Lapierre, Hasenfratz, Hansen and Sillion, *Soft Shadow
//! Maps: Efficient Sampling of Light Source Visibility*, Computer Graphics
//! Forum 25(4), 2006.
//!
//! The occluders, seen from the light's centre, become one micro-patch per
//! occluder-map texel, parallel to the light at that texel's depth (Sec. 3.2).
//! Each patch's penumbra extent is a pyramid whose section on the soft shadow
//! map (SSM) is an axis-aligned rectangle (Sec. 3.3); for every SSM texel in
//! it, the patch is projected back onto the light from the receiver there, and
//! the hidden fraction, a product of two clamped 1-D overlaps, is added into a
//! float map by blending (Sec. 3.4, 4.2). The SSM is then projected onto the
//! receivers. The two-sided variant does this for the nearest front faces and
//! the farthest back faces and keeps the larger occlusion (Sec. 3.5).
//!
//! Unlike the paper, nothing goes back to the CPU: the instanced quad of each
//! occluder texel is built in the vertex stage (the paper's stated next step,
//! Sec. 4.3 and 7), so the cost no longer grows with a readback.

use bytemuck::{Pod, Zeroable};
use ssm_core::passes::{
    bind_group, bind_group_layout, color_attachment, labelled_view, render_texture, texture_entry, uniform_buffer, uniform_entry,
};
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    Choice, Error, Frame, Geometry, LightDepthMap, LightDepthMapDesc, ParamValues, Requirements, Result, ScreenPass, Settings,
    ShadowMapBias, ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct, VISIBILITY_FORMAT,
    register_technique,
};

/// The registered name.
pub const NAME: &str = "atty";

/// WGSL files the Atty shaders import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] = &[("atty/atty_settings.wgsl", include_str!("../../../shaders/atty/atty_settings.wgsl"))];
/// The accumulation of micro-patches into the SSM.
const ACCUMULATE_SHADER: &str = include_str!("../../../shaders/atty/atty_accumulate.wgsl");
/// The projection of the SSM onto the screen.
const PROJECT_SHADER: &str = include_str!("../../../shaders/atty/atty_project.wgsl");

/// The format the micro-patches' occlusions are summed in (Sec. 4.1, Appendix A).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Choice)]
pub enum Accumulation {
    /// 32-bit float: needs FLOAT32_BLENDABLE.
    F32,
    /// 16-bit float: the paper's 2006 hardware; loses patches that hide less than 2⁻¹⁰ of the light.
    F16,
}

impl Accumulation {
    /// The soft shadow map's texture format.
    #[must_use]
    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            Self::F32 => wgpu::TextureFormat::R32Float,
            Self::F16 => wgpu::TextureFormat::R16Float,
        }
    }
}

/// Settings of [`SoftShadowMaps`]: its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Settings)]
pub struct AttySettings {
    /// Side of the occluder map, texels: one micro-patch per texel (cost grows with its square).
    #[param(default = 256, min = 32, max = 2048)]
    pub occluder_map_size: u32,
    /// Side of the soft shadow map and of the receiver map, texels.
    #[param(default = 512, min = 32, max = 4096)]
    pub ssm_size: u32,
    /// Also discretise the farthest back faces and keep the larger occlusion (Sec. 3.5; about twice the cost).
    #[param(default = false)]
    pub two_sided: bool,
    /// Format of the soft shadow map the patches are summed into: f32 (needs FLOAT32_BLENDABLE) or f16 (the paper's hardware; see Appendix A).
    #[param(choice, default = "f32")]
    pub accumulation: Accumulation,
    /// Projection lookup point moved off the surface along its normal, in receiver-map texels.
    #[param(default = 0.5, min = 0.0, max = 8.0)]
    pub normal_offset: f32,
    /// Receiver-map depths within this many texel footprints (world size of one receiver-map texel at the depth looked up) of a receiver count as that receiver: the SSM's bilinear lookup blends only those, and a point farther behind is hidden (in umbra).
    #[param(default = 2.0, min = 0.0, max = 64.0)]
    pub receiver_tolerance: f32,
    /// A micro-patch less than this many of its widths in front of a receiver hides nothing: removes the moiré of objects with role `both` shadowing themselves, but also the shadow of an occluder that close to a receiver (0: the paper).
    #[param(default = 0.0, min = 0.0, max = 16.0)]
    pub self_shadow_tolerance: f32,
}

/// The settings uniform both Atty shaders read (`AttySettings` in `shaders/atty/atty_settings.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, UniformStruct)]
pub struct AttySettingsUniform {
    occluder_map_size: f32,
    soft_shadow_map_size: f32,
    normal_offset: f32,
    receiver_tolerance: f32,
    self_shadow_tolerance: f32,
    receiver_bias: f32,
    _pad0: f32,
    _pad1: f32,
}

impl From<&AttySettings> for AttySettingsUniform {
    fn from(settings: &AttySettings) -> Self {
        Self {
            occluder_map_size: settings.occluder_map_size as f32,
            soft_shadow_map_size: settings.ssm_size as f32,
            normal_offset: settings.normal_offset,
            receiver_tolerance: settings.receiver_tolerance,
            self_shadow_tolerance: settings.self_shadow_tolerance,
            // The baselines' default constant bias, a fraction of the scene's diagonal.
            receiver_bias: ShadowMapBias::default().constant_bias,
            _pad0: 0.0,
            _pad1: 0.0,
        }
    }
}

/// One soft shadow map and the pass that fills it from one occluder map.
struct SideAccumulation {
    occluder_map: LightDepthMap,
    soft_shadow_map: wgpu::TextureView,
    bind_group: wgpu::BindGroup,
    label: &'static str,
}

/// Atty et al.'s soft shadow maps.
pub struct SoftShadowMaps {
    receiver_map: LightDepthMap,
    /// Front faces (or every face, one-sided), then back faces when two-sided.
    accumulations: Vec<SideAccumulation>,
    accumulate_pipeline: wgpu::RenderPipeline,
    project: ScreenPass,
    project_group: wgpu::BindGroup,
    patches: u32,
}

/// A linear depth map of the occluders or receivers, without bias: micro-patches and receivers sit at their true depths.
fn unbiased_depth_map(
    setup: &TechniqueSetup<'_>,
    label: &str,
    size: u32,
    geometry: Geometry,
    (cull_mode, farthest): (Option<wgpu::Face>, bool),
) -> Result<LightDepthMap> {
    LightDepthMap::new(
        setup.gpu,
        setup.scene,
        &LightDepthMapDesc { label, width: size, height: size, geometry, cull_mode, farthest, constant_bias: 0.0, slope_bias: 0.0 },
    )
}

impl SoftShadowMaps {
    /// Builds the maps and pipelines.
    ///
    /// # Errors
    /// A parameter or GPU error, or [`Error::Unrepresentable`] when the receivers are too small in the light's frame.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = AttySettings::from_params(setup.params)?;
        check_receivers_resolved(setup, settings.ssm_size)?;
        let settings_buffer = uniform_buffer(&setup.gpu.device, "atty_settings_uniform", &AttySettingsUniform::from(&settings));
        let receiver_map = unbiased_depth_map(setup, "atty_receiver_map", settings.ssm_size, Geometry::Receivers, (None, false))?;
        let accumulations = Self::accumulations(setup, &settings, &receiver_map, &settings_buffer)?;
        let accumulate_pipeline = Self::accumulate_pipeline(setup, settings.accumulation)?;
        let (project, project_group) = Self::projection(setup, &accumulations, &receiver_map, &settings_buffer)?;
        Ok(Self {
            receiver_map,
            accumulations,
            accumulate_pipeline,
            project,
            project_group,
            patches: settings.occluder_map_size * settings.occluder_map_size,
        })
    }

    /// One occluder map and SSM per side: one-sided, the nearest surface of every occluder face;
    /// two-sided (Sec. 3.5), the nearest front faces and the farthest back faces.
    fn accumulations(
        setup: &TechniqueSetup<'_>,
        settings: &AttySettings,
        receiver_map: &LightDepthMap,
        settings_buffer: &wgpu::Buffer,
    ) -> Result<Vec<SideAccumulation>> {
        let device = &setup.gpu.device;
        let layout = Self::accumulate_layout(device);
        let sides: &[(&'static str, &'static str, Option<wgpu::Face>, bool)] = if settings.two_sided {
            &[
                ("atty_occluder_map_front", "atty_accumulate_front", Some(wgpu::Face::Back), false),
                ("atty_occluder_map_back", "atty_accumulate_back", Some(wgpu::Face::Front), true),
            ]
        } else {
            &[("atty_occluder_map", "atty_accumulate", None, false)]
        };
        sides
            .iter()
            .map(|&(map_label, pass_label, cull, farthest)| {
                let occluder_map = unbiased_depth_map(setup, map_label, settings.occluder_map_size, Geometry::Occluders, (cull, farthest))?;
                let texture_label = format!("{pass_label}_soft_shadow_map");
                let texture = render_texture(
                    device,
                    &texture_label,
                    settings.ssm_size,
                    settings.ssm_size,
                    settings.accumulation.format(),
                    wgpu::TextureUsages::empty(),
                );
                let bind_group = bind_group(
                    device,
                    &format!("{pass_label}_bind_group"),
                    &layout,
                    &[
                        wgpu::BindingResource::TextureView(&occluder_map.linear_depth_view),
                        wgpu::BindingResource::TextureView(&receiver_map.linear_depth_view),
                        settings_buffer.as_entire_binding(),
                    ],
                );
                Ok(SideAccumulation {
                    occluder_map,
                    soft_shadow_map: labelled_view(&texture, &texture_label),
                    bind_group,
                    label: pass_label,
                })
            })
            .collect()
    }

    fn accumulate_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        bind_group_layout(device, "atty_accumulate_layout", &[texture_entry(0), texture_entry(1), uniform_entry(2)])
    }

    /// The instanced micro-patch pipeline: one quad per occluder texel, summed by additive
    /// blending into the float SSM (Sec. 4.1).
    fn accumulate_pipeline(setup: &TechniqueSetup<'_>, accumulation: Accumulation) -> Result<wgpu::RenderPipeline> {
        let device = &setup.gpu.device;
        let module = create_shader_with_imports(setup.gpu, "atty_accumulate_shader", ACCUMULATE_SHADER, LOCAL_SHADERS)?;
        let layout = Self::accumulate_layout(device);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("atty_accumulate_pipeline_layout"),
            bind_group_layouts: &[Some(setup.gpu.uniform_layout()), Some(&layout)],
            immediate_size: 0,
        });
        let additive = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        Ok(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("atty_accumulate_pipeline"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("atty_patch_vertex"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::TriangleStrip, ..Default::default() },
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("atty_patch_fragment"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: accumulation.format(),
                    blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                    write_mask: wgpu::ColorWrites::RED,
                })],
            }),
            multiview_mask: None,
            cache: None,
        }))
    }

    /// The projection of the SSM (the larger occlusion of both sides) onto the screen.
    fn projection(
        setup: &TechniqueSetup<'_>,
        accumulations: &[SideAccumulation],
        receiver_map: &LightDepthMap,
        settings_buffer: &wgpu::Buffer,
    ) -> Result<(ScreenPass, wgpu::BindGroup)> {
        let device = &setup.gpu.device;
        let layout =
            bind_group_layout(device, "atty_project_layout", &[texture_entry(0), texture_entry(1), texture_entry(2), uniform_entry(3)]);
        let Some(front) = accumulations.first().map(|a| &a.soft_shadow_map) else {
            return Err(Error::Technique { technique: NAME.into(), message: "no occluder side to project".into() });
        };
        // One-sided: the front map stands in for the back one (max(x, x) = x).
        let back = accumulations.get(1).map_or(front, |a| &a.soft_shadow_map);
        let group = bind_group(
            device,
            "atty_project_bind_group",
            &layout,
            &[
                wgpu::BindingResource::TextureView(front),
                wgpu::BindingResource::TextureView(back),
                wgpu::BindingResource::TextureView(&receiver_map.linear_depth_view),
                settings_buffer.as_entire_binding(),
            ],
        );
        let module = create_shader_with_imports(setup.gpu, "atty_project_shader", PROJECT_SHADER, LOCAL_SHADERS)?;
        let project = ScreenPass::new(setup, NAME, "atty_project", (&module, "atty_project"), Some(&layout), VISIBILITY_FORMAT.into())?;
        Ok((project, group))
    }
}

/// Fewest receiver-map texels across the receivers for the SSM to represent a penumbra on them.
const MIN_RECEIVER_TEXELS: f32 = 4.0;

/// The SSM lives on the receiver map of the light's frame. When that frame must be very wide (an
/// occluder almost touching the light, which every technique's frame keeps), the receivers can
/// shrink below a texel of it and would silently read as lit: refuse instead.
fn check_receivers_resolved(setup: &TechniqueSetup<'_>, ssm_size: u32) -> Result<()> {
    for (light, frame) in setup.scene.light_frames.iter().enumerate() {
        let texels = frame.footprint_texels(&setup.scene.receiver_bounds, ssm_size);
        if !setup.scene.receiver_bounds.is_empty() && texels.min_element() < MIN_RECEIVER_TEXELS {
            return Err(Error::Unrepresentable {
                technique: NAME.into(),
                reason: format!(
                    "light {light}'s frame is {:.1}° wide (an occluder lies almost in the light's plane), so the receivers cover only {:.1}×{:.1} texels of the {ssm_size}² soft shadow map; at least {MIN_RECEIVER_TEXELS} are needed",
                    2.0 * frame.tan_half.max_element().atan().to_degrees(),
                    texels.x,
                    texels.y
                ),
            });
        }
    }
    Ok(())
}

impl ShadowTechnique for SoftShadowMaps {
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()> {
        let light_frame = frame
            .scene
            .light_bind_groups
            .get(light)
            .ok_or_else(|| Error::Technique { technique: NAME.into(), message: format!("no light {light}") })?;
        self.receiver_map.encode(frame, light);
        for accumulation in &self.accumulations {
            accumulation.occluder_map.encode(frame, light);
            let mut pass = frame.render_pass(
                accumulation.label,
                &[color_attachment(&accumulation.soft_shadow_map, Some(wgpu::Color::TRANSPARENT))],
                None,
            );
            pass.set_pipeline(&self.accumulate_pipeline);
            pass.set_bind_group(0, light_frame, &[]);
            pass.set_bind_group(1, &accumulation.bind_group, &[]);
            // One quad (4-vertex strip) per occluder texel.
            pass.draw(0..4, 0..self.patches);
        }
        self.project.encode(frame, light, output, Some(&self.project_group), None);
        Ok(())
    }
}

fn requirements(params: &ParamValues) -> Result<Requirements> {
    let settings = AttySettings::from_params(params)?;
    // f32 accumulation blends into R32Float: never silently fall back to another precision.
    let features = if settings.accumulation == Accumulation::F32 { wgpu::Features::FLOAT32_BLENDABLE } else { wgpu::Features::empty() };
    Ok(Requirements {
        gbuffer: true,
        roles: true,
        features,
        max_texture_size: settings.occluder_map_size.max(settings.ssm_size),
        ..Requirements::NONE
    })
}

fn create(setup: &TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>> {
    Ok(Box::new(SoftShadowMaps::new(setup)?))
}

/// The registration.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: NAME,
    summary: "soft shadow maps: occluder micro-patches back-projected onto the light, accumulated on the GPU (one- and two-sided)",
    paper: "Atty et al. 2006, Soft Shadow Maps: Efficient Sampling of Light Source Visibility (CGF 25(4))",
    kind: TechniqueKind::Realtime,
    params: AttySettings::PARAMS,
    requirements,
    create,
    presets: PRESETS,
    trade: Some("occluder_map_size=64,128,256,512"),
    uniforms: &[UniformCheck {
        wgsl_struct: "AttySettings",
        wgsl_source: PROJECT_SHADER,
        imports: LOCAL_SHADERS,
        rust: AttySettingsUniform::LAYOUT,
    }],
};

/// Atty et al.'s studies (Sec. 5.2 and 6.2), as sweeps.
const PRESETS: &[ssm_core::Preset] = &[
    ssm_core::Preset {
        name: "atty-map-size",
        summary: "Atty et al., Fig. 17 (error) and Fig. 22 (time, with --error time) against the occluder map's size, one- and two-sided",
        scenes: &["floating-sphere"],
        varies: &["atty.occluder_map_size=33,63,127,200,255,383,511", "atty.two_sided=false,true"],
        x_axis: "atty.occluder_map_size",
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-map-size-time",
        summary: "Atty et al., Fig. 22: frame time against the occluder map's size (128², 256², 512²), one- and two-sided",
        scenes: &["floating-sphere"],
        varies: &["atty.occluder_map_size=128,256,512", "atty.two_sided=false,true"],
        x_axis: "atty.occluder_map_size",
        y_axis: "time",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-light-size",
        summary: "Atty et al., Fig. 18 and Fig. 24(b) (error; Fig. 24(a), time, with --error time) against the light's size for 63², 127², 255² maps (not powers of two, as the paper notes in Sec. 5.2.3; a thick occluder such as floating-sphere)",
        scenes: &["floating-sphere"],
        varies: &["scene.light_scale=0.02,0.25,0.5,1,1.5,2", "atty.occluder_map_size=63,127,255"],
        x_axis: "scene.light_scale",
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
    ssm_core::Preset {
        name: "atty-occluder-height",
        summary: "Atty et al., Fig. 20: error as the occluders move from the receiver towards the light (on floating-sphere: from 0.05 above the ground to 0.05 below the light)",
        scenes: &["floating-sphere"],
        varies: &["scene.occluder_lift=-0.75,-0.5,0,0.5,1,1.5,1.9,1.95", "atty.two_sided=false,true"],
        x_axis: "scene.occluder_lift",
        pixels: "receivers",
        ..ssm_core::Preset::DEFAULT
    },
];

register_technique!(INFO);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_accumulation_declares_float32_blendable_and_f16_does_not() {
        let mut params = INFO.default_params();
        params.set("accumulation", "f32").unwrap();
        let f32_needs = requirements(&params).unwrap();
        assert!(f32_needs.features.contains(wgpu::Features::FLOAT32_BLENDABLE) && f32_needs.roles && f32_needs.gbuffer);
        params.set("accumulation", "f16").unwrap();
        assert!(requirements(&params).unwrap().features.is_empty(), "f16 blends on any device");
        params.set("occluder_map_size", "2048").unwrap();
        assert_eq!(requirements(&params).unwrap().max_texture_size, 2048);
    }
}
