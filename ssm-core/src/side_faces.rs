//! The rest of a light's front hemisphere past its frame's widest angle, as a hemicube's four side
//! faces around the light's centre (each the half in front of the light), for the lights whose
//! frame reached that angle.
//!
//! A perspective frustum cannot reach 90° off its axis: the shared [`LightFrame`](crate::LightFrame)
//! stops at [`MAX_HALF_ANGLE_TANGENT`](crate::MAX_HALF_ANGLE_TANGENT) (about 84°), and a receiver
//! past it has no texel in the frame's maps. The side faces hold the rest, as the radiosity
//! engines' hemicube does for an area light: a technique that answers those receivers with its own
//! method (pcss: [`LightView::SideFaces`](crate::LightView::SideFaces)) draws them with
//! [`SideFaceMaps`], and the framework's hard answer for the others
//! (`ssm-core/src/beyond_frame.rs`) does too, and multi-sm around each of its light samples. `shaders/common/side_faces.wgsl` picks a receiver's
//! face and its coordinates there. Lights whose frame stays inside the widest angle get no faces.

use crate::context::GpuContext;
use crate::error::Result;
use crate::frame::Frame;
use crate::gpu_scene::{Geometry, GpuScene};
use crate::light_depth::{LightDepthMap, LightDepthMapDesc};
use crate::light_frame::LightFrame;
use crate::passes::{bind_group, uniform_buffer};

/// Width of each side face's map, texels (the height is half: the part in front of the light).
pub const SIDE_FACE_WIDTH: u32 = 1024;

/// Constant bias of the side faces' maps, as a fraction of the scene's diagonal.
const SIDE_FACE_CONSTANT_BIAS: f32 = 1e-5;

/// Four side-face maps (+u, −u, +v, −v, in the order `shaders/common/side_faces.wgsl` numbers
/// them), each a linear-depth map along its face's axis, drawn from the centre of whichever
/// [`SideFaceFrames`] a frame encodes them with: one light's, or one point of it after another
/// (multi-sm's samples share one set).
pub struct SideFaceMaps {
    /// +u, −u, +v, −v.
    maps: Vec<LightDepthMap>,
}

/// The four side faces' frames around one light point ([`LightFrame::side_face_uniform`]).
pub struct SideFaceFrames {
    /// Each face's frame uniform (layout [`GpuContext::uniform_layout`]).
    face_frames: Vec<wgpu::BindGroup>,
}

impl SideFaceFrames {
    /// The faces of `light_frame`, labelled `<label>_face<k>_frame_*`.
    #[must_use]
    pub fn new(gpu: &GpuContext, light_frame: &LightFrame, label: &str) -> Self {
        let face_frames = (0..4)
            .map(|face| {
                let uniform =
                    uniform_buffer(&gpu.device, &format!("{label}_face{face}_frame_uniform"), &light_frame.side_face_uniform(face));
                bind_group(
                    &gpu.device,
                    &format!("{label}_face{face}_frame_bind_group"),
                    gpu.uniform_layout(),
                    &[uniform.as_entire_binding()],
                )
            })
            .collect();
        Self { face_frames }
    }
}

impl SideFaceMaps {
    /// The faces of light `light` of `scene`, labelled `<label>_light<i>_face<k>`, with their
    /// frames around its centre; `None` where its frame stays inside the widest angle.
    ///
    /// # Errors
    /// A GPU error creating the maps.
    pub fn for_light(gpu: &GpuContext, scene: &GpuScene, light: usize, label: &str) -> Result<Option<(Self, SideFaceFrames)>> {
        let Some(light_frame) = scene.light_frames.get(light).filter(|frame| frame.reaches_widest_angle()) else {
            return Ok(None);
        };
        let label = format!("{label}_light{light}");
        Ok(Some((Self::new(gpu, scene, &label)?, SideFaceFrames::new(gpu, light_frame, &label))))
    }

    /// Four maps, labelled `<label>_face<k>`. With roles, the faces draw what casts (the
    /// occluders), as the frame's maps do.
    ///
    /// # Errors
    /// A GPU error creating the maps.
    pub fn new(gpu: &GpuContext, scene: &GpuScene, label: &str) -> Result<Self> {
        let geometry = if scene.has_roles { Geometry::Occluders } else { Geometry::All };
        let scene_diagonal = scene.bounds.size().length();
        let maps = (0..4)
            .map(|face| {
                LightDepthMap::new(
                    gpu,
                    scene,
                    &LightDepthMapDesc {
                        label: &format!("{label}_face{face}"),
                        width: SIDE_FACE_WIDTH,
                        height: SIDE_FACE_WIDTH / 2,
                        geometry,
                        cull_mode: None,
                        farthest: false,
                        constant_bias: SIDE_FACE_CONSTANT_BIAS * scene_diagonal,
                        slope_bias: 0.0,
                    },
                )
            })
            .collect::<Result<_>>()?;
        Ok(Self { maps })
    }

    /// Records the four faces' depth passes, from the point of `frames`.
    pub fn encode(&self, frame: &mut Frame<'_>, frames: &SideFaceFrames) {
        for (map, face_frame) in self.maps.iter().zip(&frames.face_frames) {
            map.encode_with(frame, face_frame);
        }
    }

    /// The faces' linear depth, +u, −u, +v, −v: `R32Float`, [`SIDE_FACE_WIDTH`] × half that.
    #[must_use]
    pub fn linear_depth_views(&self) -> [&wgpu::TextureView; 4] {
        [&self.maps[0].linear_depth_view, &self.maps[1].linear_depth_view, &self.maps[2].linear_depth_view, &self.maps[3].linear_depth_view]
    }

    /// The four views as consecutive bindings of a bind group, +u, −u, +v, −v (the order
    /// `shaders/common/side_faces.wgsl`'s users bind them in).
    #[must_use]
    pub fn bindings(&self) -> [wgpu::BindingResource<'_>; 4] {
        self.linear_depth_views().map(wgpu::BindingResource::TextureView)
    }
}
