// The rest of a light's front hemisphere past its frame's widest angle (MAX_HALF_ANGLE_TANGENT,
// about 84 degrees off its normal): a hemicube's four side faces around the light's centre, each
// the half in front of the light (ssm-core's side_faces.rs, LightFrame::side_face_uniform). Face k
// looks along +u, -u, +v, -v; its map's x runs across it (tangents [-1, 1]) and its y down, towards
// the light's normal (tangents [0, 1]); it stores depth along the face's forward axis.

// #import common/light_frame.wgsl

// MAX_HALF_ANGLE_TANGENT of ssm-core's light_frame.rs, the frame's widest tangent (a test there
// reads this line).
const MAX_HALF_ANGLE_TANGENT: f32 = 10.0;

// The frame reached its widest angle: receivers may lie past it (LightFrame::reaches_widest_angle).
fn frame_reaches_widest_angle(frame: LightFrame) -> bool {
    return max(frame.projection.x, frame.projection.y) >= MAX_HALF_ANGLE_TANGENT * (1.0 - 1e-6);
}

// Which face a point lies in, and its axes.
struct SideFace {
    // 0: +u, 1: -u, 2: +v, 3: -v.
    index: u32,
    // The map's x axis (across) and the axis depth is measured along (forward); down is the light's
    // normal on every face. across x down = forward, as u x v = normal (LightFrame::side_face_axes).
    across: vec3<f32>,
    forward: vec3<f32>,
};

// The point at `offset` from the light's centre lies past the frame: in front of the light, outside
// its frustum's tangents.
fn past_the_frame(frame: LightFrame, offset: vec3<f32>) -> bool {
    let depth = dot(offset, frame.normal.xyz);
    let across = vec2<f32>(abs(dot(offset, frame.u_axis.xyz)), abs(dot(offset, frame.v_axis.xyz)));
    return depth > 0.0 && any(across > depth * frame.projection.xy);
}

// The face of the larger of |offset.u| and |offset.v|.
fn side_face_of(frame: LightFrame, offset: vec3<f32>) -> SideFace {
    let u = frame.u_axis.xyz;
    let v = frame.v_axis.xyz;
    let along_u = dot(offset, u);
    let along_v = dot(offset, v);
    if (abs(along_u) >= abs(along_v)) {
        if (along_u >= 0.0) {
            return SideFace(0u, v, u);
        }
        return SideFace(1u, -v, -u);
    }
    if (along_v >= 0.0) {
        return SideFace(2u, -u, v);
    }
    return SideFace(3u, u, -v);
}

// A world offset from the light's centre in the face's coordinates: (across, down, forward).
fn side_face_coordinates(frame: LightFrame, face: SideFace, offset: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(offset, face.across), dot(offset, frame.normal.xyz), dot(offset, face.forward));
}

// Map coordinates of a point in face coordinates (forward > 0): x at 0.5 + 0.5 tan across, y at
// tan down.
fn side_face_uv(point: vec3<f32>) -> vec2<f32> {
    return vec2<f32>(0.5 + 0.5 * point.x / point.z, point.y / point.z);
}

// Hard visibility from the centre of `frame` through the side face that `offset` (from the centre)
// falls in, the faces' maps +u, -u, +v, -v given: 1 when no surface of the face's map is nearer
// along the face's axis. One texel read.
fn side_face_hard_visibility(
    frame: LightFrame,
    plus_u: texture_2d<f32>,
    minus_u: texture_2d<f32>,
    plus_v: texture_2d<f32>,
    minus_v: texture_2d<f32>,
    offset: vec3<f32>,
    normal: vec3<f32>,
    bias_texels: f32,
) -> f32 {
    let n = frame.normal.xyz;
    let size = vec2<f32>(textureDimensions(plus_u));
    let side = side_face_of(frame, offset);
    let across = side.across;
    let forward = side.forward;
    // The point's depth along the face's axis, and the depth its own surface (the tangent plane,
    // normal `normal`) may have at the centre of the texel it falls in: the map holds the surface
    // rasterized at texel centres. Seen from the light's centre at a grazing angle a surface's
    // depth changes by far more than a texel's width across one texel (D² δ (|N·a| + |N·n|) /
    // |N·o| for a texel of tangent δ, D the depth, o the point's offset from the centre), and a
    // fixed or clamped bias would let it shadow itself, as a floor a hair below a light does
    // everywhere. The bias is that change over `bias_texels` texels, at most the depth itself.
    let depth = max(dot(offset, forward), 1e-30);
    let uv = side_face_uv(vec3<f32>(dot(offset, across), dot(offset, n), depth));
    let texel_tangent = 1.0 / size.y;
    let facing = max(abs(dot(normal, offset)), 1e-30);
    let slope = (abs(dot(normal, across)) + abs(dot(normal, n))) * depth * depth / facing;
    let bias = min(bias_texels * texel_tangent * slope, depth);
    let texel = vec2<i32>(clamp(floor(uv * size), vec2<f32>(0.0), size - 1.0));
    var stored = 0.0;
    switch side.index {
        case 0u: { stored = textureLoad(plus_u, texel, 0).x; }
        case 1u: { stored = textureLoad(minus_u, texel, 0).x; }
        case 2u: { stored = textureLoad(plus_v, texel, 0).x; }
        default: { stored = textureLoad(minus_v, texel, 0).x; }
    }
    return select(0.0, 1.0, depth - bias <= stored);
}
