// Hard shadow mapping (Williams 1978): one depth comparison per pixel against
// the shadow map seen from the light's centre. Visibility is 0 or 1.

// #import common/fullscreen.wgsl
// #import common/light_frame.wgsl
// #import common/shadow_map.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var gbuffer_position: texture_2d<f32>;
@group(1) @binding(1) var gbuffer_normal: texture_2d<f32>;
@group(2) @binding(0) var shadow_map: texture_2d<f32>;

struct HardSettings {
    // Normal offset of the lookup point, in shadow-map texels.
    normal_offset: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
};
@group(2) @binding(1) var<uniform> settings: HardSettings;

@fragment
fn hard_lookup(in: FullscreenVertex) -> @location(0) f32 {
    let texel = vec2<i32>(in.clip.xy);
    let position = textureLoad(gbuffer_position, texel, 0);
    if (position.w < 0.5) {
        return 1.0;
    }
    if (!in_front_of_light(frame, position.xyz)) {
        return 0.0;
    }
    let normal = textureLoad(gbuffer_normal, texel, 0).xyz;
    let lookup = normal_offset_position(frame, shadow_map, position.xyz, normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    return select(0.0, 1.0, uvd.z <= shadow_map_depth(shadow_map, uvd.xy));
}
