// Atty et al. 2006, Soft Shadow Maps: the soft shadow map (SSM) accumulation,
// entirely on the GPU (the paper's own next step, Sec. 4.3 and 7: no readback
// of the occluder map). One instanced quad per micro-patch of the list that
// atty_micro_patches.wgsl builds: the vertex stage emits the patch's penumbra
// rectangle on the SSM; the fragment stage reads the receiver depth and adds
// the fraction of the light the patch hides there. Additive blending sums the
// patches.

// #import common/light_frame.wgsl
// #import common/shadow_map.wgsl
// #import atty/atty_settings.wgsl
// #import atty/atty_geometry.wgsl
// #import atty/atty_counts.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
// The micro-patches that can hide anything (atty_micro_patches.wgsl), one instance each.
@group(1) @binding(0) var<storage, read> patches: array<MicroPatchRecord>;
// Per SSM texel, x: the receiver's depth (NO_SURFACE where none). With `receiver_plane`, the
// receiver planes (atty_receiver_map.wgsl), whose y, z hold the plane's slope; without, the
// receiver map itself.
@group(1) @binding(1) var receivers: texture_2d<f32>;
@group(1) @binding(2) var<uniform> settings: AttySettings;
// This side's accumulation counters (atty_counts.wgsl): 0, texel reads (one receiver texel per
// fragment); 1, the bytes they fetched.
@group(1) @binding(3) var<storage, read_write> read_counts: array<atomic<u32>>;

// Bytes of one texel of `receivers` (the pipeline sets it from the receiver map's format: R32Float,
// or Rgba32Float planes with receiver_plane).
override RECEIVER_TEXEL_BYTES: u32;

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
    // The patch's centre in ndc (the receiver-plane test's ray).
    @location(4) @interpolate(flat) ndc_centre: vec2<f32>,
    // How far in front of a receiver's tangent plane the patch may lie and still count as on it:
    // the occluder's depth spread across the patch, plus receiver_plane_tolerance widths of one
    // texel's micro-patch.
    @location(5) @interpolate(flat) plane_slack: f32,
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
    out.ndc_centre = record.ndc_centre;
    out.plane_slack = record.depth_spread + settings.receiver_plane_tolerance * 2.0 * record.depth * max(tan_half.x, tan_half.y) / settings.occluder_map_size;
    return out;
}

@fragment
fn atty_patch_fragment(in: MicroPatch) -> @location(0) f32 {
    let texel = vec2<i32>(in.clip.xy);
    let receiver = textureLoad(receivers, texel, 0);
    record_count(0u, texel, 1u);
    record_count(1u, texel, RECEIVER_TEXEL_BYTES);
    let receiver_depth = receiver.x;
    // No receiver here, or the receiver is not behind this patch (beyond the tolerance that keeps a
    // surface in both maps from shadowing itself): nothing hidden.
    if (receiver_depth >= NO_SURFACE || receiver_depth <= in.depth + in.self_shadow_depth) {
        return 0.0;
    }
    let receiver_ndc = in.clip.xy / settings.soft_shadow_map_size * 2.0 - 1.0;
    // A patch on the receiver's tangent plane or behind it hides nothing the receiver sees: a flat
    // surface in both maps cannot shadow itself through its own micro-patches.
    if (settings.receiver_plane != 0.0
        && patch_on_or_behind_receiver_plane(receiver_ndc, receiver_depth, receiver.yz, in.ndc_centre, in.depth, in.plane_slack)) {
        return 0.0;
    }
    let light_half = vec2<f32>(frame.u_axis.w, frame.v_axis.w);
    // Sec. 3.4 and 4.2: the patch projected back onto the light from the receiver, and the hidden area.
    return hidden_fraction(light_half, in.centre, in.half_size, in.depth, receiver_ndc * receiver_depth * frame.projection.xy, receiver_depth);
}
