//! Step 1, the receiver map (Atty et al. 2006, Sec. 3.1, 3.2): per texel, the nearest receiver
//! seen from the light's centre, on the grid of the soft shadow map, whose texels hold that
//! receiver's occlusion. Without `receiver_plane` it is the paper's, ssm-core's light depth map
//! without bias ([`crate::gpu::unbiased_depth_map`]); with it (this workspace's receiver model,
//! for objects that both cast and receive, which the paper leaves out, Sec. 7) it also carries
//! each receiver's tangent plane (`shaders/atty/atty_receiver_map.wgsl`).

use ssm_core::passes::{bind_group, color_attachment, labelled_view, render_texture};
use ssm_core::shader::create_shader_with_imports;
use ssm_core::{Error, Frame, Geometry, LightDepthMap, Result, TechniqueSetup};

use crate::gpu::unbiased_depth_map;
use crate::{AttySettings, LOCAL_SHADERS, NAME};

/// The receivers' tangent planes, measured from the receiver map.
const RECEIVER_MAP_SHADER: &str = ssm_shaders::atty::ATTY_RECEIVER_MAP;

/// The receiver map: per texel of the light frame, the nearest receiver's linear depth (`.x`),
/// read by the accumulation, the penumbra bounds and the projection.
pub(crate) enum ReceiverMap {
    /// The depth alone (ssm-core's light depth map, no bias): without `receiver_plane`, the paper.
    Depth(LightDepthMap),
    /// The depth and the slope of the receiver's plane (`atty_receiver_map.wgsl`).
    Planes(ReceiverPlaneMap),
}

impl ReceiverMap {
    /// The pass's name, timed.
    const LABEL: &'static str = "atty_receiver_map";

    pub(crate) fn new(setup: &TechniqueSetup<'_>, settings: &AttySettings, settings_buffer: &wgpu::Buffer) -> Result<Self> {
        if settings.receiver_plane {
            Ok(Self::Planes(ReceiverPlaneMap::new(setup, settings.ssm_size, settings_buffer)?))
        } else {
            Ok(Self::Depth(unbiased_depth_map(setup, Self::LABEL, settings.ssm_size, Geometry::Receivers, (None, false))?))
        }
    }

    pub(crate) fn view(&self) -> &wgpu::TextureView {
        match self {
            Self::Depth(map) => &map.linear_depth_view,
            Self::Planes(map) => &map.view,
        }
    }

    /// The format of [`ReceiverMap::view`]'s texture.
    pub(crate) const fn format(&self) -> wgpu::TextureFormat {
        match self {
            Self::Depth(_) => LightDepthMap::FORMAT,
            Self::Planes(_) => ReceiverPlaneMap::FORMAT,
        }
    }

    /// Records the pass through `light_frame`, a light's frame bind group.
    pub(crate) fn encode(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup) {
        match self {
            Self::Depth(map) => map.encode_with(frame, light_frame),
            Self::Planes(map) => map.encode(frame, light_frame),
        }
    }
}

/// The receivers seen from the light's centre with their tangent planes: `(depth, slope.x,
/// slope.y, 0)` per texel (`atty_receiver_map.wgsl`), the slope read from the fragment's own
/// triangle.
pub(crate) struct ReceiverPlaneMap {
    view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    pipeline: wgpu::RenderPipeline,
    settings_group: wgpu::BindGroup,
    indices: std::ops::Range<u32>,
}

impl ReceiverPlaneMap {
    pub(crate) const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

    fn new(setup: &TechniqueSetup<'_>, size: u32, settings_buffer: &wgpu::Buffer) -> Result<Self> {
        let gpu = setup.gpu;
        let device = &gpu.device;
        let label = ReceiverMap::LABEL;
        let indices = setup.scene.index_range(NAME, Geometry::Receivers)?;
        let texture = render_texture(device, &format!("{label}_planes"), size, size, Self::FORMAT, wgpu::TextureUsages::empty());
        let depth =
            render_texture(device, &format!("{label}_depth"), size, size, LightDepthMap::DEPTH_FORMAT, wgpu::TextureUsages::empty());
        let settings_group =
            bind_group(device, &format!("{label}_settings_bind_group"), gpu.uniform_layout(), &[settings_buffer.as_entire_binding()]);
        let module = create_shader_with_imports(gpu, &format!("{label}_shader"), RECEIVER_MAP_SHADER, LOCAL_SHADERS)?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("{label}_pipeline_layout")),
            bind_group_layouts: &[Some(gpu.uniform_layout()), Some(gpu.uniform_layout())],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(&format!("{label}_pipeline")),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("atty_receiver_vertex"),
                compilation_options: Default::default(),
                buffers: &[Some(ssm_core::SceneVertex::layout())],
            },
            // Both sides of every receiver, as the plain receiver map.
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(LightDepthMap::depth_test(false)),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("atty_receiver_fragment"),
                compilation_options: Default::default(),
                targets: &[Some(Self::FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let messages = gpu.take_errors();
        if !messages.is_empty() {
            return Err(Error::Gpu { during: "building Atty's receiver-plane map".into(), messages });
        }
        Ok(Self {
            view: labelled_view(&texture, &format!("{label}_planes")),
            depth_view: labelled_view(&depth, &format!("{label}_depth")),
            pipeline,
            settings_group,
            indices,
        })
    }

    fn encode(&self, frame: &mut Frame<'_>, light_frame: &wgpu::BindGroup) {
        let scene = frame.scene;
        let no_surface = f64::from(ssm_core::NO_SURFACE);
        let mut pass = frame.render_pass(
            ReceiverMap::LABEL,
            &[color_attachment(&self.view, Some(wgpu::Color { r: no_surface, g: 0.0, b: 0.0, a: 0.0 }))],
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, light_frame, &[]);
        pass.set_bind_group(1, &self.settings_group, &[]);
        scene.draw(&mut pass, self.indices.clone());
    }
}
