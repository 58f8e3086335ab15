// PCSS past the light frame's widest angle (about 84 degrees off the light's normal), on the side
// faces of a hemicube around the light's centre (common/side_faces.wgsl): the receivers there have
// no texel in the frame's map, and a floor under a light on a wall, or beside a light resting on
// it, lies there. Fernando's three steps on the face the receiver lies in (pcss_common.wgsl does
// them in the frame):
//
// 1. Blocker search over the region of the face's map through which the receiver can see the light
//    at any depth from the face's near plane to its own: the image of the pyramid from the
//    receiver to the light's rectangle, cut at the near plane. In the frame the light lies in the
//    near plane and this is PCSS's usual back-projection, searched on an n x n grid over it; on a
//    side face the light runs along the face's axis, part of it nearer than any blocker, part
//    behind the face's origin, and the image reaches the whole map: its n² taps lie on the
//    segments from the receiver to n x n points of the light, one each, spread along them.
// 2. The average depth of the blockers found (along the face's axis).
// 3. PCF over the light seen through the blockers' plane: m x m points of the light's rectangle,
//    each projected from the receiver onto the plane at the blockers' depth and onto the map, one
//    tap each. With the light parallel to the map (the frame) these taps are PCSS's m x m grid over
//    its penumbra estimate; here they follow the light's foreshortened, tilted image. A light point
//    no farther from the receiver along the axis than the blockers' plane cannot be hidden by it,
//    and counts as lit.
//
// Each tap is compared with the receiver's tangent plane along the ray through the tap's texel
// centre (what the map holds there, the receiver's own surface included, at grazing angles too),
// less a small relative bias.

// #import common/screen_pass.wgsl
// #import common/pixel_work.wgsl
// #import common/shadow_map.wgsl
// #import common/side_faces.wgsl

@group(2) @binding(0) var visibility: texture_storage_2d<r32float, read_write>;
// The side faces' linear depth maps (common/side_faces.wgsl): +u, -u, +v, -v.
@group(2) @binding(1) var face_plus_u: texture_2d<f32>;
@group(2) @binding(2) var face_minus_u: texture_2d<f32>;
@group(2) @binding(3) var face_plus_v: texture_2d<f32>;
@group(2) @binding(4) var face_minus_v: texture_2d<f32>;
// Counters 0 (texel reads), 1 (storage bytes) and 2 (bytes read) of a counting frame
// (common/read_counts.wgsl).
@group(2) @binding(5) var<storage, read_write> read_counts: array<atomic<u32>>;

struct PcssSideFaceSettings {
    // Samples per axis of the blocker search (n) and of the filter (m), as the frame's pass.
    blocker_kernel: u32,
    pcf_kernel: u32,
    // The face's near plane (depth along its axis), which bounds the search as the frame's near
    // plane bounds PCSS's.
    near: f32,
    // Relative depth bias of a tap against the receiver's plane.
    relative_bias: f32,
};
@group(2) @binding(6) var<uniform> settings: PcssSideFaceSettings;

// Texel reads of this invocation: the G-buffer's two, and one per tap inside a face's map.
var<private> reads: u32 = 0u;
// The bytes those reads fetched, each texel its format's size: the G-buffer's position and normal
// are Rgba32Float (ssm-core's GBuffer::POSITION_FORMAT, NORMAL_FORMAT), the faces' linear depth
// R32Float (SideFaceMaps, LightDepthMap::FORMAT).
var<private> read_bytes: u32 = 0u;
const GBUFFER_TEXEL_BYTES: u32 = 16u;
const FACE_TEXEL_BYTES: u32 = 4u;

// Every face's size in texels.
fn face_size() -> vec2<f32> {
    return vec2<f32>(textureDimensions(face_plus_u));
}

// The stored depth of face `face` at map coordinates `uv`; NO_SURFACE outside the map (no read).
fn face_depth(face: u32, uv: vec2<f32>) -> f32 {
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) {
        return NO_SURFACE;
    }
    reads += 1u;
    read_bytes += FACE_TEXEL_BYTES;
    switch face {
        case 0u: { return shadow_map_depth(face_plus_u, uv); }
        case 1u: { return shadow_map_depth(face_minus_u, uv); }
        case 2u: { return shadow_map_depth(face_plus_v, uv); }
        default: { return shadow_map_depth(face_minus_v, uv); }
    }
}

// Depth along the face's axis of the receiver's tangent plane (normal `plane_normal`, through
// `receiver`, both in face coordinates) on the ray through the centre of the texel at `uv`; the
// receiver's own depth where that ray misses the plane.
fn plane_depth_at_texel(receiver: vec3<f32>, plane_normal: vec3<f32>, uv: vec2<f32>) -> f32 {
    let centre = (floor(uv * face_size()) + 0.5) / face_size();
    let ray = vec3<f32>(2.0 * centre.x - 1.0, centre.y, 1.0);
    let denominator = dot(plane_normal, ray);
    let depth = dot(plane_normal, receiver) / denominator;
    return select(receiver.z, depth, abs(denominator) > 1e-12 && depth > 0.0);
}

// The tap at `uv` holds a surface nearer the light's centre than the receiver's plane there.
fn blocks(face: u32, receiver: vec3<f32>, plane_normal: vec3<f32>, uv: vec2<f32>) -> vec2<f32> {
    let stored = face_depth(face, uv);
    let plane = plane_depth_at_texel(receiver, plane_normal, uv);
    return vec2<f32>(select(0.0, 1.0, stored < plane * (1.0 - settings.relative_bias)), stored);
}

// The receiver's pixel as every face sees it: its offset from the light's centre and its normal
// (world), and both in its own face's coordinates.
struct SideFaceReceiver {
    face: SideFace,
    offset: vec3<f32>,
    normal: vec3<f32>,
    point: vec3<f32>,
    plane_normal: vec3<f32>,
};

// The tap at `tap` (the receiver's face's coordinates, forward > 0) against the receiver's plane,
// looked up in the face the tap's direction lies in: its own face's map unless the tap crossed a
// diagonal of the hemicube, where the faces meet (a search or filter around a receiver near a
// diagonal reaches over it), then the neighbouring face's, with the plane in that face's
// coordinates. Returns (1 where it blocks, the stored surface's depth along the receiver's face's
// axis, so that blockers found on either face average on one axis).
fn blocks_at(receiver: SideFaceReceiver, tap: vec3<f32>) -> vec2<f32> {
    let uv = side_face_uv(tap);
    if (uv.x >= 0.0 && uv.x < 1.0) {
        return blocks(receiver.face.index, receiver.point, receiver.plane_normal, uv);
    }
    let direction = tap.x * receiver.face.across + tap.y * frame.normal.xyz + tap.z * receiver.face.forward;
    let other = side_face_of(frame, direction);
    let in_other = side_face_coordinates(frame, other, direction);
    let found = blocks(
        other.index,
        side_face_coordinates(frame, other, receiver.offset),
        side_face_coordinates(frame, other, receiver.normal),
        side_face_uv(in_other),
    );
    // The stored surface lies on the tap's ray at depth found.y along the other face's axis.
    let surface = direction * (found.y / max(in_other.z, 1e-12));
    return vec2<f32>(found.x, dot(surface, receiver.face.forward));
}

// The point at depth `depth` along the face's axis on the segment from `receiver` to the light
// point `light_point` (face coordinates, down 0); w = 0 where the segment does not reach it.
fn through_plane(receiver: vec3<f32>, light_point: vec3<f32>, depth: f32) -> vec4<f32> {
    if (light_point.z >= depth || receiver.z <= depth) {
        return vec4<f32>(0.0);
    }
    let t = (receiver.z - depth) / (receiver.z - light_point.z);
    return vec4<f32>(mix(receiver, light_point, t), 1.0);
}

// The light's point at (s, t) in [-1, 1]² of its rectangle, in face coordinates.
fn light_point(face: SideFace, s: f32, t: f32) -> vec3<f32> {
    let offset = s * frame.u_axis.w * frame.u_axis.xyz + t * frame.v_axis.w * frame.v_axis.xyz;
    return side_face_coordinates(frame, face, offset);
}

fn side_face_pcss(offset: vec3<f32>, normal: vec3<f32>) -> f32 {
    let face = side_face_of(frame, offset);
    let receiver = side_face_coordinates(frame, face, offset);
    let seen = SideFaceReceiver(face, offset, normal, receiver, side_face_coordinates(frame, face, normal));

    // 1. The search: n x n points of the light, each segment from the receiver to the point (cut at
    // the near plane) tapped once, at a depth along it of its own (stratified over the n² taps):
    // together they sample the pyramid's image. Its bounding box is no region to search on a grid:
    // the light reaches the face's origin, where a segment's down tangent grows without bound.
    let n = max(settings.blocker_kernel, 1u);
    var blocker_sum = 0.0;
    var blocker_count = 0u;
    for (var j = 0u; j < n; j++) {
        for (var i = 0u; i < n; i++) {
            let st = (vec2<f32>(f32(i), f32(j)) + 0.5) / f32(n) * 2.0 - 1.0;
            let lit_point = light_point(face, st.x, st.y);
            var far_end = vec4<f32>(lit_point, 1.0);
            if (lit_point.z <= settings.near) {
                far_end = through_plane(receiver, lit_point, settings.near);
            }
            if (far_end.w == 0.0) {
                continue;
            }
            // The golden ratio's sequence spreads the taps' places along their segments evenly
            // over the n² taps, whatever n.
            let along = fract(0.5 + f32(j * n + i) * 0.618034);
            let tap = blocks_at(seen, mix(receiver, far_end.xyz, along));
            if (tap.x > 0.0) {
                blocker_sum += tap.y;
                blocker_count += 1u;
            }
        }
    }
    if (blocker_count == 0u) {
        return 1.0;
    }
    // 2. The blockers' average depth.
    let blocker_depth = blocker_sum / f32(blocker_count);

    // 3. The light through the blockers' plane, one tap per light point.
    let m = max(settings.pcf_kernel, 1u);
    var lit = 0.0;
    for (var j = 0u; j < m; j++) {
        for (var i = 0u; i < m; i++) {
            let st = (vec2<f32>(f32(i), f32(j)) + 0.5) / f32(m) * 2.0 - 1.0;
            let through = through_plane(receiver, light_point(face, st.x, st.y), blocker_depth);
            if (through.w == 0.0) {
                lit += 1.0;
                continue;
            }
            lit += 1.0 - blocks_at(seen, through.xyz).x;
        }
    }
    return lit / f32(m * m);
}

@compute @workgroup_size(8, 8)
fn pcss_side_faces(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(visibility);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let texel = vec2<i32>(id.xy);
    let point = screen_point_at(texel);
    reads = 2u;
    read_bytes = 2u * GBUFFER_TEXEL_BYTES;
    var stored = 0u;
    let offset = point.position - frame.centre.xyz;
    if (point.covered && !unlit_by_rule(point) && past_the_frame(frame, offset)) {
        let answer = side_face_pcss(offset, point.normal);
        textureStore(visibility, texel, vec4<f32>(clamp(answer, 0.0, 1.0), 0.0, 0.0, 0.0));
        stored = 4u;
    }
    record_pixel_work_and_read_bytes(0u, 1u, 2u, texel, reads, stored, read_bytes);
}
