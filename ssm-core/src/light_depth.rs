//! A light-space depth map pass that techniques instantiate with their own
//! size, geometry selection, culling and bias: hard shadow maps, blocker
//! searches, and the occluder and receiver maps of Atty et al. all start
//! from one.

use bytemuck::{Pod, Zeroable};

use crate::context::GpuContext;
use crate::error::Result;
use crate::frame::Frame;
use crate::gpu_scene::{Geometry, GpuScene, SceneVertex};
use crate::passes::{color_attachment, labelled_view, render_texture};
use crate::shader::create_shader;

/// Linear depth written where no surface was drawn (cleared value).
pub const NO_SURFACE: f32 = f32::MAX;

/// How to build a [`LightDepthMap`].
#[derive(Clone, Copy, Debug)]
pub struct LightDepthMapDesc<'a> {
    /// Label prefix of every GPU object (`"mine_shadow_map"`).
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

/// The bias uniform of `shaders/core/light_depth.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, crate::UniformStruct)]
pub struct DepthBiasUniform {
    /// x: constant bias (world units), y: slope factor, z, w: the map's width and height in texels.
    pub values: [f32; 4],
}

impl DepthBiasUniform {
    /// A constant bias (world units) and a slope factor for a map (or region) of `width` × `height` texels.
    #[must_use]
    pub fn new(constant_bias: f32, slope_bias: f32, width: u32, height: u32) -> Self {
        Self { values: [constant_bias, slope_bias, width as f32, height as f32] }
    }
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
    indices: std::ops::Range<u32>,
    farthest: bool,
}

impl LightDepthMap {
    /// Format of [`LightDepthMap::linear_depth`].
    pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
    /// Format of the depth buffer the nearest (or farthest) surface is kept with.
    pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

    /// The depth test of a pass that keeps the nearest surface to the light (or, with
    /// `farthest`, the farthest) in a [`LightDepthMap::DEPTH_FORMAT`] buffer of the light frame,
    /// whose depth is reversed (near = 1): nearest wins with `Greater`.
    #[must_use]
    pub fn depth_test(farthest: bool) -> wgpu::DepthStencilState {
        wgpu::DepthStencilState {
            format: Self::DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(if farthest { wgpu::CompareFunction::Less } else { wgpu::CompareFunction::Greater }),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }
    }

    /// Allocates the map; its pipeline is built once per device and culling mode, and shared.
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`](crate::Error::UndeclaredRequirement) for a
    /// [`Geometry`] by role without roles, or [`Error::Gpu`](crate::Error::Gpu) if the shader is rejected.
    pub fn new(gpu: &GpuContext, scene: &GpuScene, desc: &LightDepthMapDesc<'_>) -> Result<Self> {
        let device = &gpu.device;
        let label = desc.label;
        let indices = scene.index_range(label, desc.geometry)?;
        let linear_depth =
            render_texture(device, &format!("{label}_linear_depth"), desc.width, desc.height, Self::FORMAT, wgpu::TextureUsages::COPY_SRC);
        let linear_depth_view = labelled_view(&linear_depth, &format!("{label}_linear_depth"));
        let depth =
            render_texture(device, &format!("{label}_depth"), desc.width, desc.height, Self::DEPTH_FORMAT, wgpu::TextureUsages::empty());
        let bias_bind_group =
            Self::bias_bind_group(gpu, label, &DepthBiasUniform::new(desc.constant_bias, desc.slope_bias, desc.width, desc.height));
        let pipeline = Self::pipeline(gpu, desc.cull_mode, desc.farthest)?;
        Ok(Self {
            linear_depth_view,
            linear_depth,
            depth_view: labelled_view(&depth, &format!("{label}_depth")),
            pipeline,
            bias_bind_group,
            label: label.to_owned(),
            indices,
            farthest: desc.farthest,
        })
    }

    /// A bind group holding `bias`, for [`LightDepthMap::encode_region`].
    #[must_use]
    pub fn bias_bind_group(gpu: &GpuContext, label: &str, bias: &DepthBiasUniform) -> wgpu::BindGroup {
        let buffer = crate::passes::uniform_buffer(&gpu.device, &format!("{label}_bias_uniform"), bias);
        crate::passes::bind_group(&gpu.device, &format!("{label}_bias_bind_group"), gpu.uniform_layout(), &[buffer.as_entire_binding()])
    }

    /// The shared pipeline for one culling mode and depth order.
    fn pipeline(gpu: &GpuContext, cull_mode: Option<wgpu::Face>, farthest: bool) -> Result<wgpu::RenderPipeline> {
        let key = format!("light_depth_pipeline/{cull_mode:?}/farthest={farthest}");
        gpu.cached_render_pipeline(&key, |gpu| {
            let device = &gpu.device;
            let module = create_shader(gpu, "light_depth_shader", ssm_shaders::core::LIGHT_DEPTH)?;
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("light_depth_pipeline_layout"),
                bind_group_layouts: &[Some(gpu.uniform_layout()), Some(gpu.uniform_layout())],
                immediate_size: 0,
            });
            Ok(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(&key),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("light_depth_vertex"),
                    compilation_options: Default::default(),
                    buffers: &[Some(SceneVertex::layout())],
                },
                primitive: wgpu::PrimitiveState { cull_mode, front_face: wgpu::FrontFace::Ccw, ..Default::default() },
                depth_stencil: Some(Self::depth_test(farthest)),
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("light_depth_fragment"),
                    compilation_options: Default::default(),
                    targets: &[Some(Self::FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            }))
        })
    }

    /// Records the pass for `light`, labelled and timed with the map's label.
    pub fn encode(&self, frame: &mut Frame<'_>, light: usize) {
        let light_frame = &frame.scene.light_bind_groups[light];
        self.encode_with(frame, light_frame);
    }

    /// Records the pass seen through another frame: a bind group of
    /// [`GpuContext::uniform_layout`] holding a
    /// [`LightFrameUniform`](crate::LightFrameUniform) (a point on the light,
    /// a tile of it...).
    pub fn encode_with(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup) {
        self.encode_region(frame, light_frame, &self.bias_bind_group, None, &self.label);
    }

    /// Records the pass into the top-left `width` × `height` texels of the map
    /// only (the whole map is cleared first), through `light_frame`, with
    /// another bias (a [`DepthBiasUniform`] of that region's size), labelled
    /// and timed as `label`: one map of the largest size serves tiles of
    /// several resolutions, one after the other.
    pub fn encode_region(
        &self,
        frame: &mut Frame<'_>,
        light_frame: &wgpu::BindGroup,
        bias: &wgpu::BindGroup,
        region: Option<(u32, u32)>,
        label: &str,
    ) {
        self.encode_region_with(frame, light_frame, bias, region, label, None);
    }

    /// As [`LightDepthMap::encode_region`], drawing the triangles that `indices` lists (indices
    /// into the scene's vertex buffer, a subset of [`LightDepthMap::index_range`] compacted on the
    /// GPU) with the `draw_indexed_indirect` arguments in `arguments` (offset 0).
    pub fn encode_region_indirect(
        &self,
        frame: &mut Frame<'_>,
        light_frame: &wgpu::BindGroup,
        bias: &wgpu::BindGroup,
        region: Option<(u32, u32)>,
        label: &str,
        (indices, arguments): (&wgpu::Buffer, &wgpu::Buffer),
    ) {
        self.encode_region_with(frame, light_frame, bias, region, label, Some((indices, arguments)));
    }

    /// The range of the scene's index buffer this map draws (its [`Geometry`]).
    #[must_use]
    pub fn index_range(&self) -> std::ops::Range<u32> {
        self.indices.clone()
    }

    fn encode_region_with(
        &self,
        frame: &mut Frame<'_>,
        light_frame: &wgpu::BindGroup,
        bias: &wgpu::BindGroup,
        region: Option<(u32, u32)>,
        label: &str,
        indirect: Option<(&wgpu::Buffer, &wgpu::Buffer)>,
    ) {
        let scene = frame.scene;
        let mut pass = frame.render_pass(
            label,
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
        if let Some((width, height)) = region {
            let (width, height) = (width.clamp(1, self.linear_depth.width()), height.clamp(1, self.linear_depth.height()));
            pass.set_viewport(0.0, 0.0, width as f32, height as f32, 0.0, 1.0);
            pass.set_scissor_rect(0, 0, width, height);
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, bias, &[]);
        match indirect {
            Some((indices, arguments)) => {
                pass.set_vertex_buffer(0, scene.vertex_buffer.slice(..));
                pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed_indirect(arguments, 0);
            }
            None => scene.draw(&mut pass, self.indices.clone()),
        }
    }
}

/// Smallest side of a shadow map a technique may ask for, texels.
pub const SHADOW_MAP_MIN_SIZE: u32 = 16;
/// Largest side of a shadow map a technique may ask for, texels (devices may allow less).
pub const SHADOW_MAP_MAX_SIZE: u32 = 16384;

/// The bias of a light depth map and of its lookups, shared by the shadow-map
/// techniques (flatten it into their settings).
#[derive(Clone, Copy, Debug, PartialEq, crate::Settings)]
pub struct ShadowMapBias {
    /// Depth bias added to every texel, as a fraction of the scene's bounding-box diagonal.
    #[param(default = 1e-3, min = 0.0, max = 0.1)]
    pub constant_bias: f32,
    /// Slope-scaled bias: multiples of the depth change across one texel (clamped to 4 texels; normal offset usually makes it unnecessary).
    #[param(default = 0.0, min = 0.0, max = 16.0)]
    pub slope_bias: f32,
    /// Lookup point moved off the surface along its normal, in shadow-map texels (Holbert 2011).
    #[param(default = 0.5, min = 0.0, max = 8.0)]
    pub normal_offset: f32,
}

impl ShadowMapBias {
    /// A square depth map of side `size` over all geometry with this bias, labelled `label`.
    ///
    /// # Errors
    /// A GPU error if the pipeline is rejected.
    pub fn depth_map(&self, setup: &crate::TechniqueSetup<'_>, label: &str, size: u32) -> Result<LightDepthMap> {
        let diagonal = setup.scene.bounds.size().length();
        LightDepthMap::new(
            setup.gpu,
            setup.scene,
            &LightDepthMapDesc {
                label,
                width: size,
                height: size,
                geometry: Geometry::All,
                cull_mode: None,
                farthest: false,
                constant_bias: self.constant_bias * diagonal,
                slope_bias: self.slope_bias,
            },
        )
    }
}

/// What shadow-map taps are compared with, for techniques that compare taps
/// with a receiver (percentage-closer filters and their variants): declared once so that they share its
/// name, default and meaning (flatten it into their settings).
#[derive(Clone, Copy, Debug, PartialEq, Eq, crate::Settings)]
pub struct ReceiverModel {
    /// Compare each shadow-map tap with the receiver's tangent plane along its ray (Isidoro 2006) instead of the receiver's depth; false is Fernando's sketch.
    #[param(default = true)]
    pub receiver_plane: bool,
}

/// The requirements of a technique made of a square shadow map of side
/// `shadow_map_size` and screen passes: the G-buffer and textures of that size.
#[must_use]
pub fn screen_space_requirements(shadow_map_size: u32) -> crate::Requirements {
    crate::Requirements { gbuffer: true, max_texture_size: shadow_map_size, ..crate::Requirements::NONE }
}
