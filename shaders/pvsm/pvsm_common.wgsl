// Shared by the passes of Shen, Guennebaud, Yang and Feng 2011, Predicted
// Virtual Soft Shadow Maps with High Quality Filtering (ssm-techniques/pvsm).

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import common/camera.wgsl

// The settings, declared once in Rust (`PvsmSettingsUniform`, ssm-techniques/pvsm/src/lib.rs),
// whose derive writes this struct.
// #import rust/PvsmSettings

// Every screen-space pass binds the camera and the settings first in its own group.
@group(2) @binding(0) var<uniform> camera: Camera;
@group(2) @binding(1) var<uniform> settings: PvsmSettings;

// One pixel's filter, from the kernel-shape pass (step 3), for the tile passes (step 8).
// One pixel's filter from step 3, declared once in Rust (`KernelRecord`, ssm-techniques/pvsm/src/kernel.rs),
// whose derive writes this struct.
// #import rust/Kernel

// Bytes of one Kernel record, an element of the kernels array (a read of a pixel's record fetches
// them all; src/kernel.rs's KernelRecord, checked by a test of the crate).
const KERNEL_RECORD_BYTES: u32 = 48u;

// Bytes of one G-buffer texel read: the position and the normal are Rgba32Float (ssm-core's
// GBuffer::POSITION_FORMAT and NORMAL_FORMAT, checked by a test of the crate).
const GBUFFER_TEXEL_BYTES: u32 = 16u;

// The pixel has a filter to evaluate.
const KERNEL_ACTIVE: u32 = 1u;
// No blocker in the conservative map's search region: fully lit, nothing more to do (Sec. 5.2).
const KERNEL_LIT: u32 = 2u;
// Behind the light's plane: sees none of it.
const KERNEL_DARK: u32 = 4u;

// The pixel counts step 3 and the filter passes keep (the `counters` buffer), for the diagnostics.
const COUNTERS: u32 = 4u;
// Pixels with a filter to evaluate.
const COUNTER_FILTERED: u32 = 0u;
// Pixels skipped as fully lit (no blocker in the conservative map).
const COUNTER_LIT: u32 = 1u;
// Pixels whose filter's walk stopped at MAX_WALK_STEPS in some tile (pvsm_filter.wgsl).
const COUNTER_CAPPED: u32 = 2u;
// Pixels with a filter that no tile covered (resolved as lit).
const COUNTER_UNCOVERED: u32 = 3u;

// The user study's cubics in x = log2 n (Sec. 5.1), and where each peaks: past its peak a cubic
// turns down, outside the study's data, so x is clamped there. The CPU twins are
// pvsm::prediction::{rho_dynamic, rho_static, DYNAMIC_PEAK, STATIC_PEAK} (a test evaluates both).
const DYNAMIC_PEAK: f32 = 10.6;
const STATIC_PEAK: f32 = 7.64;
fn rho_dynamic(x: f32) -> f32 {
    return 0.667 + 0.7794 * x + 0.3967 * x * x - 0.02716 * x * x * x;
}
fn rho_static(x: f32) -> f32 {
    return 0.5477 + 1.406 * x - 0.04687 * x * x - 0.003944 * x * x * x;
}

// The predicted texels across a filter `pixels` wide on screen (Sec. 5.1): ρ(n), n clamped at one
// pixel below and at the cubic's peak above; model 2 is the straight line in x through
// ρ_dynamic's ends. The CPU twin is pvsm::prediction::texels_needed.
fn texels_needed(model: u32, pixels: f32) -> f32 {
    let x = log2(max(pixels, 1.0));
    if (model == 1u) {
        return rho_static(min(x, STATIC_PEAK));
    }
    let d = min(x, DYNAMIC_PEAK);
    if (model == 2u) {
        let start = rho_dynamic(0.0);
        return start + (rho_dynamic(DYNAMIC_PEAK) - start) * d / DYNAMIC_PEAK;
    }
    return rho_dynamic(d);
}

// Eq. 4: the screen sizes, in pixels, of a filter whose half-extents along the map's axes e0 and
// e1 are `half_extent`: n_i = |M_φ⁻¹ e_i e_iᵀ h|, with M_φ = [u_φ v_φ] mapping the pixel's
// [-1, 1]² onto the map, so that a half-extent over a half-axis is a full size in pixels.
// (1, 1) where the footprint is degenerate (the tangent plane seen edge-on).
fn screen_sizes(half_extent: vec2<f32>, u_phi: vec2<f32>, v_phi: vec2<f32>) -> vec2<f32> {
    let determinant = u_phi.x * v_phi.y - v_phi.x * u_phi.y;
    if (abs(determinant) <= 1e-20) {
        return vec2<f32>(1.0);
    }
    let inverse = mat2x2<f32>(v_phi.y, -u_phi.y, -v_phi.x, u_phi.x) * (1.0 / determinant);
    return vec2<f32>(length(inverse * vec2<f32>(half_extent.x, 0.0)), length(inverse * vec2<f32>(0.0, half_extent.y)));
}

// The fewest texels across a penumbra when the output is point-sampled (antialiasing off): a
// penumbra spanning two texels or more is integrated as a ramp, and a point in it is off by at most
// a quarter of the penumbra where the tile's texel grid moves its edges by half a texel; a
// narrower one is a step, off wherever the edge moved.
const PENUMBRA_TEXELS: f32 = 2.0;

// Eqs. 4 and 5 for the filter h = (u_h.x, u_h.y, v_h.y) of a pixel with footprint (u_φ, v_φ):
// (n0, n1, r0, r1), the screen sizes of h along the map's axes and the texel sizes
// r_i = 2 e_iᵀ h / ρ(n_i), in shadow-map coordinates.
//
// `pixel_uv` (0 with antialiasing on): the output is the visibility at the pixel's point, not its
// average over the footprint, and pixel_uv is the texel a hard shadow gets there: a pixel's size at
// the point's distance, as if the surface faced the camera, over settings.hard_texels, in
// shadow-map coordinates along each axis. Eq. 5 sizes texels for h, which includes φ: where the
// camera sees the receiver at a grazing angle φ is long on the map, and Eq. 5's texel as long,
// right for an average over the footprint; but a point's shadow edges are then placed only to
// within that length, and occluders narrower than it (thin bars) merge or vanish from the tile.
// And ρ(n) < 1 for a penumbra under a pixel wide, so that a point inside it reads a step. So each
// texel is also bounded by the soft filter s_α alone (`soft`, its half-axes) across
// max(ρ(n), PENUMBRA_TEXELS) texels or, where that is finer still (a sharper shadow), by pixel_uv.
fn predicted_texels(model: u32, h: vec3<f32>, soft: vec2<f32>, u_phi: vec2<f32>, v_phi: vec2<f32>, pixel_uv: vec2<f32>) -> vec4<f32> {
    let n = screen_sizes(vec2<f32>(h.x, h.z), u_phi, v_phi);
    var texel = 2.0 * vec2<f32>(h.x, h.z) / vec2<f32>(texels_needed(model, n.x), texels_needed(model, n.y));
    if (all(pixel_uv > vec2<f32>(0.0))) {
        let n_soft = screen_sizes(soft, u_phi, v_phi);
        let soft_texel = 2.0 * soft / max(vec2<f32>(texels_needed(model, n_soft.x), texels_needed(model, n_soft.y)), vec2<f32>(PENUMBRA_TEXELS));
        texel = min(texel, max(soft_texel, pixel_uv));
    }
    return vec4<f32>(n, texel);
}

// The unit direction of the camera ray through pixel position `pixel`.
fn camera_ray(pixel: vec2<f32>) -> vec3<f32> {
    let ndc = vec2<f32>(pixel.x * camera.viewport.z * 2.0 - 1.0, 1.0 - pixel.y * camera.viewport.w * 2.0);
    let far = camera.inverse_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    return normalize(far.xyz / far.w - camera.position.xyz);
}

// One pixel's world size at `point`, seen through pixel position `pixel`, as if the surface there
// faced the camera: the gap between the rays through the pixel's opposite edges at the point's
// distance (the smaller of its width and height).
fn pixel_world_size(point: vec3<f32>, pixel: vec2<f32>) -> f32 {
    let across = length(camera_ray(pixel + vec2<f32>(0.5, 0.0)) - camera_ray(pixel - vec2<f32>(0.5, 0.0)));
    let down = length(camera_ray(pixel + vec2<f32>(0.0, 0.5)) - camera_ray(pixel - vec2<f32>(0.0, 0.5)));
    return length(point - camera.position.xyz) * min(across, down);
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
