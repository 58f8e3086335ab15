// Atty et al. 2006, Soft Shadow Maps: the soft shadow map (SSM) accumulation,
// entirely on the GPU (the paper's own next step, Sec. 4.3 and 7: no readback
// of the occluder map). One instanced quad per occluder-map texel: the vertex
// stage reads the texel, turns it into a micro-patch and emits the patch's
// penumbra rectangle on the SSM; the fragment stage reads the receiver depth
// and adds the fraction of the light the patch hides there. Additive blending
// sums the patches.

// #import common/light_frame.wgsl
// #import common/shadow_map.wgsl
// #import atty/atty_settings.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var occluder_map: texture_2d<f32>;
@group(1) @binding(1) var receiver_map: texture_2d<f32>;
@group(1) @binding(2) var<uniform> settings: AttySettings;

struct MicroPatch {
    @builtin(position) clip: vec4<f32>,
    // Centre (x along the light's u axis, y along v) and half extents of the micro-patch, in light view space at its depth.
    @location(0) @interpolate(flat) centre: vec2<f32>,
    @location(1) @interpolate(flat) half_size: vec2<f32>,
    // The micro-patch's depth z_O.
    @location(2) @interpolate(flat) depth: f32,
};

const CORNERS: array<vec2<f32>, 4> = array<vec2<f32>, 4>(vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, 1.0));

@vertex
fn atty_patch_vertex(@builtin(vertex_index) corner: u32, @builtin(instance_index) instance: u32) -> MicroPatch {
    let n = u32(settings.occluder_map_size);
    let texel = vec2<u32>(instance % n, instance / n);
    let depth = textureLoad(occluder_map, vec2<i32>(texel), 0).x;
    var out: MicroPatch;
    // An empty texel becomes a zero-area quad outside the target: no fragment runs for it.
    out.clip = vec4<f32>(-4.0, -4.0, 0.0, 1.0);
    out.centre = vec2<f32>(0.0);
    out.half_size = vec2<f32>(0.0);
    out.depth = 0.0;
    if (depth >= NO_SURFACE || depth <= 0.0) {
        return out;
    }
    let tan_half = frame.projection.xy;
    // Sec. 3.2: the texel as a micro-patch parallel to the light, at its depth, covering the texel's image area.
    let texel_ndc = (vec2<f32>(texel) + 0.5) / settings.occluder_map_size * 2.0 - 1.0;
    let centre = texel_ndc * depth * tan_half;
    let half_size = depth * tan_half / settings.occluder_map_size;
    let light_half = vec2<f32>(frame.u_axis.w, frame.v_axis.w);
    // Sec. 3.3: the penumbra extent is the pyramid of apex O, C_L O = r/(1+r) C_L C_P with
    // r = LL'/PP' = l/p per axis, at depth z_apex = r/(1+r) z_O. On the plane at depth z_R it is
    // the rectangle of centre C_L C_R = (z_R/z_apex) C_L O = (z_R/z_O) C_P and half-width
    // l (z_R - z_apex)/z_apex = (l + p) z_R/z_O - l: the same formulas written without dividing
    // by r, so that a point light (r = 0, apex at the light) needs no special case.
    // Projected into the SSM from the light's centre (divide by z_R tan), the centre is the
    // texel's own and the half extent is (l + p)/(z_O tan) - l/(z_R tan), growing with z_R:
    // evaluated at the far plane, the rectangle covers every receiver (conservative).
    let far = frame.projection.w;
    let half_ndc = (light_half + half_size) / (depth * tan_half) - light_half / (far * tan_half);
    // Near the light the extent grows without bound (Eq. 3): clamp to just past the map.
    let ndc = clamp(texel_ndc + CORNERS[corner] * half_ndc, vec2<f32>(-2.0), vec2<f32>(2.0));
    // Texture rows run along the light's v axis, clip-space y against it.
    out.clip = vec4<f32>(ndc.x, -ndc.y, 0.0, 1.0);
    out.centre = centre;
    out.half_size = half_size;
    out.depth = depth;
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
    let tolerance = settings.self_shadow_tolerance * 2.0 * max(in.half_size.x, in.half_size.y);
    if (receiver_depth >= NO_SURFACE || receiver_depth <= in.depth + tolerance) {
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
