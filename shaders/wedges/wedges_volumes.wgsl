// The umbra from the light's centre by z-fail shadow volumes (Carmack's
// reverse; Forest et al., Sec. 4.1), one silhouette buffer at a time, into
// the technique's own Depth24PlusStencil8 target. Every region's volume is
// closed: its silhouette half-edges extruded to infinity, its faces as the
// near cap and their projections to infinity as the far cap. Back faces that
// fail the depth test increment, front faces decrement: a non-zero count
// means the surface is inside a volume, wherever the camera is.

// #import common/light_frame.wgsl
// #import common/camera.wgsl
// #import wedges/wedges_common.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var<uniform> camera: Camera;

@group(2) @binding(0) var<storage, read> positions: array<vec4<f32>>;
@group(2) @binding(1) var<storage, read> faces: array<Face>;
@group(2) @binding(2) var<storage, read> face_state: array<u32>;
@group(2) @binding(3) var<storage, read> half_edges: array<WedgeRecord>;
@group(2) @binding(4) var<storage, read> caps: array<u32>;

fn finite_clip(p: vec3<f32>) -> vec4<f32> {
    return camera.view_proj * vec4<f32>(p, 1.0);
}

// The side quad of half-edge `vertex / 6`, wound outwards: b, a, a at
// infinity, b at infinity (the volume lies on the negative side of the plane
// through the light's centre, a and b).
@vertex
fn wedges_side_vertex(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    let record = half_edges[vertex / SIDE_VERTICES];
    let a = record.a.xyz;
    let b = record.b.xyz;
    switch (vertex % SIDE_VERTICES) {
        case 0u, 3u: {
            return finite_clip(b);
        }
        case 1u: {
            return finite_clip(a);
        }
        case 2u, 4u: {
            return clip_at_infinity(camera.view_proj, frame, a);
        }
        default: {
            return clip_at_infinity(camera.view_proj, frame, b);
        }
    }
}

// The near cap (the face, turned to face the light) and the far cap (its
// projection to infinity, wound the other way) of cap face `vertex / 6`.
@vertex
fn wedges_cap_vertex(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    let f = caps[vertex / CAP_VERTICES];
    let face = faces[f];
    let corner = vertex % CAP_VERTICES;
    let reversed = (face_state[f] & STATE_REVERSED) != 0u;
    // Near cap: v0, v1, v2 when the winding faces the light, else v0, v2, v1.
    // Far cap: the opposite order.
    var index = face.v0;
    let near = corner < 3u;
    let k = corner % 3u;
    let flip = reversed != !near;
    if (k == 1u) {
        index = select(face.v1, face.v2, flip);
    } else if (k == 2u) {
        index = select(face.v2, face.v1, flip);
    }
    let p = positions[index].xyz;
    if (near) {
        return finite_clip(p);
    }
    return clip_at_infinity(camera.view_proj, frame, p);
}
