// Atty et al. 2006: the soft shadow map projected onto the receivers, from the
// light's centre, as a projective texture (Sec. 3.1), giving screen-space
// visibility. Two-sided: the larger occlusion of the front- and back-face
// maps (Sec. 3.5).

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import atty/atty_settings.wgsl
// #import atty/atty_geometry.wgsl
// #import atty/atty_counts.wgsl

@group(2) @binding(0) var soft_shadow_front: texture_2d<f32>;
@group(2) @binding(1) var soft_shadow_back: texture_2d<f32>;
// Per texel, x: the nearest receiver's depth; with `receiver_plane`, the receiver planes
// (atty_receiver_map.wgsl), whose y, z hold the plane's slope; without, the receiver map.
@group(2) @binding(2) var receiver_map: texture_2d<f32>;
@group(2) @binding(3) var<uniform> settings: AttySettings;
// The projection's counters (atty_counts.wgsl): 0, texel reads; 1, the bytes they fetched.
@group(2) @binding(4) var<storage, read_write> read_counts: array<atomic<u32>>;

// Bytes of one texel read (the pipeline sets them from the formats: src/lib.rs's projection): of
// the G-buffer's position and normal (Rgba32Float), of the receiver map (R32Float, or Rgba32Float
// planes with receiver_plane) and of the soft shadow maps (R32Float, or R16Float with
// accumulation = f16).
override GBUFFER_TEXEL_BYTES: u32;
override RECEIVER_TEXEL_BYTES: u32;
override SOFT_SHADOW_TEXEL_BYTES: u32;

// Texel reads of this invocation (textureLoad calls), and the bytes they fetched, for the counts.
var<private> reads: u32;
var<private> read_bytes: u32;

// Bilinear interpolation of an unfilterable float texture (R32Float needs a feature to be
// filtered) that leaves out the texels whose receiver lies at another depth than the lookup's
// (by more than `tolerance`): at a receiver depth edge the SSM holds the occlusion of two
// different surfaces, and blending them would shade one with the other's shadow. When no
// texel of the four qualifies, the nearest one is used.
fn receiver_bilinear(map: texture_2d<f32>, uv: vec2<f32>, depth: f32, tolerance: f32) -> f32 {
    let size = vec2<f32>(textureDimensions(map));
    let position = uv * size - 0.5;
    let base = floor(position);
    let t = position - base;
    let limit = vec2<i32>(size) - 1;
    var sum = 0.0;
    var total = 0.0;
    for (var corner = 0; corner < 4; corner++) {
        let step = vec2<i32>(corner & 1, corner >> 1u);
        let texel = clamp(vec2<i32>(base) + step, vec2<i32>(0), limit);
        let weights = select(1.0 - t, t, vec2<bool>(step == vec2<i32>(1)));
        let same_surface = abs(textureLoad(receiver_map, texel, 0).x - depth) <= tolerance;
        let weight = select(0.0, weights.x * weights.y, same_surface);
        sum += weight * textureLoad(map, texel, 0).x;
        total += weight;
    }
    reads += 8u;
    read_bytes += 4u * (RECEIVER_TEXEL_BYTES + SOFT_SHADOW_TEXEL_BYTES);
    if (total <= 1e-6) {
        reads += 1u;
        read_bytes += SOFT_SHADOW_TEXEL_BYTES;
        return textureLoad(map, clamp(vec2<i32>(uv * size), vec2<i32>(0), limit), 0).x;
    }
    return sum / total;
}

// Depth margin of the hidden-receiver test against the nearest receiver's plane, in receiver-map
// texel footprints at the lookup's depth: a tenth of the normal offset's half texel
// (normal_offset = 0.5), which keeps a receiver's own points in front of its plane; it covers the
// plane's rounding (atty_geometry.wgsl).
const PLANE_MARGIN_TEXELS: f32 = 0.05;

// With `receiver_plane`: the depth, along the ray through ndc `q`, of the plane of the receiver in
// texel `texel` of the receiver map (which holds (depth, slope.x, slope.y)); NO_SURFACE where the
// texel holds none.
fn texel_plane_depth(texel: vec2<i32>, q: vec2<f32>) -> f32 {
    let receiver = textureLoad(receiver_map, texel, 0);
    reads += 1u;
    read_bytes += RECEIVER_TEXEL_BYTES;
    if (receiver.x >= NO_SURFACE) {
        return NO_SURFACE;
    }
    let size = vec2<f32>(textureDimensions(receiver_map));
    let texel_ndc = (vec2<f32>(texel) + 0.5) / size * 2.0 - 1.0;
    return patch_ray_plane_depth(texel_ndc, receiver.x, receiver.yz, q);
}

// With `receiver_plane`: the bilinear interpolation of both SSMs (the larger occlusion) at the
// point `uvd` (its uv and depth) over the four texels whose receiver's plane passes within
// `tolerance` of it, along its own ray: the texels of the point's own surface, even where that
// surface is seen edge-on from the light and fills a texel or two (a texel beside it holds another
// surface, deeper or nearer, whose occlusion is not the point's). Where none does, the texel whose
// plane passes nearest.
fn plane_bilinear(uvd: vec3<f32>, tolerance: f32) -> f32 {
    let size = vec2<f32>(textureDimensions(receiver_map));
    let q = uvd.xy * 2.0 - 1.0;
    let position = uvd.xy * size - 0.5;
    let base = floor(position);
    let t = position - base;
    let limit = vec2<i32>(size) - 1;
    var sum = vec2<f32>(0.0);
    var total = 0.0;
    var closest = NO_SURFACE;
    var closest_value = vec2<f32>(0.0);
    for (var corner = 0; corner < 4; corner++) {
        let step = vec2<i32>(corner & 1, corner >> 1u);
        let texel = clamp(vec2<i32>(base) + step, vec2<i32>(0), limit);
        let gap = abs(texel_plane_depth(texel, q) - uvd.z);
        let value = vec2<f32>(textureLoad(soft_shadow_front, texel, 0).x, textureLoad(soft_shadow_back, texel, 0).x);
        reads += 2u;
        read_bytes += 2u * SOFT_SHADOW_TEXEL_BYTES;
        let weights = select(1.0 - t, t, vec2<bool>(step == vec2<i32>(1)));
        let weight = select(0.0, weights.x * weights.y, gap <= tolerance);
        sum += weight * value;
        total += weight;
        if (gap < closest) {
            closest = gap;
            closest_value = value;
        }
    }
    let occlusion = select(closest_value, sum / total, total > 1e-6);
    return max(occlusion.x, occlusion.y);
}

@fragment
fn atty_project(in: FullscreenVertex) -> @location(0) f32 {
    let visibility = project(in);
    record_count(0u, vec2<i32>(in.clip.xy), reads);
    record_count(1u, vec2<i32>(in.clip.xy), read_bytes);
    return visibility;
}

// The visibility at the pixel of `in`.
fn project(in: FullscreenVertex) -> f32 {
    let point = screen_point(in);
    // The G-buffer's position and normal.
    reads = 2u;
    read_bytes = 2u * GBUFFER_TEXEL_BYTES;
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
    if (settings.receiver_plane != 0.0) {
        // Behind the nearest receiver's tangent plane along the lookup's own ray: the plane gives
        // that receiver's depth there, not at the texel's centre, so no depth tolerance is needed,
        // and a point just behind a wall seen at a grazing angle (the ground outside a box around
        // the light) is hidden, not read as the wall.
        let size = vec2<f32>(textureDimensions(receiver_map));
        let texel = min(vec2<i32>(uvd.xy * size), vec2<i32>(size) - 1);
        if (uvd.z > texel_plane_depth(texel, uvd.xy * 2.0 - 1.0) + PLANE_MARGIN_TEXELS * shadow_texel_size(frame, receiver_map, uvd.z)) {
            return 0.0;
        }
        // The point's own surface, found by its plane where the point itself (not the lookup moved
        // off it) lies.
        let own = light_uv_depth(frame, point.position);
        let occlusion = plane_bilinear(own, settings.receiver_tolerance * shadow_texel_size(frame, receiver_map, own.z));
        return 1.0 - clamp(occlusion, 0.0, 1.0);
    }
    // The SSM holds the occlusion of the receiver nearest the light's centre in each texel. A point
    // behind it (an object with the role `both` between it and the light) has no value of its own:
    // count it as in umbra, as a hard shadow would.
    let nearest = shadow_map_depth(receiver_map, uvd.xy);
    reads += 1u;
    read_bytes += RECEIVER_TEXEL_BYTES;
    // Depths within this of the lookup's count as the same receiver: a constant bias plus
    // `receiver_tolerance` texel footprints of the receiver map at this depth.
    let tolerance = scene_length(frame, settings.receiver_bias) + settings.receiver_tolerance * shadow_texel_size(frame, receiver_map, uvd.z);
    if (uvd.z > nearest + tolerance) {
        return 0.0;
    }
    let occlusion = max(receiver_bilinear(soft_shadow_front, uvd.xy, nearest, tolerance), receiver_bilinear(soft_shadow_back, uvd.xy, nearest, tolerance));
    return 1.0 - clamp(occlusion, 0.0, 1.0);
}
