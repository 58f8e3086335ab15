// SSSM step 1 (Table 1): per pixel, the hard shadow, its light depth d, and the horizontal
// partial blocker sum and count over the n×1 row of the depth map through its shadow-map
// position (Sec. 4.1): partial_blocker_sum(p) = Σ_x dm(x, 0) for dm < d (d, or the receiver's
// tangent plane along each tap's ray with `receiver_plane`, as in pcss).

// Also each pixel's packed_blur_source, for the blurs' taps.

// #import sssm/sssm_common.wgsl

struct HorizontalBlockerOutput {
    // (d, partial sum, partial count, hard visibility); d = -1 where there is nothing to compute.
    @location(0) blocker: vec4<f32>,
    // packed_blur_source.
    @location(1) blur_source: vec4<f32>,
};

@fragment
fn sssm_horizontal_blocker(in: FullscreenVertex) -> HorizontalBlockerOutput {
    let point = screen_point(in);
    // The G-buffer's two texels, read at every pixel.
    count_own_texels(false);
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        record_reads(0u, point.texel);
        return HorizontalBlockerOutput(vec4<f32>(-1.0, 0.0, 0.0, trivial), packed_blur_source(trivial, point));
    }
    let result = partial_blocker(point);
    record_reads(0u, point.texel);
    return HorizontalBlockerOutput(result, packed_blur_source(result.w, point));
}

fn partial_blocker(point: ScreenPoint) -> vec4<f32> {
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    let receiver = compared_plane(lookup, point.normal, uvd.z);
    let hard = select(0.0, 1.0, uvd.z <= tap_depth(uvd.xy));
    count_shadow_map_read();
    // The search window: the light back-projected through the near plane (every blocker lies beyond it), as in PCSS.
    let search = light_half_extent_uv(frame, frame.projection.z, uvd.z);
    let partial = blocker_row(uvd.xy, search.x, receiver, max(settings.blocker_kernel, 1u));
    return vec4<f32>(uvd.z, partial, hard);
}
