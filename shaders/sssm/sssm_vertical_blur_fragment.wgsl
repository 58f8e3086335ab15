// SSSM step 3 as a fragment pass: every blur tap reads its pixel from the textures.

// #import sssm/sssm_vertical_blur.wgsl

fn vertical_source(texel: vec2<i32>) -> BlurSource {
    return load_vertical_source(texel);
}

@fragment
fn sssm_vertical_blur(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    // (horizontal blur, half-width along x, along y, blocker rows reused or -1).
    let own = textureLoad(horizontal_blur, point.texel, 0);
    if (own.w < 0.0) {
        // Nothing computed here (background, behind the light): -1 keeps it out of the average.
        textureStore(reuse_share, point.texel, vec4<f32>(-1.0));
        return own.x;
    }
    reads = 3u;
    let result = vertical(in.clip.xy, point, own);
    textureStore(reuse_share, point.texel, vec4<f32>(result.y));
    record_reads(2u, point.texel);
    return result.x;
}
