// Hard shadow mapping (Williams 1978): one depth comparison per pixel against
// the shadow map seen from the light's centre. Visibility is 0 or 1.

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl

struct HardSettings {
    // Normal offset of the lookup point, in shadow-map texels.
    normal_offset: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
};
@group(2) @binding(0) var shadow_map: texture_2d<f32>;
@group(2) @binding(1) var<uniform> settings: HardSettings;

@fragment
fn hard_lookup(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        return trivial;
    }
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    return select(0.0, 1.0, uvd.z <= shadow_map_depth(shadow_map, uvd.xy));
}
