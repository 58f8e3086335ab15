// The binding convention of ssm-core's ScreenPass: a full-screen pass over the
// G-buffer for one light. Group 0: the light frame; group 1: the G-buffer;
// group 2: the technique's own resources.

// #import common/fullscreen.wgsl
// #import common/light_frame.wgsl
// #import common/scene.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var gbuffer_position: texture_2d<f32>;
@group(1) @binding(1) var gbuffer_normal: texture_2d<f32>;

// What the G-buffer holds at one pixel.
struct ScreenPoint {
    texel: vec2<i32>,
    // World position.
    position: vec3<f32>,
    // Unit normal, turned towards the camera.
    normal: vec3<f32>,
    // Geometry covers the pixel.
    covered: bool,
    // The surface has the receiver role.
    receives: bool,
    // The surface belongs to a closed mesh (ssm_scene::Scene::closed_meshes).
    closed: bool,
};

fn screen_point(in: FullscreenVertex) -> ScreenPoint {
    return screen_point_at(vec2<i32>(in.clip.xy));
}

// The same for a texel, from a compute shader.
fn screen_point_at(texel: vec2<i32>) -> ScreenPoint {
    let position = textureLoad(gbuffer_position, texel, 0);
    let normal = textureLoad(gbuffer_normal, texel, 0);
    let flags = u32(round(max(normal.w, 0.0)));
    return ScreenPoint(texel, position.xyz, normal.xyz, position.w > 0.5, (flags & GBUFFER_RECEIVES) != 0u, (flags & GBUFFER_CLOSED) != 0u);
}

// The visibility of pixels no technique needs to compute: 1 where nothing
// covers the pixel; 0 behind the light's plane (the emitter is one-sided); 0 on
// a closed mesh where the whole light is behind the surface's tangent plane
// (the unlit side of a solid: every ray to the light goes through it, as the
// ground truth finds); 0 everywhere when a closed mesh seals the light from the
// camera (a light in a closed box seen from outside: an engine culls it, and a
// frame's maps could not show it where the box's walls meet the ground, nor
// past the frame's widest angle); -1 where the technique must compute it.
// Where the light straddles a closed surface's tangent plane, the solid hides the part behind
// it: the framework gives that share after the technique's passes, to every technique that
// samples the light from its centre (core/own_surface_share.wgsl states the rule and its
// limit), so a technique need not model it.
fn trivial_visibility(point: ScreenPoint) -> f32 {
    if (!point.covered) {
        return 1.0;
    }
    if (unlit_by_rule(point)) {
        return 0.0;
    }
    return -1.0;
}

// A covered point that the shared rules of trivial_visibility say receives none of the light.
fn unlit_by_rule(point: ScreenPoint) -> bool {
    return light_sealed(frame) || !in_front_of_light(frame, point.position) || hidden_by_own_surface(point);
}

// True on a closed mesh where the whole light (of `frame`) is behind the surface's tangent plane.
// An open surface (a leaf card, a floor) is not: the ground truth's rays leave it on the side
// facing the light.
fn hidden_by_own_surface(point: ScreenPoint) -> bool {
    return point.closed && light_behind_surface(frame, point.position, point.normal);
}
