// PCSS (pcss_common.wgsl) as a fragment pass: every tap reads the shadow map.

// #import pcss/pcss_common.wgsl

// One texel read.
fn tap_depth(uv: vec2<f32>) -> f32 {
    reads += 1u;
    read_bytes += SHADOW_MAP_TEXEL_BYTES;
    return shadow_map_depth(shadow_map, uv);
}

@fragment
fn pcss_filter(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    // The G-buffer's two texels, read at every pixel, trivial ones included.
    reads = 2u;
    read_bytes = 2u * GBUFFER_TEXEL_BYTES;
    var visibility = trivial_visibility(point);
    if (visibility < 0.0) {
        visibility = soft_visibility(pcss_pixel(point));
    }
    record_pcss_reads(point.texel);
    return visibility;
}
