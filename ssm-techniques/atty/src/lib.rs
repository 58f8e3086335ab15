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
use ssm_core::passes::{color_attachment, labelled_view, render_texture, texture_entry, uniform_entry};
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{
    Error, Frame, Geometry, LightDepthMap, LightDepthMapDesc, ParamKind, ParamSpec, ParamValues, Requirements, Result, ScreenPass,
    ShadowTechnique, TechniqueInfo, TechniqueKind, TechniqueSetup, VISIBILITY_FORMAT, register_technique,
};
use wgpu::util::DeviceExt;

/// The registered name.
pub const NAME: &str = "atty";

/// Parameters of [`SoftShadowMaps`].
pub const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "occluder_map_size",
        kind: ParamKind::Int { default: 256, min: 32, max: 2048 },
        doc: "side of the occluder map, texels: one micro-patch per texel (cost grows with its square)",
    },
    ParamSpec {
        name: "ssm_size",
        kind: ParamKind::Int { default: 512, min: 32, max: 4096 },
        doc: "side of the soft shadow map and of the receiver map, texels",
    },
    ParamSpec {
        name: "two_sided",
        kind: ParamKind::Bool { default: false },
        doc: "also discretise the farthest back faces and keep the larger occlusion (Sec. 3.5; about twice the cost)",
    },
    ParamSpec {
        name: "accumulation",
        kind: ParamKind::Choice { default: "f32", options: &["f32", "f16"] },
        doc: "format of the soft shadow map the patches are summed into: f32 (needs FLOAT32_BLENDABLE) or f16 (the paper's hardware; see Appendix A)",
    },
    ParamSpec {
        name: "normal_offset",
        kind: ParamKind::Float { default: 0.5, min: 0.0, max: 8.0 },
        doc: "projection lookup point moved off the surface along its normal, in receiver-map texels",
    },
    ParamSpec {
        name: "receiver_tolerance",
        kind: ParamKind::Float { default: 2.0, min: 0.0, max: 64.0 },
        doc: "receiver-map depths within this many texel footprints (world size of one receiver-map texel at the depth looked up) of a receiver count as that receiver: the SSM's bilinear lookup blends only those, and a point farther behind is hidden (in umbra)",
    },
    ParamSpec {
        name: "self_shadow_tolerance",
        kind: ParamKind::Float { default: 0.0, min: 0.0, max: 16.0 },
        doc: "a micro-patch less than this many of its widths in front of a receiver hides nothing: removes the moiré of objects with role `both` shadowing themselves, but also the shadow of an occluder that close to a receiver (0: the paper)",
    },
];

/// WGSL files the Atty shaders import besides `common/`.
const LOCAL_SHADERS: &[(&str, &str)] = &[("atty/atty_settings.wgsl", include_str!("../../../shaders/atty/atty_settings.wgsl"))];

/// The settings uniform both Atty shaders read (`shaders/atty/atty_settings.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct AttySettingsUniform {
    occluder_map_size: f32,
    soft_shadow_map_size: f32,
    normal_offset: f32,
    receiver_tolerance: f32,
    self_shadow_tolerance: f32,
    receiver_bias: f32,
    padding: [f32; 2],
}

/// Settings read from the parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttySettings {
    /// Occluder map side.
    pub occluder_map_size: u32,
    /// SSM and receiver map side.
    pub ssm_size: u32,
    /// Two-sided variant.
    pub two_sided: bool,
    /// SSM format.
    pub accumulation: wgpu::TextureFormat,
    /// Normal offset, texels.
    pub normal_offset: f32,
    /// Same-receiver depth tolerance, receiver-map texel footprints.
    pub receiver_tolerance: f32,
    /// Self-shadow tolerance, micro-patch widths.
    pub self_shadow_tolerance: f32,
}

impl AttySettings {
    /// Reads the parameters.
    ///
    /// # Errors
    /// A parameter error.
    pub fn from_params(params: &ParamValues) -> Result<Self> {
        let size = |name| params.int(name).map(|v| u32::try_from(v).unwrap_or(u32::MAX));
        Ok(Self {
            occluder_map_size: size("occluder_map_size")?,
            ssm_size: size("ssm_size")?,
            two_sided: params.bool("two_sided")?,
            accumulation: match params.choice("accumulation")? {
                "f16" => wgpu::TextureFormat::R16Float,
                _ => wgpu::TextureFormat::R32Float,
            },
            normal_offset: params.float("normal_offset")? as f32,
            receiver_tolerance: params.float("receiver_tolerance")? as f32,
            self_shadow_tolerance: params.float("self_shadow_tolerance")? as f32,
        })
    }
}

/// One soft shadow map and the pass that fills it from one occluder map.
struct Accumulation {
    occluder_map: LightDepthMap,
    soft_shadow_map: wgpu::TextureView,
    bind_group: wgpu::BindGroup,
    label: &'static str,
}

/// Atty et al.'s soft shadow maps.
pub struct SoftShadowMaps {
    receiver_map: LightDepthMap,
    /// Front faces (or every face, one-sided), then back faces when two-sided.
    accumulations: Vec<Accumulation>,
    accumulate_pipeline: wgpu::RenderPipeline,
    project: ScreenPass,
    project_group: wgpu::BindGroup,
    patches: u32,
}

impl SoftShadowMaps {
    /// Builds the maps and pipelines.
    ///
    /// # Errors
    /// A parameter or GPU error.
    pub fn new(setup: &TechniqueSetup<'_>) -> Result<Self> {
        let settings = AttySettings::from_params(setup.params)?;
        check_receivers_resolved(setup, settings.ssm_size)?;
        let device = &setup.gpu.device;
        let depth_map = |label: &str, size: u32, geometry: Geometry, cull_mode: Option<wgpu::Face>, farthest: bool| {
            // No bias: micro-patches and receivers sit at their true depths.
            LightDepthMap::new(
                setup.gpu,
                setup.scene,
                &LightDepthMapDesc { label, width: size, height: size, geometry, cull_mode, farthest, constant_bias: 0.0, slope_bias: 0.0 },
            )
        };
        let receiver_map = depth_map("atty_receiver_map", settings.ssm_size, Geometry::Receivers, None, false)?;
        let uniform = AttySettingsUniform {
            occluder_map_size: settings.occluder_map_size as f32,
            soft_shadow_map_size: settings.ssm_size as f32,
            normal_offset: settings.normal_offset,
            receiver_tolerance: settings.receiver_tolerance,
            self_shadow_tolerance: settings.self_shadow_tolerance,
            // The baselines' default constant bias: 0.1% of the scene's diagonal.
            receiver_bias: 1e-3 * setup.scene.bounds.size().length(),
            padding: [0.0; 2],
        };
        let settings_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("atty_settings_uniform"),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let accumulate_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("atty_accumulate_layout"),
            entries: &[texture_entry(0), texture_entry(1), uniform_entry(2)],
        });
        // One-sided: the nearest surface of every occluder face. Two-sided (Sec. 3.5): the nearest
        // front faces, and the farthest back faces.
        let occluder_maps: Vec<(&'static str, &'static str, Option<wgpu::Face>, bool)> = if settings.two_sided {
            vec![
                ("atty_occluder_map_front", "atty_accumulate_front", Some(wgpu::Face::Back), false),
                ("atty_occluder_map_back", "atty_accumulate_back", Some(wgpu::Face::Front), true),
            ]
        } else {
            vec![("atty_occluder_map", "atty_accumulate", None, false)]
        };
        let mut accumulations = Vec::new();
        for (map_label, pass_label, cull, farthest) in occluder_maps {
            let occluder_map = depth_map(map_label, settings.occluder_map_size, Geometry::Occluders, cull, farthest)?;
            let texture_label = format!("{pass_label}_soft_shadow_map");
            let texture = render_texture(
                device,
                &texture_label,
                settings.ssm_size,
                settings.ssm_size,
                settings.accumulation,
                wgpu::TextureUsages::empty(),
            );
            let soft_shadow_map = labelled_view(&texture, &texture_label);
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&format!("{pass_label}_bind_group")),
                layout: &accumulate_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&occluder_map.linear_depth_view) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&receiver_map.linear_depth_view) },
                    wgpu::BindGroupEntry { binding: 2, resource: settings_buffer.as_entire_binding() },
                ],
            });
            accumulations.push(Accumulation { occluder_map, soft_shadow_map, bind_group, label: pass_label });
        }

        let accumulate_module = create_shader_with_imports(
            setup.gpu,
            "atty_accumulate_shader",
            include_str!("../../../shaders/atty/atty_accumulate.wgsl"),
            LOCAL_SHADERS,
        )?;
        let accumulate_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("atty_accumulate_pipeline_layout"),
            bind_group_layouts: &[Some(&setup.scene.uniform_layout), Some(&accumulate_layout)],
            immediate_size: 0,
        });
        // Sec. 4.1: the patches' occlusions are summed by additive blending into the float SSM.
        let additive = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let accumulate_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("atty_accumulate_pipeline"),
            layout: Some(&accumulate_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &accumulate_module,
                entry_point: Some("atty_patch_vertex"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState { topology: wgpu::PrimitiveTopology::TriangleStrip, ..Default::default() },
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &accumulate_module,
                entry_point: Some("atty_patch_fragment"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: settings.accumulation,
                    blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                    write_mask: wgpu::ColorWrites::RED,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });

        let project_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("atty_project_layout"),
            entries: &[texture_entry(0), texture_entry(1), texture_entry(2), uniform_entry(3)],
        });
        let front = &accumulations[0].soft_shadow_map;
        // One-sided: the front map stands in for the back one (max(x, x) = x).
        let back = accumulations.get(1).map_or(front, |a| &a.soft_shadow_map);
        let project_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("atty_project_bind_group"),
            layout: &project_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(front) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(back) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&receiver_map.linear_depth_view) },
                wgpu::BindGroupEntry { binding: 3, resource: settings_buffer.as_entire_binding() },
            ],
        });
        let project_module = create_shader_with_imports(
            setup.gpu,
            "atty_project_shader",
            include_str!("../../../shaders/atty/atty_project.wgsl"),
            LOCAL_SHADERS,
        )?;
        let project = ScreenPass::new(
            setup,
            NAME,
            "atty_project",
            (&project_module, "atty_project"),
            Some(&project_layout),
            VISIBILITY_FORMAT.into(),
        )?;
        Ok(Self {
            receiver_map,
            accumulations,
            accumulate_pipeline,
            project,
            project_group,
            patches: settings.occluder_map_size * settings.occluder_map_size,
        })
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
    let features =
        if settings.accumulation == wgpu::TextureFormat::R32Float { wgpu::Features::FLOAT32_BLENDABLE } else { wgpu::Features::empty() };
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
    params: PARAMS,
    requirements,
    create,
};

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
