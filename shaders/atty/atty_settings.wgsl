// The settings both Atty passes read (ssm-techniques/atty's AttySettingsUniform).

struct AttySettings {
    // Side of the occluder map (N) and of the soft shadow map (and receiver map), texels.
    occluder_map_size: f32,
    soft_shadow_map_size: f32,
    // Normal offset of the projection's lookup point, in receiver-map texels.
    normal_offset: f32,
    // Depth tolerance, in receiver-map texel footprints, within which a receiver-map depth counts
    // as the looked-up receiver (the hidden-receiver test and the SSM's depth-aware bilinear lookup).
    receiver_tolerance: f32,
    // A micro-patch less than this many of its own widths in front of a receiver counts as the
    // receiver's own surface and hides nothing (objects with the role `both` are in both maps).
    self_shadow_tolerance: f32,
    // Constant depth tolerance of the hidden-receiver test, a fraction of the scene's diagonal (as the baselines' constant bias).
    receiver_bias: f32,
    // 1: each micro-patch's penumbra rectangle is bounded by the deepest receiver under it (the
    // receiver_bounds pyramid); 0: by the frame's far plane.
    receiver_bounded: f32,
    // Neighbouring occluder texels whose depths differ by at most this many micro-patch widths
    // are drawn as one micro-patch (0: never).
    merge_tolerance: f32,
    // 1: a micro-patch on or behind a receiver's tangent plane hides nothing from it (the
    // accumulation reads the receiver planes); 0: the receiver's depth alone decides.
    receiver_plane: f32,
    // How far in front of a receiver's tangent plane, in widths of one texel's micro-patch, a patch
    // still counts as lying on it.
    receiver_plane_tolerance: f32,
    _pad0: f32,
    _pad1: f32,
};


// One micro-patch of the accumulation's list (ssm-techniques/atty's 32-byte record).
struct MicroPatchRecord {
    // Centre and half extent of its penumbra rectangle on the soft shadow map, in [-1, 1] coordinates.
    ndc_centre: vec2<f32>,
    half_ndc: vec2<f32>,
    // Its depth z_O, and the distance behind it within which a receiver is its own surface.
    depth: f32,
    self_shadow_depth: f32,
    // Occluder texels per side (1, or 2^level for a merged block).
    span: f32,
    // How far the occluder's depth runs on either side of the patch's across the patch (its slope).
    depth_spread: f32,
};
