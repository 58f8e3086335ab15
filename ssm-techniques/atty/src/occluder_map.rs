//! Step 2, the occluder maps (Atty et al. 2006, Sec. 3.2, 3.5): the occluders seen from the
//! light's centre, each texel of which becomes a micro-patch. One-sided, one map of the nearest
//! surface of every face; two-sided (Sec. 3.5), one of the nearest front faces and one of the
//! farthest back faces. Each is ssm-core's light depth map without bias
//! ([`crate::gpu::unbiased_depth_map`], `shaders/core/light_depth.wgsl`: Atty has no shader of its
//! own for it); this module names each side's maps and passes.

/// One occluder side's maps and passes, by name (every pass label a counter can carry is static).
pub(crate) struct Side {
    /// The occluder map.
    pub(crate) occluder_map: &'static str,
    /// The occluder map's min-max pyramid pass.
    pub(crate) patch_merge: &'static str,
    /// The micro-patch list pass.
    pub(crate) patches: &'static str,
    /// The accumulation pass, and the soft shadow map's label stem.
    pub(crate) accumulate: &'static str,
    /// The faces culled from the occluder map, and whether it keeps the farthest surface.
    pub(crate) cull: Option<wgpu::Face>,
    pub(crate) farthest: bool,
}

/// One-sided: the nearest surface of every occluder face.
pub(crate) const ONE_SIDED: &[Side] = &[Side {
    occluder_map: "atty_occluder_map",
    patch_merge: "atty_patch_merge",
    patches: "atty_accumulate_patches",
    accumulate: "atty_accumulate",
    cull: None,
    farthest: false,
}];

/// Two-sided (Sec. 3.5): the nearest front faces and the farthest back faces.
pub(crate) const TWO_SIDED: &[Side] = &[
    Side {
        occluder_map: "atty_occluder_map_front",
        patch_merge: "atty_patch_merge",
        patches: "atty_accumulate_front_patches",
        accumulate: "atty_accumulate_front",
        cull: Some(wgpu::Face::Back),
        farthest: false,
    },
    Side {
        occluder_map: "atty_occluder_map_back",
        patch_merge: "atty_patch_merge_back",
        patches: "atty_accumulate_back_patches",
        accumulate: "atty_accumulate_back",
        cull: Some(wgpu::Face::Front),
        farthest: true,
    },
];
