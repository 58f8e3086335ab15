// Lookups into a linear-depth light map (ssm-core's LightDepthMap): the
// stored value is the distance along the light's normal of the nearest
// surface, with bias already added; NO_SURFACE where nothing was drawn.

// #import common/light_frame.wgsl

const NO_SURFACE: f32 = 3.40282347e38;

// Nearest-texel depth at shadow-map coordinates `uv`; NO_SURFACE outside the map.
fn shadow_map_depth(map: texture_2d<f32>, uv: vec2<f32>) -> f32 {
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) {
        return NO_SURFACE;
    }
    let size = vec2<f32>(textureDimensions(map));
    return textureLoad(map, vec2<i32>(uv * size), 0).x;
}

// World-space side of one texel of `map` at linear depth `depth` (the larger of its two sides).
fn shadow_texel_size(frame: LightFrame, map: texture_2d<f32>, depth: f32) -> f32 {
    let size = vec2<f32>(textureDimensions(map));
    return 2.0 * depth * max(frame.projection.x / size.x, frame.projection.y / size.y);
}

// Normal offset (Holbert 2011): the point to look up, moved `texels` texels
// off the surface along its normal, on the side facing the light. Removes the
// acne of surfaces at grazing angles to the light, which a depth bias alone
// cannot, since their depth changes by many units across one texel.
fn normal_offset_position(frame: LightFrame, map: texture_2d<f32>, position: vec3<f32>, normal: vec3<f32>, texels: f32) -> vec3<f32> {
    let towards_light = select(-normal, normal, dot(normal, frame.centre.xyz - position) >= 0.0);
    return position + towards_light * texels * shadow_texel_size(frame, map, light_depth(frame, position));
}

// Offset of sample `i` of `count` across [-1, 1], at the centres of equal cells (the regular
// kernels of PCSS and SSSM).
fn grid_offset(i: u32, count: u32) -> f32 {
    return (f32(i) + 0.5) / f32(count) * 2.0 - 1.0;
}

// The depth a shadow-map tap at `uv` is compared with, for a receiver at world `position` with
// normal `normal` and light depth `receiver_depth`: with `plane`, the depth of the receiver's
// tangent plane along that tap's ray, so that a wide kernel on a surface tilted to the light does
// not find the surface itself (Isidoro 2006); without, the receiver's own depth (Fernando 2005).
fn tap_receiver_depth(frame: LightFrame, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, receiver_depth: f32, plane: bool) -> f32 {
    if (!plane) {
        return receiver_depth;
    }
    return receiver_plane_depth(frame, position, normal, uv, receiver_depth);
}

// What tap_receiver_depth compares each tap with, prepared once per receiver point: read it at a
// tap's uv with tap_plane_depth.
fn receiver_tap_plane(frame: LightFrame, position: vec3<f32>, normal: vec3<f32>, receiver_depth: f32, plane: bool) -> TapPlane {
    if (!plane) {
        return constant_tap_plane(receiver_depth);
    }
    return tap_plane(frame, position, normal, receiver_depth);
}
