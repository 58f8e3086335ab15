// Hard shadow mapping (Williams 1978): one depth comparison per pixel against
// the shadow map seen from the light's centre. Visibility is 0 or 1.

// #import common/fullscreen.wgsl
// #import common/light_frame.wgsl
// #import common/shadow_map.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var gbuffer_position: texture_2d<f32>;
@group(1) @binding(1) var gbuffer_normal: texture_2d<f32>;
@group(2) @binding(0) var shadow_map: texture_2d<f32>;

@fragment
fn hard_lookup(in: FullscreenVertex) -> @location(0) f32 {
    let position = textureLoad(gbuffer_position, vec2<i32>(in.clip.xy), 0);
    if (position.w < 0.5) {
        return 1.0;
    }
    if (!in_front_of_light(frame, position.xyz)) {
        return 0.0;
    }
    let uvd = light_uv_depth(frame, position.xyz);
    return select(0.0, 1.0, uvd.z <= shadow_map_depth(shadow_map, uvd.xy));
}
