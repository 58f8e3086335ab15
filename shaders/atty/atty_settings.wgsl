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
    _pad0: f32,
    _pad1: f32,
};
