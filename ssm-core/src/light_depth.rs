//! A light-space depth map pass that techniques instantiate with their own
//! size, geometry selection, culling and bias (hard shadows, PCSS, SSSM and
//! the occluder/receiver maps of Atty et al. all start from one).

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::Result;
use crate::frame::Frame;
use crate::gpu_scene::{Geometry, GpuScene, SceneVertex};
use crate::params::{ParamKind, ParamSpec};
use crate::passes::{color_attachment, labelled_view, render_texture, uniform_entry};
use crate::shader::create_shader;

/// Linear depth written where no surface was drawn (cleared value).
pub const NO_SURFACE: f32 = f32::MAX;

/// How to build a [`LightDepthMap`].
#[derive(Clone, Copy, Debug)]
pub struct LightDepthMapDesc<'a> {
    /// Label prefix of every GPU object (`"pcss_shadow_map"`).
    pub label: &'a str,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Which triangles to draw.
    pub geometry: Geometry,
    /// Faces to cull (`Some(Face::Back)` keeps faces turned to the light), or none.
    pub cull_mode: Option<wgpu::Face>,
    /// Keep the farthest surface per texel instead of the nearest (the
    /// back-face occluder map of Atty et al., Sec. 3.5).
    pub farthest: bool,
    /// Bias added to every stored depth, world units.
    pub constant_bias: f32,
    /// Bias per unit of depth change across one texel (slope-scaled bias); the
    /// depth change is clamped to 4 texels' worth of world distance.
    pub slope_bias: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct DepthBiasUniform {
    values: [f32; 4],
}

/// A light-space map of linear depth (`R32Float`: distance along the light's
/// normal of the nearest drawn surface, plus bias; [`NO_SURFACE`] where none).
#[derive(Debug)]
pub struct LightDepthMap {
    /// The linear depth map.
    pub linear_depth: wgpu::Texture,
    /// View of `linear_depth`.
    pub linear_depth_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    pipeline: wgpu::RenderPipeline,
    bias_bind_group: wgpu::BindGroup,
    label: String,
    geometry: Geometry,
    farthest: bool,
}

impl LightDepthMap {
    /// Format of [`LightDepthMap::linear_depth`].
    pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

    /// Allocates the map and builds its pipeline.
    ///
    /// # Errors
    /// [`Error::Gpu`](crate::Error::Gpu) if the shader is rejected.
    pub fn new(gpu: &GpuContext, scene: &GpuScene, desc: &LightDepthMapDesc<'_>) -> Result<Self> {
        let device = &gpu.device;
        let label = desc.label;
        let linear_depth =
            render_texture(device, &format!("{label}_linear_depth"), desc.width, desc.height, Self::FORMAT, wgpu::TextureUsages::COPY_SRC);
        let depth = render_texture(
            device,
            &format!("{label}_depth"),
            desc.width,
            desc.height,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::empty(),
        );
        let bias = DepthBiasUniform { values: [desc.constant_bias, desc.slope_bias, desc.width as f32, desc.height as f32] };
        let bias_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(&format!("{label}_bias_uniform")),
            contents: bytemuck::bytes_of(&bias),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bias_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(&format!("{label}_bias_layout")),
            entries: &[uniform_entry(0)],
        });
        let bias_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&format!("{label}_bias_bind_group")),
            layout: &bias_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: bias_buffer.as_entire_binding() }],
        });
        let module = create_shader(gpu, &format!("{label}_shader"), include_str!("../../shaders/core/light_depth.wgsl"))?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label}_pipeline_layout")),
            bind_group_layouts: &[Some(&scene.uniform_layout), Some(&bias_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(&format!("{label}_pipeline")),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("light_depth_vertex"),
                compilation_options: Default::default(),
                buffers: &[Some(SceneVertex::layout())],
            },
            primitive: wgpu::PrimitiveState { cull_mode: desc.cull_mode, front_face: wgpu::FrontFace::Ccw, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(true),
                // The light frame's depth is reversed (near = 1): nearest wins with Greater.
                depth_compare: Some(if desc.farthest { wgpu::CompareFunction::Less } else { wgpu::CompareFunction::Greater }),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("light_depth_fragment"),
                compilation_options: Default::default(),
                targets: &[Some(Self::FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(Self {
            linear_depth_view: labelled_view(&linear_depth, &format!("{label}_linear_depth")),
            linear_depth,
            depth_view: labelled_view(&depth, &format!("{label}_depth")),
            pipeline,
            bias_bind_group,
            label: label.to_owned(),
            geometry: desc.geometry,
            farthest: desc.farthest,
        })
    }

    /// Records the pass for `light`, labelled and timed with the map's label.
    pub fn encode(&self, frame: &mut Frame<'_>, light: usize) {
        let light_frame = &frame.scene.light_bind_groups[light];
        self.encode_with(frame, light_frame);
    }

    /// Records the pass seen through another frame: a bind group of
    /// [`GpuScene::uniform_layout`](crate::GpuScene) holding a
    /// [`LightFrameUniform`](crate::LightFrameUniform) (a point on the light,
    /// a tile of it...).
    pub fn encode_with(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup) {
        let scene = frame.scene;
        let mut pass = frame.render_pass(
            &self.label,
            &[color_attachment(&self.linear_depth_view, Some(wgpu::Color { r: f64::from(NO_SURFACE), g: 0.0, b: 0.0, a: 0.0 }))],
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(if self.farthest { 1.0 } else { 0.0 }),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.bias_bind_group, &[]);
        scene.draw(&mut pass, self.geometry);
    }
}

/// Size and bias of a square light depth map over all geometry, read from the
/// parameters `shadow_map_size`, `constant_bias`, `slope_bias` and
/// `normal_offset` that the shadow-map techniques share. Declare the last
/// three with [`ShadowMapSettings::BIAS_PARAMS`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowMapSettings {
    /// Side of the square map, texels.
    pub size: u32,
    /// Constant bias, fraction of the scene diagonal.
    pub constant_bias: f32,
    /// Slope-scaled bias, multiples of the depth change per texel.
    pub slope_bias: f32,
    /// Normal offset of the lookup point, shadow-map texels (used by the lookup shader).
    pub normal_offset: f32,
}

impl ShadowMapSettings {
    /// `constant_bias`, `slope_bias` and `normal_offset`, with their defaults
    /// and ranges, for a technique's parameter list.
    pub const BIAS_PARAMS: [ParamSpec; 3] = [
        ParamSpec {
            name: "constant_bias",
            kind: ParamKind::Float { default: 1e-3, min: 0.0, max: 0.1 },
            doc: "depth bias added to every texel, as a fraction of the scene's bounding-box diagonal",
        },
        ParamSpec {
            name: "slope_bias",
            kind: ParamKind::Float { default: 0.0, min: 0.0, max: 16.0 },
            doc: "slope-scaled bias: multiples of the depth change across one texel (clamped to 4 texels; normal offset usually makes it unnecessary)",
        },
        ParamSpec {
            name: "normal_offset",
            kind: ParamKind::Float { default: 0.5, min: 0.0, max: 8.0 },
            doc: "lookup point moved off the surface along its normal, in shadow-map texels (Holbert 2011)",
        },
    ];

    /// `receiver_plane`: the receiver model of techniques that compare shadow-map taps
    /// with a receiver (`pcss`, `sssm`), declared once so that they share name, default and doc.
    pub const RECEIVER_PLANE_PARAM: ParamSpec = ParamSpec {
        name: "receiver_plane",
        kind: ParamKind::Bool { default: true },
        doc: "compare each shadow-map tap with the receiver's tangent plane along its ray (Isidoro 2006) instead of the receiver's depth; false is Fernando's sketch",
    };

    /// The `shadow_map_size` parameter with a technique's own default.
    #[must_use]
    pub const fn size_param(default: i64) -> ParamSpec {
        ParamSpec {
            name: "shadow_map_size",
            kind: ParamKind::Int { default, min: 16, max: 16384 },
            doc: "side of the square shadow map, texels",
        }
    }

    /// Reads `shadow_map_size` and the [`ShadowMapSettings::BIAS_PARAMS`].
    ///
    /// # Errors
    /// A parameter error if one is missing or of another type.
    pub fn from_params(params: &crate::ParamValues) -> Result<Self> {
        Ok(Self {
            size: u32::try_from(params.int("shadow_map_size")?).unwrap_or(u32::MAX),
            constant_bias: params.float("constant_bias")? as f32,
            slope_bias: params.float("slope_bias")? as f32,
            normal_offset: params.float("normal_offset")? as f32,
        })
    }

    /// The requirements of a technique made of this map and screen passes:
    /// the G-buffer, and textures of `shadow_map_size`.
    ///
    /// # Errors
    /// A parameter error.
    pub fn screen_space_requirements(params: &crate::ParamValues) -> Result<crate::Requirements> {
        let settings = Self::from_params(params)?;
        Ok(crate::Requirements { gbuffer: true, max_texture_size: settings.size, ..crate::Requirements::NONE })
    }

    /// Builds the depth map over all geometry, labelled `label`.
    ///
    /// # Errors
    /// A GPU error if the pipeline is rejected.
    pub fn depth_map(&self, setup: &crate::TechniqueSetup<'_>, label: &str) -> Result<LightDepthMap> {
        let diagonal = setup.scene.bounds.size().length();
        LightDepthMap::new(
            setup.gpu,
            setup.scene,
            &LightDepthMapDesc {
                label,
                width: self.size,
                height: self.size,
                geometry: Geometry::All,
                cull_mode: None,
                farthest: false,
                constant_bias: self.constant_bias * diagonal,
                slope_bias: self.slope_bias,
            },
        )
    }
}
