// The average of K hard shadow maps rendered from stratified points on the
// light (the reference of Shen et al., Table 2, and of Buades et al., Fig. 13).
// One dispatch per sample adds that sample's hard visibility, weighted 1/K,
// to the visibility target; a clear to 0 precedes the first.

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import common/read_counts.wgsl
// #import common/side_faces.wgsl

// The settings, declared once in Rust (`MultiSmSettingsUniform`, ssm-techniques/multi-sm/src/lib.rs),
// whose derive writes this struct.
// #import rust/MultiSmSettings

// Group 0 (`frame`) holds this sample's frame: a point light at the sample, with the light's axes.
@group(2) @binding(0) var shadow_map: texture_2d<f32>;
@group(2) @binding(1) var<uniform> settings: MultiSmSettings;
@group(2) @binding(2) var visibility: texture_storage_2d<r32float, read_write>;
// Counters 0 (texel reads), 1 (storage bytes) and 2 (bytes read) of multi_sm_accumulate,
// (invocations, count) per bucket (common/read_counts.wgsl), summed over the K dispatches; written
// only with COUNT_READS (a counting frame, TechniqueSetup::count_work). Each textureLoad is one
// texel: per invocation inside the target, the G-buffer's two, the visibility's running sum, and
// the shadow map's or a side face's one where the sample's lookup is made (the normal offset reads
// none); it stores one r32float, 4 bytes. A texel read costs its format's size (the *_TEXEL_BYTES
// below).
@group(2) @binding(3) var<storage, read_write> read_counts: array<atomic<u32>>;
// Bytes of one texel of what the accumulation reads: the G-buffer's position and normal are
// Rgba32Float (ssm-core's GBuffer::POSITION_FORMAT, NORMAL_FORMAT); the visibility target is
// R32Float (VISIBILITY_FORMAT); the shadow map and the side faces hold linear depth in R32Float
// (LightDepthMap::FORMAT).
const GBUFFER_TEXEL_BYTES: u32 = 16u;
const VISIBILITY_TEXEL_BYTES: u32 = 4u;
const DEPTH_TEXEL_BYTES: u32 = 4u;
// This sample's side faces (common/side_faces.wgsl), +u, -u, +v, -v, drawn around it where its
// frame reaches the widest angle: a receiver past its frame is looked up there, one texel. A 1x1
// texel, never read, where no sample's frame reaches it.
@group(2) @binding(4) var face_plus_u: texture_2d<f32>;
@group(2) @binding(5) var face_minus_u: texture_2d<f32>;
@group(2) @binding(6) var face_plus_v: texture_2d<f32>;
@group(2) @binding(7) var face_minus_v: texture_2d<f32>;

// The share of this sample's stratum (a rectangle of the light centred on the sample, the frame's
// centre) in front of a closed surface's tangent plane at `point`; 1 on an open surface, which the
// ground truth lights from either side.
fn stratum_share_in_front(point: ScreenPoint) -> f32 {
    if (!point.closed) {
        return 1.0;
    }
    return rect_share_in_front(frame, settings.stratum_half_size, point.position, point.normal);
}

@compute @workgroup_size(8, 8)
fn multi_sm_accumulate(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(visibility);
    if (id.x >= size.x || id.y >= size.y) {
        return;
    }
    let texel = vec2<i32>(id.xy);
    let point = screen_point_at(texel);
    var lit = 1.0;
    var reads = 3u;
    var read_bytes = 2u * GBUFFER_TEXEL_BYTES + VISIBILITY_TEXEL_BYTES;
    if (point.covered) {
        // This sample stands for its stratum of the light. On a closed surface, the part of the
        // stratum behind the tangent plane is hidden by the surface itself: the stratum's share in
        // front, exact for a rectangle (light_frame.wgsl), weighs the sample's shadow test, rather
        // than the sample alone deciding (with 16 samples, a face whose plane passes through a
        // column of strata got 4/16 of the light where it sees 1/8). A sample behind the plane
        // sees the surface's back, which its map holds in front of the point: its test says
        // nothing of the stratum's part in front, which is taken as lit. Elsewhere the other
        // shared rules (screen_pass.wgsl).
        let share = stratum_share_in_front(point);
        if (light_sealed(frame) || !in_front_of_light(frame, point.position) || share <= 0.0) {
            lit = 0.0;
        } else if (point.closed && light_centre_height(frame, point.position, point.normal) < 0.0) {
            lit = share;
        } else if (frame_reaches_widest_angle(frame) && past_the_frame(frame, point.position - frame.centre.xyz)) {
            // Past this sample's frame: its hard shadow through the side face around it.
            reads += 1u;
            read_bytes += DEPTH_TEXEL_BYTES;
            let offset = point.position - frame.centre.xyz;
            lit = share * side_face_hard_visibility(frame, face_plus_u, face_minus_u, face_plus_v, face_minus_v, offset, point.normal, settings.side_face_bias_texels);
        } else {
            let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
            let uvd = light_uv_depth(frame, lookup);
            reads += 1u;
            read_bytes += DEPTH_TEXEL_BYTES;
            lit = share * select(0.0, 1.0, uvd.z <= shadow_map_depth(shadow_map, uvd.xy));
        }
    }
    let sum = textureLoad(visibility, texel).x + settings.weight * lit;
    textureStore(visibility, texel, vec4<f32>(sum, 0.0, 0.0, 0.0));
    if (COUNT_READS) {
        let reads_word = read_count_word(0u, texel);
        atomicAdd(&read_counts[reads_word], 1u);
        atomicAdd(&read_counts[reads_word + 1u], reads);
        let bytes_word = read_count_word(1u, texel);
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], 4u);
        let read_bytes_word = read_count_word(2u, texel);
        atomicAdd(&read_counts[read_bytes_word], 1u);
        atomicAdd(&read_counts[read_bytes_word + 1u], read_bytes);
    }
}
