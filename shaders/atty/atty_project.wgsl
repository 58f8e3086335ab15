// Atty et al. 2006: the soft shadow map projected onto the receivers, from the
// light's centre, as a projective texture (Sec. 3.1), giving screen-space
// visibility. Two-sided: the larger occlusion of the front- and back-face
// maps (Sec. 3.5).

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import atty/atty_settings.wgsl

@group(2) @binding(0) var soft_shadow_front: texture_2d<f32>;
@group(2) @binding(1) var soft_shadow_back: texture_2d<f32>;
@group(2) @binding(2) var receiver_map: texture_2d<f32>;
@group(2) @binding(3) var<uniform> settings: AttySettings;

// Bilinear interpolation of an unfilterable float texture (R32Float needs a feature to be filtered).
fn bilinear(map: texture_2d<f32>, uv: vec2<f32>) -> f32 {
    let size = vec2<f32>(textureDimensions(map));
    let position = uv * size - 0.5;
    let base = floor(position);
    let t = position - base;
    let limit = vec2<i32>(size) - 1;
    let p0 = clamp(vec2<i32>(base), vec2<i32>(0), limit);
    let p1 = clamp(vec2<i32>(base) + 1, vec2<i32>(0), limit);
    let top = mix(textureLoad(map, p0, 0).x, textureLoad(map, vec2<i32>(p1.x, p0.y), 0).x, t.x);
    let bottom = mix(textureLoad(map, vec2<i32>(p0.x, p1.y), 0).x, textureLoad(map, p1, 0).x, t.x);
    return mix(top, bottom, t.y);
}

@fragment
fn atty_project(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        return trivial;
    }
    // Occluders receive no shadow (the paper's stated limitation, Sec. 1 and 7).
    if (!point.receives) {
        return 1.0;
    }
    let lookup = normal_offset_position(frame, receiver_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    if (any(uvd.xy < vec2<f32>(0.0)) || any(uvd.xy >= vec2<f32>(1.0))) {
        return 1.0;
    }
    // The SSM holds the occlusion of the receiver nearest the light's centre in each texel. A point
    // behind it (an object with the role `both` between it and the light) has no value of its own:
    // count it as in umbra, as a hard shadow would.
    let nearest = shadow_map_depth(receiver_map, uvd.xy);
    if (uvd.z > nearest + settings.receiver_bias + settings.receiver_tolerance * shadow_texel_size(frame, receiver_map, uvd.z)) {
        return 0.0;
    }
    let occlusion = max(bilinear(soft_shadow_front, uvd.xy), bilinear(soft_shadow_back, uvd.xy));
    return 1.0 - clamp(occlusion, 0.0, 1.0);
}
