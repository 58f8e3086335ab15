// SSSM step 2 as a compute pass with a shared row: each workgroup is a run of SEGMENT_PIXELS pixels
// of one screen row. After their blocker searches, the group loads once into workgroup memory the
// row segment their horizontal blurs reach (its pixels, widened by the widest blur half-width of
// the group, up to SEGMENT_CAPACITY texels), and every blur tap inside it reads from there instead
// of from the texture; taps beyond it read the texture as the fragment pass does, so the
// result is the fragment pass's.

// #import sssm/sssm_blocker_blur.wgsl
// #import sssm/sssm_segment.wgsl

@group(2) @binding(6) var horizontal_blur_target: texture_storage_2d<rgba32float, write>;
@group(2) @binding(7) var penumbra_error: texture_storage_2d<r32float, write>;
@group(2) @binding(8) var vertical_tap_source: texture_storage_2d<rgba32float, write>;

fn horizontal_source(texel: vec2<i32>) -> BlurSource {
    // A tap off the group's row (the blur along the light's sides leaves it) reads the texture.
    let index = select(-1, segment_index(texel.x), texel.y == segment_line);
    if (index < 0) {
        return load_horizontal_source(texel);
    }
    return segment_source(index);
}

@compute @workgroup_size(SEGMENT_PIXELS, 1, 1)
fn sssm_blocker_blur_rows(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let texel = vec2<i32>(id.xy);
    let row_on_screen = f32(texel.y) < camera.viewport.y;
    let inside = row_on_screen && f32(texel.x) < camera.viewport.x;
    var result = vec4<f32>(1.0, 0.0, 0.0, -1.0);
    var point: ScreenPoint;
    var own = vec4<f32>(0.0);
    var computed = false;
    var blur = false;
    var axes = BlurAxes(vec2<f32>(0.0), vec2<f32>(0.0));
    segment_line = texel.y;
    reads = 0u;
    read_bytes = 0u;
    if (inside) {
        point = screen_point_at(texel);
        own = textureLoad(horizontal_blocker, texel, 0);
        // The G-buffer's two texels and step 1's, read at every pixel of the screen.
        count_own_texels(true);
        if (own.x < 0.0) {
            result = vec4<f32>(own.w, 0.0, 0.0, -1.0);
        } else {
            computed = true;
            let searched = blocker_search(point, own);
            result = searched.result;
            blur = searched.blur;
            axes = searched.axes;
            if (blur) {
                reach_for(abs(axes.first.x));
            }
        }
        store_penumbra_error(texel);
    }
    workgroupBarrier();
    place_segment(i32(group.x * SEGMENT_PIXELS));
    if (row_on_screen) {
        for (var index = i32(local); index < segment_length; index += i32(SEGMENT_PIXELS)) {
            let column = segment_start + index;
            if (column >= 0 && f32(column) < camera.viewport.x) {
                store_segment(index, load_horizontal_source(vec2<i32>(column, texel.y)));
            }
        }
    }
    workgroupBarrier();
    if (blur) {
        result = horizontal_blur(vec2<f32>(texel) + 0.5, point, own, result, axes);
    }
    if (inside) {
        textureStore(horizontal_blur_target, texel, result);
        textureStore(vertical_tap_source, texel, packed_vertical_tap_source(result.x, point));
    }
    record_reads_of(1u, texel, u32(inside));
    if (computed) {
        record_failed_rows(1u, texel);
    }
}
