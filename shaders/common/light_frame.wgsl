// The shared light frame (ssm-core's LightFrame): a perspective view from the
// light's centre, x along the rectangle's u axis, texture y along its v axis,
// looking along its normal, fitted to the scene. Every technique sees the same
// light geometry through it.

struct LightFrame {
    // World to clip space of the light's shadow-map frustum (depth in [0, 1]).
    view_proj: mat4x4<f32>,
    // World to light view space (right-handed: x = u, y = -v, z = -normal).
    view: mat4x4<f32>,
    // xyz: centre of the rectangle; w: intensity.
    centre: vec4<f32>,
    // xyz: unit u axis; w: half width along u.
    u_axis: vec4<f32>,
    // xyz: unit v axis; w: half height along v.
    v_axis: vec4<f32>,
    // xyz: unit normal (emission direction); w: area.
    normal: vec4<f32>,
    // x, y: tangents of the frustum's half angles along u and v; z: near; w: far.
    projection: vec4<f32>,
    // x: the diagonal of the scene's bounding box, the scale of scene-relative settings; y: 1 when
    // a closed mesh separates the whole light from the camera (ssm-core's LightFrame::sealed);
    // z: 1 when a closed mesh holds the light (LightFrame::enclosed); w: unused.
    scene: vec4<f32>,
    // xyz: the light's linear RGB colour (the composite shading's; visibility ignores it); w: unused.
    colour: vec4<f32>,
};

// A length given as a fraction of the scene's diagonal (biases, thresholds), in world units.
fn scene_length(frame: LightFrame, fraction: f32) -> f32 {
    return fraction * frame.scene.x;
}

// Distance of `world` in front of the light's plane (its linear light-space depth).
fn light_depth(frame: LightFrame, world: vec3<f32>) -> f32 {
    return dot(world - frame.centre.xyz, frame.normal.xyz);
}

// Shadow-map texture coordinates (u right, v down, both in [0, 1] inside the
// frustum) and linear depth of a world point. Meaningless for depth <= 0.
fn light_uv_depth(frame: LightFrame, world: vec3<f32>) -> vec3<f32> {
    let offset = world - frame.centre.xyz;
    let depth = dot(offset, frame.normal.xyz);
    let x = dot(offset, frame.u_axis.xyz) / (depth * frame.projection.x);
    let y = dot(offset, frame.v_axis.xyz) / (depth * frame.projection.y);
    // Texture y grows along v (the frame's view y is -v).
    return vec3<f32>(0.5 + 0.5 * x, 0.5 + 0.5 * y, depth);
}

// Half extent of the light rectangle, in shadow-map uv units, as seen through
// a plane at linear depth `depth` from a point at `receiver_depth`: the
// back-projection of the light through that plane (similar triangles).
fn light_half_extent_uv(frame: LightFrame, depth: f32, receiver_depth: f32) -> vec2<f32> {
    let half_size = vec2<f32>(frame.u_axis.w, frame.v_axis.w);
    let scale = max(receiver_depth - depth, 0.0) / max(receiver_depth * depth, 1e-12);
    return 0.5 * half_size * scale / frame.projection.xy;
}

// True when the point is in front of the light (a one-sided emitter lights
// nothing behind its plane).
fn in_front_of_light(frame: LightFrame, world: vec3<f32>) -> bool {
    return light_depth(frame, world) > 0.0;
}

// True when a closed mesh separates the whole light from the camera: nothing seen receives any of
// it (LightFrame::sealed in ssm-core).
fn light_sealed(frame: LightFrame) -> bool {
    return frame.scene.y > 0.5;
}

// True when a closed mesh holds the light: an interior (LightFrame::enclosed in ssm-core).
fn light_enclosed(frame: LightFrame) -> bool {
    return frame.scene.z > 0.5;
}

// True when the whole light lies strictly behind the plane through `world` with normal `normal`
// (its highest corner above the plane is below it). A light touching the plane, or partly in
// front of it, is not.
fn light_behind_surface(frame: LightFrame, world: vec3<f32>, normal: vec3<f32>) -> bool {
    let centre_height = dot(frame.centre.xyz - world, normal);
    let corner_reach = abs(frame.u_axis.w * dot(frame.u_axis.xyz, normal)) + abs(frame.v_axis.w * dot(frame.v_axis.xyz, normal));
    return centre_height + corner_reach < 0.0;
}

// Height of the light's centre above the plane through `world` with normal `normal`.
fn light_centre_height(frame: LightFrame, world: vec3<f32>, normal: vec3<f32>) -> f32 {
    return dot(frame.centre.xyz - world, normal);
}

// The fraction of the light's area strictly in front of the plane through `world` with normal
// `normal`: 1 wholly in front, 0 wholly behind. Its points are at heights h + a A + b B above the
// plane (h the centre's, A and B the half sides' reaches along the normal, a and b uniform in
// [-1, 1]), so the fraction is sum_of_uniforms_cdf(h, A, B). CPU twin:
// ssm_scene::RectLight::share_in_front_of_plane.
fn light_share_in_front(frame: LightFrame, world: vec3<f32>, normal: vec3<f32>) -> f32 {
    return rect_share_in_front(frame, vec2<f32>(frame.u_axis.w, frame.v_axis.w), world, normal);
}

// The same for a rectangle centred on the light's centre, along its axes, of half sides
// `half_size` (a stratum of a light, whose frame is a point light at its centre).
fn rect_share_in_front(frame: LightFrame, half_size: vec2<f32>, world: vec3<f32>, normal: vec3<f32>) -> f32 {
    let reach_u = abs(half_size.x * dot(frame.u_axis.xyz, normal));
    let reach_v = abs(half_size.y * dot(frame.v_axis.xyz, normal));
    return sum_of_uniforms_cdf(light_centre_height(frame, world, normal), reach_u, reach_v);
}

// P(a A + b B < t) for a, b independent and uniform in [-1, 1], A, B >= 0: the sum's cumulative
// distribution, piecewise in t with the larger reach first. No piece subtracts nearly equal terms
// (a tube's B far below A keeps its precision), B = 0 never divides (its corner pieces are empty
// and caught by the first two tests), and A = B = 0 gives the step t > 0. CPU twin:
// ssm_scene::sum_of_uniforms_cdf.
fn sum_of_uniforms_cdf(t: f32, first: f32, second: f32) -> f32 {
    let a = max(first, second);
    let b = min(first, second);
    // Distances to the lowest and highest heights, B added last so that A's rounding keeps it.
    let below = (t + a) + b;
    if (below <= 0.0) {
        return 0.0;
    }
    let above = (a - t) + b;
    if (above <= 0.0) {
        return 1.0;
    }
    // A > 0 here, and B > 0 in the corners (with B = 0, t <= -A and t > A returned above). Each
    // corner is half a product of two ratios in (0, 1]: no overflow.
    if (t <= b - a) {
        return 0.5 * min(below / (2.0 * a), 1.0) * min(below / (2.0 * b), 1.0);
    }
    if (t <= a - b) {
        return clamp((t + a) / (2.0 * a), 0.0, 1.0);
    }
    return 1.0 - 0.5 * min(above / (2.0 * a), 1.0) * min(above / (2.0 * b), 1.0);
}

// The receiver's tangent plane as seen from the light, prepared once per receiver point so that
// each tap costs one multiply-add and a division: along the ray from the light's centre through
// shadow-map coordinates `uv`, the plane's linear depth is numerator / (c.x + c.y u + c.z v)
// (the ray's direction, scaled to a unit component along the light's normal, is affine in uv).
struct TapPlane {
    coefficients: vec3<f32>,
    numerator: f32,
    // The depth returned where the ray misses the plane or runs along it.
    fallback: f32,
}

// The tangent plane through `point` with normal `normal`; `fallback` where a ray misses it.
fn tap_plane(frame: LightFrame, point: vec3<f32>, normal: vec3<f32>, fallback: f32) -> TapPlane {
    // direction(uv) = N + (2u - 1) p_x U + (2v - 1) p_y V.
    let along_u = frame.projection.x * dot(frame.u_axis.xyz, normal);
    let along_v = frame.projection.y * dot(frame.v_axis.xyz, normal);
    let constant = dot(frame.normal.xyz, normal) - along_u - along_v;
    return TapPlane(vec3<f32>(constant, 2.0 * along_u, 2.0 * along_v), dot(point - frame.centre.xyz, normal), fallback);
}

// A plane that every tap sees at `depth` (the receiver's own depth for every tap, Fernando 2005).
fn constant_tap_plane(depth: f32) -> TapPlane {
    return TapPlane(vec3<f32>(1.0, 0.0, 0.0), depth, depth);
}

// The plane's linear depth along the ray through `uv`; its fallback where the ray misses it.
fn tap_plane_depth(plane: TapPlane, uv: vec2<f32>) -> f32 {
    let denominator = plane.coefficients.x + plane.coefficients.y * uv.x + plane.coefficients.z * uv.y;
    let depth = plane.numerator / denominator;
    return select(depth, plane.fallback, abs(denominator) < 1e-6 || !(depth > 0.0));
}

// Linear depth, along the ray from the light's centre through shadow-map
// coordinates `uv`, of the plane through `point` with normal `normal`: the
// receiver's own tangent plane seen at another texel (an exact, perspective
// form of the receiver-plane depth bias of Isidoro 2006). Returns
// `fallback` where the ray misses the plane or runs along it.
fn receiver_plane_depth(frame: LightFrame, point: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, fallback: f32) -> f32 {
    return tap_plane_depth(tap_plane(frame, point, normal, fallback), uv);
}
