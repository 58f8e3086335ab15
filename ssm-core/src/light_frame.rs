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

/// Widest half-angle a light frustum takes to contain the scene's bounds, as a
/// tangent (about 84°): geometry beside the light, nearly in its plane, is
/// clipped rather than spreading the shadow map over an unbounded angle.
pub const MAX_HALF_ANGLE_TANGENT: f32 = 10.0;

/// Widest half-angle a light frustum takes, as a tangent (about 89.99°), to
/// contain occluders that lie between the light and a receiver: an occluder
/// a thousandth of the scene's size below the light hides it from everything,
/// and a frame that clipped it would lose the shadow, not just blur it.
pub const MAX_WIDENED_HALF_ANGLE_TANGENT: f32 = 1e4;

/// One light's frustum, fitted to the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightFrame {
    /// The light it was built for.
    pub light: RectLight,
    /// World to light view space (right-handed: x = u, y = -v, looking along the normal).
    pub view: Mat4,
    /// Light view to clip space, reversed depth: 1 at the near plane, 0 at the far plane.
    pub projection: Mat4,
    /// Tangents of the half-angles along u and v.
    pub tan_half: Vec2,
    /// Near plane (linear depth).
    pub near: f32,
    /// Far plane (linear depth).
    pub far: f32,
    /// Length of the diagonal of the scene's bounding box: the scale that
    /// scene-relative settings (biases, thresholds) are fractions of.
    pub scene_diagonal: f32,
    /// A closed mesh separates the whole light from the camera
    /// ([`ssm_scene::Scene::separates_light_from`]): nothing the camera sees receives any of
    /// it, and every pixel reads 0 (`trivial_visibility` in `shaders/common/screen_pass.wgsl`),
    /// as an engine culls a light sealed away from the viewer. A frame's maps could not show it
    /// everywhere: past the frame's widest angle ([`MAX_HALF_ANGLE_TANGENT`]) there is no
    /// texel, and where the box's wall meets the ground outside, the floor inside is at the same
    /// depth and a filter's taps find it lit. Set by [`GpuScene`](crate::GpuScene), which knows
    /// the camera; false from the `fit` functions.
    pub sealed: bool,
    /// A closed mesh holds the light ([`ssm_scene::Scene::encloses_light`]): an interior, whose
    /// walls, floor and ceiling beside the light lie close to its plane in every map, inside the
    /// search regions of techniques that search through the nearest depth (pvsm's blocker search
    /// keeps only texels in each receiver's light cone there). Set by
    /// [`GpuScene`](crate::GpuScene); false from the `fit` functions.
    pub enclosed: bool,
}

impl LightFrame {
    /// Fits the frame of `light` to `bounds`: every part of the box in front of
    /// the light (up to [`MAX_HALF_ANGLE_TANGENT`]) projects inside the map.
    #[must_use]
    pub fn fit(light: &RectLight, bounds: &Aabb) -> Self {
        Self::fit_with_occluders(light, bounds, &Aabb::EMPTY, &[])
    }

    /// As [`LightFrame::fit`], and widened (up to
    /// [`MAX_WIDENED_HALF_ANGLE_TANGENT`], with a nearer near plane) so that
    /// every point of `casting_points` that can lie between the light and a
    /// receiver is inside the frame: those inside the convex hull of the light
    /// rectangle and the corners of `receivers` behind them. Geometry beside
    /// the light that blocks nothing (a wall at the light's level) does not
    /// widen it. Triangles are judged by their corners.
    #[must_use]
    pub fn fit_with_occluders(light: &RectLight, bounds: &Aabb, receivers: &Aabb, casting_points: &[Vec3]) -> Self {
        Self::fit_to_geometry(light, bounds, receivers, casting_points, &[])
    }

    /// As [`LightFrame::fit_with_occluders`], and where the light's plane clips
    /// the box (a light inside the scene's bounds, or tilted across them), fitted
    /// to `triangle_corners` (three per triangle, world space) instead of the
    /// box: the box's corners beside the light are empty space, and a frame
    /// stretched over them (up to [`MAX_HALF_ANGLE_TANGENT`], with its near
    /// plane at the light) would spend most of a map's texels, and every
    /// depth-range and search-region bound, on nothing. A triangle that itself
    /// crosses the light's plane keeps the box's fit.
    #[must_use]
    pub fn fit_to_geometry(light: &RectLight, bounds: &Aabb, receivers: &Aabb, casting_points: &[Vec3], triangle_corners: &[Vec3]) -> Self {
        let normal = light.normal();
        let view = glam::camera::rh::view::look_to_mat4(light.centre, normal, -light.v_axis);
        let extent = bounds.size().length().max(1e-6);
        // Closest depth kept: geometry nearer the light's plane than this is clipped. An occluder
        // a thousandth of the scene's size below the light is kept (and casts its huge penumbra,
        // Atty et al. Eq. 3); the reversed depth below keeps the far end precise all the same.
        let min_depth = extent * 1e-7;
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
        let (mut near, mut far) = (f32::INFINITY, min_depth);
        for p in &points {
            near = near.min(p.z);
            far = far.max(p.z);
        }
        if points.is_empty() {
            // Nothing in front of the light: any valid frustum will do; everything reads as unlit.
            near = min_depth;
            far = min_depth * 2.0;
        }
        let mut tan_half = light_shaped_tangents(light, widest_tangents(&points)).min(Vec2::splat(MAX_HALF_ANGLE_TANGENT));
        if tan_half.max_element() >= MAX_HALF_ANGLE_TANGENT {
            if let Some((tangents, geometry_near, geometry_far)) = geometry_extent(triangle_corners, local, min_depth) {
                tan_half = light_shaped_tangents(light, tangents).min(Vec2::splat(MAX_HALF_ANGLE_TANGENT));
                (near, far) = (geometry_near, geometry_far);
            }
        }
        if tan_half.max_element() >= MAX_HALF_ANGLE_TANGENT && !receivers.is_empty() {
            // The box was clipped: widen the frame for the occluders it clipped that block light.
            let receiver_corners = receivers.corners().map(local);
            let blocking: Vec<Vec3> = casting_points
                .iter()
                .map(|p| local(*p))
                .filter(|p| p.z >= min_depth && between_light_and_receivers(light, &receiver_corners, *p))
                .collect();
            if !blocking.is_empty() {
                let widened = light_shaped_tangents(light, widest_tangents(&blocking)).min(Vec2::splat(MAX_WIDENED_HALF_ANGLE_TANGENT));
                tan_half = tan_half.max(widened);
                near = blocking.iter().fold(near, |n, p| n.min(p.z));
            }
        }
        let near = (near * 0.98).max(min_depth);
        let far = far * 1.02 + min_depth;
        let fov_y = 2.0 * tan_half.y.atan();
        // Reversed depth (near → 1, far → 0): with a 32-bit float depth buffer the precision is then
        // nearly constant relative to depth, so a near plane a million times closer than the far
        // one still orders surfaces at the far end correctly. Depth tests use `Greater` for nearest.
        let projection = glam::camera::rh::proj::directx::perspective(fov_y, tan_half.x / tan_half.y, far, near);
        Self {
            light: *light,
            view,
            projection,
            tan_half,
            near,
            far,
            scene_diagonal: bounds.size().length(),
            sealed: false,
            enclosed: false,
        }
    }

    /// Size in texels, along the map's two axes, of the part of a `map_size`²
    /// map that `region` (clipped to the frame's depth range) covers: how finely
    /// a map of this frame resolves it. Zero when nothing of it lies in front of
    /// the light.
    #[must_use]
    pub fn footprint_texels(&self, region: &Aabb, map_size: u32) -> Vec2 {
        let (mut low, mut high) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for corner in region.corners() {
            let offset = corner - self.light.centre;
            let depth = offset.dot(self.light.normal()).max(self.near);
            let uv = Vec2::new(offset.dot(self.light.u_axis), offset.dot(self.light.v_axis)) / (depth * self.tan_half) * 0.5 + 0.5;
            low = low.min(uv.clamp(Vec2::ZERO, Vec2::ONE));
            high = high.max(uv.clamp(Vec2::ZERO, Vec2::ONE));
        }
        if region.is_empty() { Vec2::ZERO } else { (high - low).max(Vec2::ZERO) * map_size as f32 }
    }

    /// World to clip.
    #[must_use]
    pub fn view_proj(&self) -> Mat4 {
        self.projection * self.view
    }

    /// The uniform of the part of this frame whose shadow-map coordinates lie
    /// in `[uv_min, uv_max]` (a tile of a virtual shadow map): its clip space
    /// maps that rectangle onto the whole viewport, and its half-angle
    /// tangents are the tile's share of the frame's, so that texel sizes
    /// (slope bias, normal offset) are the tile's. Depth and every other field
    /// are the frame's.
    #[must_use]
    pub fn tile_uniform(&self, uv_min: Vec2, uv_max: Vec2) -> LightFrameUniform {
        let extent = (uv_max - uv_min).max(Vec2::splat(1e-9));
        // NDC x = 2u − 1 and NDC y = 1 − 2v map to the tile's [-1, 1]: x' = (x − c_x w)/e_x, y' = (y − c_y w)/e_y.
        let centre = Vec2::new(uv_min.x + uv_max.x - 1.0, 1.0 - (uv_min.y + uv_max.y));
        let to_tile = Mat4::from_cols(
            glam::Vec4::new(1.0 / extent.x, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 1.0 / extent.y, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, 1.0, 0.0),
            glam::Vec4::new(-centre.x / extent.x, -centre.y / extent.y, 0.0, 1.0),
        );
        let mut uniform = LightFrameUniform::from(self);
        uniform.view_proj = (to_tile * self.view_proj()).to_cols_array_2d();
        uniform.projection[0] = self.tan_half.x * extent.x;
        uniform.projection[1] = self.tan_half.y * extent.y;
        uniform
    }

    /// Whether the fit reached the widest angle ([`MAX_HALF_ANGLE_TANGENT`]) along an axis: then
    /// part of the light's front hemisphere may hold receivers that the frame's maps have no
    /// texel for, which the framework answers from the [side faces](LightFrame::side_face_uniform).
    #[must_use]
    pub fn reaches_widest_angle(&self) -> bool {
        self.tan_half.max_element() >= MAX_HALF_ANGLE_TANGENT * (1.0 - 1e-6)
    }

    /// The axes of side face `face` (0: +u, 1: −u, 2: +v, 3: −v, the direction it looks along):
    /// across (the map's x), down (its y: the light's normal) and forward, with across × down =
    /// forward as u × v = normal. `shaders/core/beyond_frame.wgsl` picks the same.
    #[must_use]
    pub fn side_face_axes(&self, face: usize) -> [Vec3; 3] {
        let (u, v, n) = (self.light.u_axis, self.light.v_axis, self.light.normal());
        match face {
            0 => [v, n, u],
            1 => [-v, n, -u],
            2 => [-u, n, v],
            _ => [u, n, -v],
        }
    }

    /// The uniform of side face `face` ([`LightFrame::side_face_axes`]): a frustum from the
    /// light's centre looking along the light's plane, tangents [-1, 1] across and [0, 1]
    /// towards the normal (the half of a hemicube's side in front of the light), for a map twice
    /// as wide as high. Its `normal` is the face's forward axis, so that a
    /// [`LightDepthMap`](crate::LightDepthMap) drawn through it stores depth along that axis;
    /// the light's size, the scene and the sealed flag are the frame's.
    #[must_use]
    pub fn side_face_uniform(&self, face: usize) -> LightFrameUniform {
        let [across, down, forward] = self.side_face_axes(face);
        let view = glam::camera::rh::view::look_to_mat4(self.light.centre, forward, -down);
        let near = self.scene_diagonal.max(1e-6) * 1e-6;
        let far = 2.0 * self.scene_diagonal + self.far;
        // A 90° square frustum, reversed depth as the frame's, whose lower half (view y from −w
        // to 0: in front of the light) is stretched over the whole viewport: y' = 2y + w.
        let square = glam::camera::rh::proj::directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, far, near);
        let lower_half = Mat4::from_cols(
            glam::Vec4::new(1.0, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 2.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, 1.0, 0.0),
            glam::Vec4::new(0.0, 1.0, 0.0, 1.0),
        );
        let mut uniform = LightFrameUniform::from(self);
        uniform.view_proj = (lower_half * square * view).to_cols_array_2d();
        uniform.view = view.to_cols_array_2d();
        uniform.u_axis = across.extend(self.light.half_size.x).to_array();
        uniform.v_axis = down.extend(self.light.half_size.y).to_array();
        uniform.normal = forward.extend(self.light.area()).to_array();
        // Half-extent tangents: 1 across, 0.5 down (the [0, 1] range over the map's height).
        uniform.projection = [1.0, 0.5, near, far];
        uniform
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

/// Largest |x|/z and |y|/z over light-space points (at least 1e-3).
/// The widest tangents and the depth range of the triangles in front of the
/// light (light-space corners from `local`); `None` when none is, or when one
/// crosses the plane at `min_depth` (its part next to the light is as wide as
/// the box's).
fn geometry_extent(triangle_corners: &[Vec3], local: impl Fn(Vec3) -> Vec3, min_depth: f32) -> Option<(Vec2, f32, f32)> {
    let mut in_front = Vec::with_capacity(triangle_corners.len());
    for triangle in triangle_corners.chunks_exact(3) {
        let corners = [local(triangle[0]), local(triangle[1]), local(triangle[2])];
        let ahead = corners.iter().filter(|c| c.z >= min_depth).count();
        match ahead {
            0 => {}
            3 => in_front.extend_from_slice(&corners),
            _ => return None,
        }
    }
    if in_front.is_empty() {
        return None;
    }
    let (near, far) = in_front.iter().fold((f32::INFINITY, min_depth), |(near, far), p| (near.min(p.z), far.max(p.z)));
    Some((widest_tangents(&in_front), near, far))
}

fn widest_tangents(points: &[Vec3]) -> Vec2 {
    points.iter().fold(Vec2::splat(1e-3), |tan, p| tan.max(Vec2::new(p.x.abs(), p.y.abs()) / p.z))
}

/// Most the frame's shape follows a long light's: beyond it the frame keeps this aspect ratio.
/// A tube 1000 times longer than wide shaped exactly would stretch the frame 1000 times past the
/// scene along its length (past the widest angle, where the shadow is lost); at this ratio the
/// frame still spends its texels on the scene, finest across the tube, where its penumbra is
/// narrowest.
pub const MAX_FRAME_ASPECT: f32 = 8.0;

/// Tangents given the light's aspect ratio (Atty et al., Sec. 3.2; point lights
/// are square; at most [`MAX_FRAME_ASPECT`]) and a small margin, so that
/// geometry on the boundary is not lost to rasterisation rules.
fn light_shaped_tangents(light: &RectLight, tan_half: Vec2) -> Vec2 {
    let shaped = if light.is_point() {
        Vec2::splat(tan_half.max_element())
    } else {
        let aspect = (light.half_size.x / light.half_size.y).clamp(1.0 / MAX_FRAME_ASPECT, MAX_FRAME_ASPECT);
        Vec2::new(tan_half.x.max(tan_half.y * aspect), tan_half.y.max(tan_half.x / aspect))
    };
    shaped * 1.02
}

/// True when light-space point `p` lies in the convex hull of the light
/// rectangle and some receiver corner behind it, per axis: a segment from the
/// light to that receiver can pass through `p`. (Conservative: the hull of the
/// whole receiver box is taken corner by corner.)
fn between_light_and_receivers(light: &RectLight, receiver_corners: &[Vec3; 8], p: Vec3) -> bool {
    // 0.1% of slack: an occluder exactly as wide as the light has its corners on the hull.
    let slack = 1.001;
    let (mut reach_x, mut reach_y) = (0.0f32, 0.0f32);
    let mut any_behind = false;
    for r in receiver_corners.iter().filter(|r| r.z > p.z) {
        any_behind = true;
        let t = p.z / r.z;
        reach_x = reach_x.max(light.half_size.x * (1.0 - t) + r.x.abs() * t);
        reach_y = reach_y.max(light.half_size.y * (1.0 - t) + r.y.abs() * t);
    }
    any_behind && p.x.abs() <= reach_x * slack && p.y.abs() <= reach_y * slack
}

const BOX_EDGES: [(usize, usize); 12] = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];

/// [`LightFrame`] as the uniform `shaders/common/light_frame.wgsl` declares.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, crate::UniformStruct)]
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
    /// The scene's bounding-box diagonal; y: 1 when the light is sealed from the camera
    /// ([`LightFrame::sealed`]), else 0; z: 1 when a closed mesh holds the light
    /// ([`LightFrame::enclosed`]), else 0; w unused.
    pub scene: [f32; 4],
    /// The light's linear RGB colour; w unused.
    pub colour: [f32; 4],
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
            scene: [frame.scene_diagonal, if frame.sealed { 1.0 } else { 0.0 }, if frame.enclosed { 1.0 } else { 0.0 }, 0.0],
            colour: light.colour.extend(0.0).to_array(),
        }
    }
}

#[cfg(test)]
mod tests {
    use ssm_scene::builtin;

    use super::*;

    /// The WGSL that decides whether a frame reached its widest angle (multi-sm's samples) holds
    /// the same tangent.
    #[test]
    fn the_shaders_widest_tangent_is_this_one() {
        let line = format!("const MAX_HALF_ANGLE_TANGENT: f32 = {MAX_HALF_ANGLE_TANGENT:?};");
        assert!(ssm_shaders::common::SIDE_FACES.contains(&line), "shaders/common/side_faces.wgsl lacks `{line}`");
    }

    #[test]
    fn frame_contains_the_scene_and_agrees_with_the_projection_matrix() {
        for entry in ssm_scene::BUILTIN_SCENES {
            let scene = entry.build();
            let bounds = scene.bounds();
            let frame = LightFrame::fit(&scene.lights[0], &bounds);
            for corner in bounds.corners() {
                let uvd = frame.uv_depth(corner);
                // Reversed depth: the near plane maps to 1, the far plane to 0.
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

    /// An occluder 0.001 below the unit light, between it and the receiver, widens the frame far past
    /// the usual limit and pulls the near plane in front of it; the same square beside the light
    /// (it blocks nothing) does not.
    #[test]
    fn occluders_between_the_light_and_the_receivers_widen_the_frame_and_others_do_not() {
        let scene = builtin("parallel-square").unwrap().build();
        let light = scene.lights[0];
        let receivers = Aabb { min: Vec3::new(-4.0, 0.0, -4.0), max: Vec3::new(4.0, 0.0, 4.0) };
        let square = |centre: Vec3| {
            [Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 0.0, -0.5), Vec3::new(0.5, 0.0, 0.5), Vec3::new(-0.5, 0.0, 0.5)].map(|c| c + centre)
        };
        let fit = |occluder: [Vec3; 4]| {
            let mut bounds = receivers;
            occluder.iter().for_each(|p| bounds.extend(*p));
            LightFrame::fit_with_occluders(&light, &bounds, &receivers, &occluder)
        };
        let below = fit(square(Vec3::new(0.0, 3.999, 0.0)));
        assert!(below.tan_half.x > 400.0 && below.tan_half.x <= MAX_WIDENED_HALF_ANGLE_TANGENT, "{}", below.tan_half);
        assert!(below.near < 0.001, "{}", below.near);
        for corner in square(Vec3::new(0.0, 3.999, 0.0)) {
            let uvd = below.uv_depth(corner);
            assert!(uvd.x > 0.0 && uvd.x < 1.0 && uvd.z > below.near, "{uvd}");
        }
        let beside = fit(square(Vec3::new(30.0, 3.999, 0.0)));
        assert_eq!(beside.tan_half.x, MAX_HALF_ANGLE_TANGENT, "a square beside the light blocks nothing");
        // Without occluders near the light, the fit is the plain one.
        assert_eq!(
            LightFrame::fit_with_occluders(&light, &scene.bounds(), &receivers, &[Vec3::Y * 2.0]),
            LightFrame::fit(&light, &scene.bounds())
        );
    }

    /// The dragon's set-up: a light tilted across the scene's box (its plane cuts the box's top
    /// corners) is fitted to the triangles, not to the box's empty corners: a narrower frame that
    /// still holds every triangle, with its near plane at the nearest one instead of at the light.
    /// A triangle crossing the light's plane brings back the box's fit.
    #[test]
    fn a_light_tilted_across_the_box_is_fitted_to_the_triangles() {
        let light = RectLight::try_facing(Vec3::new(1.2, 3.2, 0.8), Vec3::new(-0.35, -1.0, -0.25), Vec3::X, Vec2::splat(0.8), 1.0).unwrap();
        let ground = [(-4.0, -4.0), (4.0, -4.0), (4.0, 4.0), (-4.0, -4.0), (4.0, 4.0), (-4.0, 4.0)].map(|(x, z)| Vec3::new(x, 0.0, z));
        // A tall, thin occluder whose top lifts the box to y = 2.5.
        let pole = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.1, 0.0, 0.0), Vec3::new(0.0, 2.5, 0.0)];
        let triangles: Vec<Vec3> = ground.iter().chain(pole.iter()).copied().collect();
        let mut bounds = Aabb::EMPTY;
        triangles.iter().for_each(|p| bounds.extend(*p));
        let receivers = Aabb { min: Vec3::new(-4.0, 0.0, -4.0), max: Vec3::new(4.0, 0.0, 4.0) };
        let boxed = LightFrame::fit_with_occluders(&light, &bounds, &receivers, &pole);
        assert_eq!(boxed.tan_half.max_element(), MAX_HALF_ANGLE_TANGENT, "the box is clipped: {}", boxed.tan_half);
        let fitted = LightFrame::fit_to_geometry(&light, &bounds, &receivers, &pole, &triangles);
        assert!(fitted.tan_half.max_element() < 0.5 * MAX_HALF_ANGLE_TANGENT, "{}", fitted.tan_half);
        assert!(fitted.near > 0.5, "near plane at the nearest triangle, not the light: {}", fitted.near);
        for corner in &triangles {
            let uvd = fitted.uv_depth(*corner);
            assert!((0.0..=1.0).contains(&uvd.x) && (0.0..=1.0).contains(&uvd.y), "{corner} -> {uvd}");
            assert!(uvd.z >= fitted.near && uvd.z <= fitted.far, "{corner}: {} not in [{}, {}]", uvd.z, fitted.near, fitted.far);
        }
        let mut crossing = triangles.clone();
        crossing.extend_from_slice(&[Vec3::new(1.2, 3.0, 0.8), Vec3::new(1.3, 3.0, 0.8), Vec3::new(1.2, 3.5, 0.8)]);
        let mut crossing_bounds = bounds;
        crossing.iter().for_each(|p| crossing_bounds.extend(*p));
        let crossed = LightFrame::fit_to_geometry(&light, &crossing_bounds, &receivers, &pole, &crossing);
        assert_eq!(crossed.tan_half.max_element(), MAX_HALF_ANGLE_TANGENT);
    }

    /// A tile's clip space maps its part of the map onto the whole viewport.
    /// A tube 1000 times longer than wide over `parallel-square`: the frame follows its shape up
    /// to MAX_FRAME_ASPECT, so it stays within the widest angle, where
    /// shaping it exactly would stretch it past the widest angle (and lose the shadow).
    #[test]
    fn a_tube_lights_frame_keeps_to_the_scene() {
        let scene = builtin("parallel-square").unwrap().build();
        for u_hint in [Vec3::X, Vec3::Z, Vec3::new(0.866, 0.0, 0.5)] {
            let tube = RectLight::try_facing(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, u_hint, Vec2::new(4.0, 0.004), 1.0).unwrap();
            let receivers = Aabb { min: Vec3::new(-4.0, 0.0, -4.0), max: Vec3::new(4.0, 0.0, 4.0) };
            let occluder = [Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, 0.5), Vec3::new(-0.5, 2.0, 0.5)];
            let frame = LightFrame::fit_with_occluders(&tube, &scene.bounds(), &receivers, &occluder);
            let ratio = frame.tan_half.x / frame.tan_half.y;
            println!("{u_hint}: tangents {}, aspect {ratio}", frame.tan_half);
            assert!(frame.tan_half.max_element() <= MAX_HALF_ANGLE_TANGENT, "{u_hint}: {}", frame.tan_half);
            assert!((1.0..=MAX_FRAME_ASPECT * 1.001).contains(&ratio), "{u_hint}: aspect {ratio}");
        }
    }

    #[test]
    fn a_tile_frame_maps_its_rectangle_onto_the_viewport() {
        let scene = builtin("parallel-square").unwrap().build();
        let frame = LightFrame::fit(&scene.lights[0], &scene.bounds());
        let (low, high) = (Vec2::new(0.25, 0.5), Vec2::new(0.5, 0.625));
        let tile = frame.tile_uniform(low, high);
        let view_proj = Mat4::from_cols_array_2d(&tile.view_proj);
        for world in [Vec3::new(0.3, 0.0, 0.1), Vec3::new(-1.0, 1.0, 0.7), Vec3::new(-2.0, 0.5, 1.5)] {
            let uvd = frame.uv_depth(world);
            let ndc = view_proj.project_point3(world);
            let tile_uv = Vec2::new(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
            let expected = (Vec2::new(uvd.x, uvd.y) - low) / (high - low);
            assert!((tile_uv - expected).length() < 1e-4, "{world}: {tile_uv} vs {expected}");
        }
        assert!((tile.projection[0] - frame.tan_half.x * 0.25).abs() < 1e-6);
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

    /// Each side face's clip space puts a point in front of the light where
    /// `shaders/core/beyond_frame.wgsl` looks it up: x at 0.5 + 0.5 tan across, y (down) at the
    /// tangent towards the light's normal, depth inside [0, 1]; and the four faces, with the
    /// frame, cover the front hemisphere.
    #[test]
    fn side_faces_map_the_front_hemisphere_as_the_lookup_reads_it() {
        let light = RectLight::try_facing(Vec3::new(0.3, 2.0, -0.4), Vec3::new(0.2, -1.0, 0.1), Vec3::X, Vec2::new(0.5, 0.2), 1.0).unwrap();
        let frame = LightFrame::fit(&light, &Aabb { min: Vec3::splat(-5.0), max: Vec3::splat(5.0) });
        let (u, v, n) = (light.u_axis, light.v_axis, light.normal());
        let mut state = 11u64;
        let mut random = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        for _ in 0..500 {
            // In a side face's region: at most 45 degrees from the light's plane.
            let (x, y) = (random() * 4.0, random() * 4.0);
            let local = Vec3::new(x, y, (random().abs() * 0.999 + 1e-4) * x.abs().max(y.abs()));
            let world = light.centre + u * local.x + v * local.y + n * local.z;
            // The face the lookup picks: the larger of |u| and |v|, its sign.
            let face = if local.x.abs() >= local.y.abs() { usize::from(local.x < 0.0) } else { 2 + usize::from(local.y < 0.0) };
            let [across, down, forward] = frame.side_face_axes(face);
            assert!((across.cross(down) - forward).length() < 1e-5, "face {face} is not (u, v, normal)-handed");
            let offset = world - light.centre;
            let expected = Vec2::new(0.5 + 0.5 * offset.dot(across) / offset.dot(forward), offset.dot(down) / offset.dot(forward));
            let uniform = frame.side_face_uniform(face);
            let clip = Mat4::from_cols_array_2d(&uniform.view_proj) * world.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            let uv = Vec2::new(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
            assert!((uv - expected).length() < 1e-4, "face {face}: {uv} where the lookup reads {expected}");
            assert!(uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all(), "face {face}: {uv} outside its map");
            assert!(ndc.z > 0.0 && ndc.z < 1.0, "face {face}: depth {} outside the range", ndc.z);
        }
    }
}
