// The ground truth is traced on the CPU and uploaded into a texture; this
// pass copies it into the visibility target, like any technique's last pass.

// #import common/screen_pass.wgsl

@group(2) @binding(0) var traced: texture_2d<f32>;

@fragment
fn reference_upload(in: FullscreenVertex) -> @location(0) f32 {
    return textureLoad(traced, vec2<i32>(in.clip.xy), 0).x;
}
