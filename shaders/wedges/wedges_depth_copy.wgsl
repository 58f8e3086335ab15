// The G-buffer's camera depth, copied into the technique's Depth24PlusStencil8
// target for the shadow volumes and wedges (the G-buffer's depth has no
// stencil). It is moved by a few units of the last place to the side of the
// surface that faces the light's centre: a cap coinciding with the surface
// (a face is its own volume's near cap) then counts on the right side of it,
// and a thin surface seen from its back is judged on the side facing the
// light, as the ground truth and the shadow maps' normal offset judge it.

// #import common/fullscreen.wgsl
// #import common/light_frame.wgsl
// #import common/camera.wgsl
// #import wedges/wedges_common.wgsl
// #import wedges/wedges_counts.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var gbuffer_depth: texture_depth_2d;
@group(1) @binding(1) var<uniform> settings: WedgesSettings;
@group(1) @binding(2) var gbuffer_position: texture_2d<f32>;
@group(1) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(1) @binding(4) var<uniform> camera: Camera;
@group(1) @binding(5) var<storage, read_write> read_counts: array<atomic<u32>>;

@fragment
fn wedges_depth_copy(in: FullscreenVertex) -> @builtin(frag_depth) f32 {
    let texel = vec2<i32>(in.clip.xy);
    let depth = textureLoad(gbuffer_depth, texel, 0);
    let position = textureLoad(gbuffer_position, texel, 0);
    // The depth and the position, and the normal where a surface covers the pixel.
    let covered = position.w >= 0.5;
    let bytes = GBUFFER_DEPTH_BYTES + select(1u, 2u, covered) * GBUFFER_TEXEL_BYTES;
    record_reads(COUNTER_DEPTH_COPY_READS, texel, select(2u, 3u, covered), bytes);
    if (position.w < 0.5) {
        return depth;
    }
    // The G-buffer's normal is turned towards the camera: the light's side is the camera's when
    // the light's centre is in front of it too.
    let normal = textureLoad(gbuffer_normal, texel, 0).xyz;
    return clamp(depth + volume_depth_offset(frame, settings.depth_bias, position.xyz, normal), 0.0, 1.0);
}
