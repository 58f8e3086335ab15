// The G-buffer's camera depth, copied into the technique's Depth24PlusStencil8
// target for the shadow volumes and wedges (the G-buffer's depth has no
// stencil). It is moved towards the camera by a few units of the last place,
// so that a cap coinciding with the surface it caps (a face shadowing the
// points beside it) counts as behind it on every rasteriser.

// #import common/fullscreen.wgsl
// #import wedges/wedges_common.wgsl

@group(0) @binding(0) var gbuffer_depth: texture_depth_2d;
@group(0) @binding(1) var<uniform> settings: WedgesSettings;

@fragment
fn wedges_depth_copy(in: FullscreenVertex) -> @builtin(frag_depth) f32 {
    let depth = textureLoad(gbuffer_depth, vec2<i32>(in.clip.xy), 0);
    return max(depth - settings.depth_bias, 0.0);
}
