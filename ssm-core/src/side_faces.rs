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
//! (`ssm-core/src/beyond_frame.rs`) does too. `shaders/common/side_faces.wgsl` picks a receiver's
//! face and its coordinates there. Lights whose frame stays inside the widest angle get no faces.

use crate::context::GpuContext;
use crate::error::Result;
use crate::frame::Frame;
use crate::gpu_scene::{Geometry, GpuScene};
use crate::light_depth::{LightDepthMap, LightDepthMapDesc};
use crate::passes::{bind_group, uniform_buffer};

/// Width of each side face's map, texels (the height is half: the part in front of the light).
pub const SIDE_FACE_WIDTH: u32 = 1024;

/// Constant bias of the side faces' maps, as a fraction of the scene's diagonal.
const SIDE_FACE_CONSTANT_BIAS: f32 = 1e-5;

/// One light's four side faces (+u, −u, +v, −v, in the order `shaders/common/side_faces.wgsl`
/// numbers them): each a linear-depth map along the face's axis through
/// [`LightFrame::side_face_uniform`](crate::LightFrame::side_face_uniform).
pub struct SideFaceMaps {
    /// +u, −u, +v, −v.
    maps: Vec<LightDepthMap>,
    /// Each face's frame uniform (layout [`GpuContext::uniform_layout`]).
    face_frames: Vec<wgpu::BindGroup>,
}

impl SideFaceMaps {
    /// The faces of light `light` of `scene`, labelled `<label>_light<i>_face<k>`, or `None` where
    /// its frame stays inside the widest angle. With roles, the faces draw what casts (the
    /// occluders), as the frame's maps do.
    ///
    /// # Errors
    /// A GPU error creating the maps.
    pub fn new(gpu: &GpuContext, scene: &GpuScene, light: usize, label: &str) -> Result<Option<Self>> {
        let Some(light_frame) = scene.light_frames.get(light).filter(|frame| frame.reaches_widest_angle()) else {
            return Ok(None);
        };
        let geometry = if scene.has_roles { Geometry::Occluders } else { Geometry::All };
        let mut maps = Vec::with_capacity(4);
        let mut face_frames = Vec::with_capacity(4);
        for face in 0..4 {
            let face_label = format!("{label}_light{light}_face{face}");
            maps.push(LightDepthMap::new(
                gpu,
                scene,
                &LightDepthMapDesc {
                    label: &face_label,
                    width: SIDE_FACE_WIDTH,
                    height: SIDE_FACE_WIDTH / 2,
                    geometry,
                    cull_mode: None,
                    farthest: false,
                    constant_bias: SIDE_FACE_CONSTANT_BIAS * light_frame.scene_diagonal,
                    slope_bias: 0.0,
                },
            )?);
            let uniform = uniform_buffer(&gpu.device, &format!("{face_label}_frame_uniform"), &light_frame.side_face_uniform(face));
            face_frames.push(bind_group(
                &gpu.device,
                &format!("{face_label}_frame_bind_group"),
                gpu.uniform_layout(),
                &[uniform.as_entire_binding()],
            ));
        }
        Ok(Some(Self { maps, face_frames }))
    }

    /// Records the four faces' depth passes.
    pub fn encode(&self, frame: &mut Frame<'_>) {
        for (map, face_frame) in self.maps.iter().zip(&self.face_frames) {
            map.encode_with(frame, face_frame);
        }
    }

    /// The faces' linear depth, +u, −u, +v, −v: `R32Float`, [`SIDE_FACE_WIDTH`] × half that.
    #[must_use]
    pub fn linear_depth_views(&self) -> [&wgpu::TextureView; 4] {
        [&self.maps[0].linear_depth_view, &self.maps[1].linear_depth_view, &self.maps[2].linear_depth_view, &self.maps[3].linear_depth_view]
    }
}
