//! The light frame: one perspective frustum per light, shared by every
//! technique so that all of them see the same light geometry.
//!
//! The frame's origin is the light's centre; its texture axes run along the
//! rectangle's `u` and `v` axes (Atty et al., Sec. 3.2: the occluder map is
//! axis-aligned with the light and has its aspect ratio); depth is the
//! distance along the light's normal; the frustum is symmetric and just
//! contains the scene's bounds in front of the light.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3};
use ssm_scene::{Aabb, RectLight};

/// Widest half-angle a light frustum may take, as a tangent (about 84°):
/// geometry beside the light, nearly in its plane, is clipped rather than
/// spreading the shadow map over an unbounded angle.
pub const MAX_HALF_ANGLE_TANGENT: f32 = 10.0;

/// One light's frustum, fitted to the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightFrame {
    /// The light it was built for.
    pub light: RectLight,
    /// World to light view space (right-handed: x = u, y = -v, looking along the normal).
    pub view: Mat4,
    /// Light view to clip space, depth in `[0, 1]`.
    pub projection: Mat4,
    /// Tangents of the half-angles along u and v.
    pub tan_half: Vec2,
    /// Near plane (linear depth).
    pub near: f32,
    /// Far plane (linear depth).
    pub far: f32,
}

impl LightFrame {
    /// Fits the frame of `light` to `bounds`: every part of the box in front of
    /// the light (up to [`MAX_HALF_ANGLE_TANGENT`]) projects inside the map.
    #[must_use]
    pub fn fit(light: &RectLight, bounds: &Aabb) -> Self {
        let normal = light.normal();
        let view = glam::camera::rh::view::look_to_mat4(light.centre, normal, -light.v_axis);
        let extent = bounds.size().length().max(1e-6);
        // Closest depth kept: geometry nearer the light's plane than this is clipped.
        let min_depth = extent * 1e-4;
        let local = |p: Vec3| {
            let offset = p - light.centre;
            Vec3::new(offset.dot(light.u_axis), offset.dot(light.v_axis), offset.dot(normal))
        };
        // The box clipped to depth >= min_depth: its corners in front, plus the
        // crossings of its edges with that plane.
        let corners = bounds.corners().map(local);
        let mut points: Vec<Vec3> = corners.iter().copied().filter(|c| c.z >= min_depth).collect();
        for (a, b) in BOX_EDGES {
            let (pa, pb) = (corners[a], corners[b]);
            if (pa.z - min_depth) * (pb.z - min_depth) < 0.0 {
                let t = (min_depth - pa.z) / (pb.z - pa.z);
                points.push(pa.lerp(pb, t));
            }
        }
        let mut tan_half = Vec2::splat(1e-3);
        let (mut near, mut far) = (f32::INFINITY, min_depth);
        for p in &points {
            tan_half = tan_half.max(Vec2::new(p.x.abs(), p.y.abs()) / p.z);
            near = near.min(p.z);
            far = far.max(p.z);
        }
        if points.is_empty() {
            // Nothing in front of the light: any valid frustum will do; everything reads as unlit.
            near = min_depth;
            far = min_depth * 2.0;
        }
        // Same aspect ratio as the light (Atty et al., Sec. 3.2); point lights are square.
        if !light.is_point() {
            let aspect = light.half_size.x / light.half_size.y;
            tan_half = Vec2::new(tan_half.x.max(tan_half.y * aspect), tan_half.y.max(tan_half.x / aspect));
        } else {
            tan_half = Vec2::splat(tan_half.max_element());
        }
        // A small margin so that geometry on the boundary is not lost to rasterisation rules.
        tan_half = (tan_half * 1.02).min(Vec2::splat(MAX_HALF_ANGLE_TANGENT));
        let near = (near * 0.98).max(min_depth);
        let far = far * 1.02 + min_depth;
        let fov_y = 2.0 * tan_half.y.atan();
        let projection = glam::camera::rh::proj::directx::perspective(fov_y, tan_half.x / tan_half.y, near, far);
        Self { light: *light, view, projection, tan_half, near, far }
    }

    /// World to clip.
    #[must_use]
    pub fn view_proj(&self) -> Mat4 {
        self.projection * self.view
    }

    /// Shadow-map texture coordinates (u right, v down) and linear depth of a
    /// world point; the CPU twin of `light_uv_depth` in `light_frame.wgsl`.
    #[must_use]
    pub fn uv_depth(&self, world: Vec3) -> Vec3 {
        let offset = world - self.light.centre;
        let depth = offset.dot(self.light.normal());
        let x = offset.dot(self.light.u_axis) / (depth * self.tan_half.x);
        let y = offset.dot(self.light.v_axis) / (depth * self.tan_half.y);
        Vec3::new(0.5 + 0.5 * x, 0.5 + 0.5 * y, depth)
    }
}

const BOX_EDGES: [(usize, usize); 12] = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];

/// [`LightFrame`] as the uniform `shaders/common/light_frame.wgsl` declares.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightFrameUniform {
    /// World to clip.
    pub view_proj: [[f32; 4]; 4],
    /// World to light view.
    pub view: [[f32; 4]; 4],
    /// Centre, intensity.
    pub centre: [f32; 4],
    /// u axis, half width.
    pub u_axis: [f32; 4],
    /// v axis, half height.
    pub v_axis: [f32; 4],
    /// Normal, area.
    pub normal: [f32; 4],
    /// tan half u, tan half v, near, far.
    pub projection: [f32; 4],
}

impl From<&LightFrame> for LightFrameUniform {
    fn from(frame: &LightFrame) -> Self {
        let light = &frame.light;
        Self {
            view_proj: frame.view_proj().to_cols_array_2d(),
            view: frame.view.to_cols_array_2d(),
            centre: light.centre.extend(light.intensity).to_array(),
            u_axis: light.u_axis.extend(light.half_size.x).to_array(),
            v_axis: light.v_axis.extend(light.half_size.y).to_array(),
            normal: light.normal().extend(light.area()).to_array(),
            projection: [frame.tan_half.x, frame.tan_half.y, frame.near, frame.far],
        }
    }
}

#[cfg(test)]
mod tests {
    use ssm_scene::builtin;

    use super::*;

    #[test]
    fn frame_contains_the_scene_and_agrees_with_the_projection_matrix() {
        for entry in ssm_scene::BUILTIN_SCENES {
            let scene = entry.build();
            let bounds = scene.bounds();
            let frame = LightFrame::fit(&scene.lights[0], &bounds);
            for corner in bounds.corners() {
                let uvd = frame.uv_depth(corner);
                assert!(uvd.x >= 0.0 && uvd.x <= 1.0 && uvd.y >= 0.0 && uvd.y <= 1.0, "{}: {corner} -> {uvd}", entry.name);
                assert!(uvd.z >= frame.near && uvd.z <= frame.far, "{}", entry.name);
                // The matrix path (as the rasteriser sees it) and the closed form agree.
                let clip = frame.view_proj() * corner.extend(1.0);
                let ndc = clip.truncate() / clip.w;
                assert!((0.5 + 0.5 * ndc.x - uvd.x).abs() < 1e-4, "{}: u {} vs {}", entry.name, 0.5 + 0.5 * ndc.x, uvd.x);
                assert!((0.5 - 0.5 * ndc.y - uvd.y).abs() < 1e-4, "{}: v {} vs {}", entry.name, 0.5 - 0.5 * ndc.y, uvd.y);
                assert!(ndc.z >= 0.0 && ndc.z <= 1.0);
            }
        }
    }

    #[test]
    fn texture_axes_follow_the_light_axes() {
        let scene = builtin("parallel-square").unwrap().build();
        let frame = LightFrame::fit(&scene.lights[0], &scene.bounds());
        let centre = frame.uv_depth(Vec3::ZERO);
        assert!((centre - Vec3::new(0.5, 0.5, 4.0)).length() < 1e-5, "{centre}");
        // +X is the light's u axis, +Z its v axis.
        assert!(frame.uv_depth(Vec3::X).x > 0.5 && frame.uv_depth(Vec3::Z).y > 0.5);
        // Square light: square frustum.
        assert_eq!(frame.tan_half.x, frame.tan_half.y);
    }
}
