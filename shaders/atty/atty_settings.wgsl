// The settings every Atty pass reads, declared once in Rust (`AttySettingsUniform`,
// ssm-techniques/atty/src/lib.rs), whose derive writes this struct.
// #import rust/AttySettings

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
