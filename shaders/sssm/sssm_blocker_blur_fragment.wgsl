// SSSM step 2 as a fragment pass: every blur tap reads its pixel from the textures.

// #import sssm/sssm_blocker_blur.wgsl

@group(2) @binding(6) var penumbra_error: texture_storage_2d<r32float, write>;

fn horizontal_source(texel: vec2<i32>) -> BlurSource {
    return load_horizontal_source(texel);
}

struct BlockerBlurOutput {
    // (first blur's visibility, the blockers' average light depth or 0 where there is no blur,
    // the pixel's light depth, blocker rows reused); w = -1 where nothing was computed
    // (background, behind the light).
    @location(0) horizontal_blur: vec4<f32>,
    // packed_vertical_tap_source.
    @location(1) vertical_tap_source: vec4<f32>,
};

@fragment
fn sssm_blocker_blur(in: FullscreenVertex) -> BlockerBlurOutput {
    let point = screen_point(in);
    let own = textureLoad(horizontal_blocker, point.texel, 0);
    // The G-buffer's two texels and step 1's, read at every pixel.
    count_own_texels(true);
    if (own.x < 0.0) {
        store_penumbra_error(point.texel);
        record_reads(1u, point.texel);
        return BlockerBlurOutput(vec4<f32>(own.w, 0.0, 0.0, -1.0), packed_vertical_tap_source(own.w, point));
    }
    let searched = blocker_search(point, own);
    store_penumbra_error(point.texel);
    var result = searched.result;
    if (searched.blur) {
        result = horizontal_blur(in.clip.xy, point, own, result, searched.axes);
    }
    record_reads(1u, point.texel);
    record_failed_rows(1u, point.texel);
    return BlockerBlurOutput(result, packed_vertical_tap_source(result.x, point));
}
