// The rest of a light's front hemisphere past its frame's widest angle (MAX_HALF_ANGLE_TANGENT,
// about 84 degrees off its normal): a hemicube's four side faces around the light's centre, each
// the half in front of the light (ssm-core's side_faces.rs, LightFrame::side_face_uniform). Face k
// looks along +u, -u, +v, -v; its map's x runs across it (tangents [-1, 1]) and its y down, towards
// the light's normal (tangents [0, 1]); it stores depth along the face's forward axis.

// #import common/light_frame.wgsl

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
