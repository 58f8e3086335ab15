// SSSM step 3 as a fragment pass: every blur tap reads its pixel from the textures.

// #import sssm/sssm_vertical_blur.wgsl

fn vertical_source(texel: vec2<i32>) -> BlurSource {
    return load_vertical_source(texel);
}

struct VerticalBlurOutput {
    // The soft visibility.
    @location(0) visibility: f32,
    // The share of rows reused (Fig. 10); -1 where nothing was computed (background, behind the
    // light), which keeps the pixel out of the average.
    @location(1) reuse_share: f32,
};

@fragment
fn sssm_vertical_blur(in: FullscreenVertex) -> VerticalBlurOutput {
    let point = screen_point(in);
    // (first blur, blockers' light depth or 0, the pixel's light depth, blocker rows reused or -1).
    let own = textureLoad(horizontal_blur, point.texel, 0);
    // The G-buffer's two texels and step 2's, read at every pixel.
    count_own_texels(true);
    if (own.w < 0.0) {
        record_reads(2u, point.texel);
        return VerticalBlurOutput(own.x, -1.0);
    }
    let result = vertical(in.clip.xy, point, own, step_2_axes(point, own));
    record_reads(2u, point.texel);
    record_failed_rows(2u, point.texel);
    return VerticalBlurOutput(result.x, result.y);
}
