// SSSM step 3 as a compute pass with a shared column: each workgroup is a run of SEGMENT_PIXELS
// pixels of one screen column, which loads once into workgroup memory the column segment their
// vertical blurs reach (widened by the group's widest blur half-height, up to SEGMENT_CAPACITY
// texels); every tap inside it reads from there instead of from the texture, taps beyond it
// read the texture as the fragment pass does, so the result is the fragment pass's.

// #import sssm/sssm_vertical_blur.wgsl
// #import sssm/sssm_segment.wgsl

// (The fragment pass renders these two.)
@group(2) @binding(7) var reuse_share: texture_storage_2d<r32float, write>;
@group(2) @binding(8) var visibility_target: texture_storage_2d<r32float, write>;

fn vertical_source(texel: vec2<i32>) -> BlurSource {
    // A tap off the group's column (the blur along the light's sides leaves it) reads the texture.
    let index = select(-1, segment_index(texel.y), texel.x == segment_line);
    if (index < 0) {
        return load_vertical_source(texel);
    }
    return segment_source(index);
}

// The group's invocations run down the column: x of the workgroup grid counts runs of
// SEGMENT_PIXELS rows, y counts columns, and invocation i is row i of the run. (A workgroup shaped
// 1×64 would leave all but one lane of each SIMD vector idle on CPU rasterisers such as lavapipe,
// which vectorise along x.)
@compute @workgroup_size(SEGMENT_PIXELS, 1, 1)
fn sssm_vertical_blur_columns(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let texel = vec2<i32>(i32(group.y), i32(group.x * SEGMENT_PIXELS + local));
    let column_on_screen = f32(texel.x) < camera.viewport.x;
    let inside = column_on_screen && f32(texel.y) < camera.viewport.y;
    var point: ScreenPoint;
    var own = vec4<f32>(1.0, 0.0, 0.0, -1.0);
    var computed = false;
    var axes = BlurAxes(vec2<f32>(0.0), vec2<f32>(0.0));
    segment_line = texel.x;
    reads = 0u;
    read_bytes = 0u;
    if (inside) {
        point = screen_point_at(texel);
        // (first blur, blockers' light depth or 0, the pixel's light depth, blocker rows reused or -1).
        own = textureLoad(horizontal_blur, texel, 0);
        // The G-buffer's two texels and step 2's, read at every pixel of the screen.
        count_own_texels(true);
        if (own.w >= 0.0) {
            computed = true;
            axes = step_2_axes(point, own);
            if (!under_half_a_pixel(axes)) {
                reach_for(abs(axes.second.y));
            }
        }
    }
    workgroupBarrier();
    place_segment(i32(group.x * SEGMENT_PIXELS));
    if (column_on_screen) {
        for (var index = i32(local); index < segment_length; index += i32(SEGMENT_PIXELS)) {
            let row = segment_start + index;
            if (row >= 0 && f32(row) < camera.viewport.y) {
                store_segment(index, load_vertical_source(vec2<i32>(texel.x, row)));
            }
        }
    }
    workgroupBarrier();
    if (!inside) {
        // Past the screen's bottom edge: no pixel, but its share of the segment's loads.
        record_reads_of(2u, texel, 0u);
        return;
    }
    if (!computed) {
        // Nothing computed here (background, behind the light): -1 keeps it out of the average.
        textureStore(reuse_share, texel, vec4<f32>(-1.0));
        textureStore(visibility_target, texel, vec4<f32>(own.x));
        record_reads(2u, texel);
        return;
    }
    let result = vertical(vec2<f32>(texel) + 0.5, point, own, axes);
    textureStore(reuse_share, texel, vec4<f32>(result.y));
    textureStore(visibility_target, texel, vec4<f32>(result.x));
    record_reads(2u, texel);
    record_failed_rows(2u, texel);
}
