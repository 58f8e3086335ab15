// Atty et al. 2006, Soft Shadow Maps: the soft shadow map (SSM) accumulation,
// entirely on the GPU (the paper's own next step, Sec. 4.3 and 7: no readback
// of the occluder map). One instanced quad per micro-patch of the list that
// atty_patches.wgsl builds: the vertex stage emits the patch's penumbra
// rectangle on the SSM; the fragment stage reads the receiver depth and adds
// the fraction of the light the patch hides there. Additive blending sums the
// patches.

// #import common/light_frame.wgsl
// #import common/shadow_map.wgsl
// #import atty/atty_settings.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
// The micro-patches that can hide anything (atty_patches.wgsl), one instance each.
@group(1) @binding(0) var<storage, read> patches: array<MicroPatchRecord>;
@group(1) @binding(1) var receiver_map: texture_2d<f32>;
@group(1) @binding(2) var<uniform> settings: AttySettings;

struct MicroPatch {
    @builtin(position) clip: vec4<f32>,
    // Centre (x along the light's u axis, y along v) and half extents of the micro-patch, in light view space at its depth.
    @location(0) @interpolate(flat) centre: vec2<f32>,
    @location(1) @interpolate(flat) half_size: vec2<f32>,
    // The micro-patch's depth z_O.
    @location(2) @interpolate(flat) depth: f32,
    // A receiver less than this far behind the patch is its own surface (self_shadow_tolerance
    // widths of one texel's micro-patch, also for a merged patch).
    @location(3) @interpolate(flat) self_shadow_depth: f32,
};

const CORNERS: array<vec2<f32>, 4> = array<vec2<f32>, 4>(vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, 1.0));

@vertex
fn atty_patch_vertex(@builtin(vertex_index) corner: u32, @builtin(instance_index) instance: u32) -> MicroPatch {
    let record = patches[instance];
    let tan_half = frame.projection.xy;
    // Near the light the extent grows without bound (Eq. 3): clamp to just past the map.
    let ndc = clamp(record.ndc_centre + CORNERS[corner] * record.half_ndc, vec2<f32>(-2.0), vec2<f32>(2.0));
    var out: MicroPatch;
    // Texture rows run along the light's v axis, clip-space y against it.
    out.clip = vec4<f32>(ndc.x, -ndc.y, 0.0, 1.0);
    out.centre = record.ndc_centre * record.depth * tan_half;
    out.half_size = record.depth * tan_half * record.span / settings.occluder_map_size;
    out.depth = record.depth;
    out.self_shadow_depth = record.self_shadow_depth;
    return out;
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

@fragment
fn atty_patch_fragment(in: MicroPatch) -> @location(0) f32 {
    let texel = vec2<i32>(in.clip.xy);
    let receiver_depth = textureLoad(receiver_map, texel, 0).x;
    // No receiver here, or the receiver is not behind this patch (beyond the tolerance that keeps a
    // surface in both maps from shadowing itself): nothing hidden.
    if (receiver_depth >= NO_SURFACE || receiver_depth <= in.depth + in.self_shadow_depth) {
        return 0.0;
    }
    let uv = in.clip.xy / settings.soft_shadow_map_size;
    let receiver = (uv * 2.0 - 1.0) * receiver_depth * frame.projection.xy;
    // Sec. 3.4: project the micro-patch from the receiver point back onto the light's plane
    // (Drettakis and Fiume 1994): a scaling about the receiver by z_R / (z_R - z_O).
    let scale = receiver_depth / (receiver_depth - in.depth);
    let low = receiver + (in.centre - in.half_size - receiver) * scale;
    let high = receiver + (in.centre + in.half_size - receiver) * scale;
    let light_half = vec2<f32>(frame.u_axis.w, frame.v_axis.w);
    // Sec. 4.2: the hidden area is the product of the two 1-D overlaps.
    return light_overlap(low.x, high.x, light_half.x) * light_overlap(low.y, high.y, light_half.y);
}
