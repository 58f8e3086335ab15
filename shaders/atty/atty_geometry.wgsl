// Atty et al. 2006, the micro-patch geometry (Sec. 3.3, 3.4, 4.2) that the list pass
// (atty_micro_patches.wgsl) and the accumulation (atty_accumulation.wgsl) evaluate. Its twin is
// ssm-techniques/atty/src/geometry.rs, which also states the paper's own forms; the crate's tests
// check that module against hand-computed cases and run these functions on the GPU against it.
// Coordinates: the light's view space (x along u, y along v, depth along its normal from its
// centre); ndc: the light frame's maps, lateral position / (depth · tan_half).

// #import common/shadow_map.wgsl

// Half extent, in ndc, of a micro-patch's penumbra rectangle (Sec. 3.3) on the plane at depth
// `depth`, for a patch of half size `patch_half` at depth `patch_depth` and a light of half size
// `light_half`: the paper's C_L C_R = (z_R/z_O) C_L O and RR' = LL' (z_R − z_O)/z_O, with z_O the
// apex's depth r/(1+r)·z_P (r = LL'/PP'), written without dividing by r as
// (l + p)/(z_P tan) − l/(z_R tan), so that a point light (r = 0) needs no special case. Its
// centre is the patch's own ndc position. It grows with `depth`: at the deepest receiver (or the
// far plane) it holds every receiver's rectangle.
fn penumbra_half_ndc(light_half: vec2<f32>, tan_half: vec2<f32>, patch_half: vec2<f32>, patch_depth: f32, depth: f32) -> vec2<f32> {
    let reach = (light_half + patch_half) / (patch_depth * tan_half);
    let shrink = light_half / tan_half;
    return reach - shrink / depth;
}

// Length of [low, high] ∩ [-half, half] divided by 2·half (Sec. 4.2: the light normalised to
// [0, 1] and the interval clamped, as the paper's saturating MOV); a point light (half = 0) is
// hit when it lies inside the interval.
fn light_overlap(low: f32, high: f32, half: f32) -> f32 {
    if (half <= 0.0) {
        return select(0.0, 1.0, low <= 0.0 && 0.0 <= high);
    }
    let a = clamp((low + half) / (2.0 * half), 0.0, 1.0);
    let b = clamp((high + half) / (2.0 * half), 0.0, 1.0);
    return max(b - a, 0.0);
}

// The fraction of the light that a micro-patch (centre `patch_centre`, half size `patch_half`,
// depth `patch_depth`) hides from the receiver point at lateral position `receiver`, depth
// `receiver_depth` (Sec. 3.4): the patch projected from the point back onto the light's plane, a
// scaling about the point by z_R / (z_R − z_P) (Drettakis and Fiume 1994), and the hidden area
// the product of the two 1-D overlaps (Sec. 4.2). 0 for a point not behind the patch.
fn hidden_fraction(light_half: vec2<f32>, patch_centre: vec2<f32>, patch_half: vec2<f32>, patch_depth: f32, receiver: vec2<f32>, receiver_depth: f32) -> f32 {
    if (receiver_depth <= patch_depth) {
        return 0.0;
    }
    let scale = receiver_depth / (receiver_depth - patch_depth);
    let low = receiver + (patch_centre - patch_half - receiver) * scale;
    let high = receiver + (patch_centre + patch_half - receiver) * scale;
    return light_overlap(low.x, high.x, light_half.x) * light_overlap(low.y, high.y, light_half.y);
}

// Depth, along the ray through ndc `q`, of the tangent plane of the receiver at ndc `receiver_ndc`,
// depth `receiver_depth`, whose 1/depth has gradient `slope` / receiver_depth per ndc unit (a
// plane's 1/depth is affine in ndc: 1/z(q) = (1 + slope·(q − q_R)) / z_R; atty_receiver_map.wgsl
// measures `slope`). NO_SURFACE where the ray meets the plane behind the light or runs along it.
fn patch_ray_plane_depth(receiver_ndc: vec2<f32>, receiver_depth: f32, slope: vec2<f32>, q: vec2<f32>) -> f32 {
    let denominator = 1.0 + dot(slope, q - receiver_ndc);
    return select(NO_SURFACE, receiver_depth / denominator, denominator > 0.0);
}

// True when a micro-patch centred at ndc `q`, depth `patch_depth`, lies on the receiver's tangent
// plane or behind it, within `slack` (a depth): it hides nothing the receiver sees. A segment from
// the receiver to a point of the light in front of the plane stays in front of it, so what lies
// behind the plane can hide only light the receiver's own surface already hides; and a flat
// surface's own micro-patches, centred on it, cannot hide it.
fn patch_on_or_behind_receiver_plane(receiver_ndc: vec2<f32>, receiver_depth: f32, slope: vec2<f32>, q: vec2<f32>, patch_depth: f32, slack: f32) -> bool {
    return patch_depth >= patch_ray_plane_depth(receiver_ndc, receiver_depth, slope, q) - slack;
}
