// The receivers past the light frame's widest angle (ssm-core's beyond_frame.rs), run by the
// framework after a technique whose maps see the light through that one frame
// (LightView::Frame) when the frame reached its widest angle (MAX_HALF_ANGLE_TANGENT, about 84
// degrees off the light's normal). There its maps hold no texel, and its value is whatever its
// sampler's clamp finds. The framework answers those pixels instead, from four side faces around
// the light's centre that cover the rest of its front hemisphere (a hemicube's sides, as the
// radiosity engines render one for an area light): a hard shadow from the centre, the same for
// every such technique, and it counts them so that the report says how many it answered.

// #import common/screen_pass.wgsl
// #import common/pixel_work.wgsl
// #import common/side_faces.wgsl

@group(2) @binding(0) var visibility: texture_storage_2d<r32float, read_write>;
// The side faces' linear depth maps (common/side_faces.wgsl): +u, -u, +v, -v.
@group(2) @binding(1) var face_plus_u: texture_2d<f32>;
@group(2) @binding(2) var face_minus_u: texture_2d<f32>;
@group(2) @binding(3) var face_plus_v: texture_2d<f32>;
@group(2) @binding(4) var face_minus_v: texture_2d<f32>;
// Word `light` counts the pixels answered here for that light (cleared every frame).
@group(2) @binding(5) var<storage, read_write> answered: array<atomic<u32>>;
// Counters 0 (texel reads), 1 (storage bytes) and 2 (the bytes the reads fetched) of a counting
// frame (common/read_counts.wgsl): the G-buffer's two texels at every pixel (Rgba32Float, 16 bytes
// each) and, where the pixel is answered here, one side face's (R32Float, 4 bytes) and one
// r32float visibility stored (4 bytes).
@group(2) @binding(6) var<storage, read_write> read_counts: array<atomic<u32>>;

// Bytes of one texel of the G-buffer's position and normal (GBuffer::POSITION_FORMAT and
// NORMAL_FORMAT, Rgba32Float), of a side face's linear depth (LightDepthMap::FORMAT, R32Float)
// and of the visibility (VISIBILITY_FORMAT, R32Float); a test in ssm-core's beyond_frame.rs reads
// these lines.
const GBUFFER_TEXEL_BYTES: u32 = 16u;
const SIDE_FACE_TEXEL_BYTES: u32 = 4u;
const VISIBILITY_TEXEL_BYTES: u32 = 4u;

struct BeyondFrameSettings {
    // x: this light's index (its word of `answered`); y: the texels of the receiver's own depth
    // change its bias allows (side_face_hard_visibility); z, w unused.
    values: vec4<f32>,
};
@group(2) @binding(7) var<uniform> settings: BeyondFrameSettings;

@compute @workgroup_size(8, 8)
fn beyond_frame_visibility(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(visibility);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let texel = vec2<i32>(id.xy);
    let point = screen_point_at(texel);
    var reads = 2u;
    var read_bytes = 2u * GBUFFER_TEXEL_BYTES;
    var stored = 0u;
    let offset = point.position - frame.centre.xyz;
    if (point.covered && !unlit_by_rule(point) && past_the_frame(frame, offset)) {
        let answer = side_face_hard_visibility(frame, face_plus_u, face_minus_u, face_plus_v, face_minus_v, offset, point.normal, settings.values.y);
        textureStore(visibility, texel, vec4<f32>(answer, 0.0, 0.0, 0.0));
        atomicAdd(&answered[u32(settings.values.x)], 1u);
        reads += 1u;
        read_bytes += SIDE_FACE_TEXEL_BYTES;
        stored = VISIBILITY_TEXEL_BYTES;
    }
    record_pixel_work_and_read_bytes(0u, 1u, 2u, texel, reads, stored, read_bytes);
}
