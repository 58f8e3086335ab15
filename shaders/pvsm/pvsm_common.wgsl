// Shared by the passes of Shen, Guennebaud, Yang and Feng 2011, Predicted
// Virtual Soft Shadow Maps with High Quality Filtering (ssm-techniques/pvsm).

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import common/camera.wgsl

struct PvsmSettings {
    // Side of the shadow-map tile grid (SMTG), cells.
    grid_size: u32,
    // Samples per axis of the blocker search on the low-resolution map.
    blocker_kernel: u32,
    // ρ model: 0 dynamic, 1 static, 2 linear, 3 fixed (no prediction).
    prediction: u32,
    // 1: the filter is convolved with the pixel's footprint (Sec. 4.2).
    antialiasing: u32,
    // k: k×k screen-space sub-samples per pixel (the supersampling of Fig. 11); 1: none.
    supersampling: u32,
    // 1: texels compare with the receiver's tangent plane along their ray; 0: with its depth.
    receiver_plane: u32,
    // Normal offset of the lookup point, in texels of the resolution the pixel asked for.
    normal_offset: f32,
    // Constant depth bias, a fraction of the scene's diagonal (scene_length).
    constant_bias: f32,
    // Side of the shadow map of prediction = fixed, texels.
    fixed_size: f32,
    // 1: each texel a point sample, weighted fully when its centre is inside the filter (classic
    // PCF, Fig. 4(a)); 0: each texel a quad weighted by its exact overlap (Eq. 2, Fig. 4(c)).
    point_samples: u32,
    // 1: a tile finer than the pixel's predicted texel is read at every k-th texel (k the ratio);
    // 0: at every texel (the paper).
    predicted_stride: u32,
    _pad: f32,
};

// Every screen-space pass binds the camera and the settings first in its own group.
@group(2) @binding(0) var<uniform> camera: Camera;
@group(2) @binding(1) var<uniform> settings: PvsmSettings;

// One pixel's filter, from the kernel-shape pass (step 3), for the tile passes (step 8).
struct Kernel {
    // Shadow-map coordinates of the pixel's point (before the normal offset).
    centre: vec2<f32>,
    // The filter h as a parallelogram (Sec. 4.2): half-axis u (any direction) and half-axis v,
    // vertical (only its height), in shadow-map coordinates.
    u_axis: vec2<f32>,
    v_height: f32,
    // Light depth of the pixel's point.
    depth: f32,
    // KERNEL_* flags.
    flags: u32,
    // The largest normal offset the lookup point may get, world units.
    offset: f32,
    // The texel size the prediction asked for along each axis (shadow-map coordinates): tiles finer
    // than that (a neighbour needed more) are integrated at about this resolution.
    texel: vec2<f32>,
    // The average occluder depth z_o the filter's size came from (the receiver's own depth where no
    // blocker was seen, with prediction = fixed).
    blocker_depth: f32,
    _pad: f32,
};

// The pixel has a filter to evaluate.
const KERNEL_ACTIVE: u32 = 1u;
// No blocker in the conservative map's search region: fully lit, nothing more to do (Sec. 5.2).
const KERNEL_LIT: u32 = 2u;
// Behind the light's plane: sees none of it.
const KERNEL_DARK: u32 = 4u;

// The predicted texels across a filter `pixels` wide on screen (Sec. 5.1): ρ(n) as a cubic in
// log2 n, clamped at one pixel below and at the cubic's peak above (past it the fit turns down,
// outside the study's data). The CPU twin is pvsm::prediction::texels_needed.
fn texels_needed(model: u32, pixels: f32) -> f32 {
    let x = log2(max(pixels, 1.0));
    if (model == 1u) {
        let s = min(x, 7.64);
        return 0.5477 + 1.406 * s - 0.04687 * s * s - 0.003944 * s * s * s;
    }
    let d = min(x, 10.6);
    if (model == 2u) {
        let end = 0.667 + 0.7794 * 10.6 + 0.3967 * 10.6 * 10.6 - 0.02716 * 10.6 * 10.6 * 10.6;
        return 0.667 + (end - 0.667) * d / 10.6;
    }
    return 0.667 + 0.7794 * d + 0.3967 * d * d - 0.02716 * d * d * d;
}

// The appendix: the convolution of parallelogram filters (u0, v0) and (u1, v1), seen as Gaussians
// whose variances add, turned back into the parallelogram (u, v) with v vertical: the columns of the
// Cholesky factor of the summed variance. Returns (u.x, u.y, v.y).
fn convolve(u0: vec2<f32>, v0: vec2<f32>, u1: vec2<f32>, v1: vec2<f32>) -> vec3<f32> {
    let m00 = u0.x * u0.x + v0.x * v0.x + u1.x * u1.x + v1.x * v1.x;
    let m10 = u0.x * u0.y + v0.x * v0.y + u1.x * u1.y + v1.x * v1.y;
    let m11 = u0.y * u0.y + v0.y * v0.y + u1.y * u1.y + v1.y * v1.y;
    let ux = sqrt(max(m00, 1e-30));
    let uy = m10 / ux;
    return vec3<f32>(ux, uy, sqrt(max(m11 - uy * uy, 0.0)));
}

// Where the camera ray through pixel position `pixel` meets the plane through `point` with normal
// `normal`; w = 0 when it runs along the plane or meets it behind the eye.
fn tangent_point(point: vec3<f32>, normal: vec3<f32>, pixel: vec2<f32>) -> vec4<f32> {
    let ndc = vec2<f32>(pixel.x * camera.viewport.z * 2.0 - 1.0, 1.0 - pixel.y * camera.viewport.w * 2.0);
    let far = camera.inverse_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let eye = camera.position.xyz;
    let direction = far.xyz / far.w - eye;
    let denominator = dot(direction, normal);
    if (abs(denominator) < 1e-12) {
        return vec4<f32>(point, 0.0);
    }
    let t = dot(point - eye, normal) / denominator;
    return vec4<f32>(eye + direction * t, select(0.0, 1.0, t > 0.0));
}

// The lookup point of a surface point: moved `offset` world units off the surface, on the side facing the light.
fn offset_point(position: vec3<f32>, normal: vec3<f32>, offset: f32) -> vec3<f32> {
    let towards_light = select(-normal, normal, dot(normal, frame.centre.xyz - position) >= 0.0);
    return position + towards_light * offset;
}
