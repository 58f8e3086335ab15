// SSSM step 3 (Table 1): the vertical blur over m taps, reusing a tap pixel's horizontal result
// when its camera depth differs from this pixel's tangent plane by less than β (Sec. 4.2: "the
// distance is modified taking into account the normal"), else shadow-testing that row's points
// of this pixel's tangent plane directly (which also covers taps past the screen's edges, unless
// CLAMP_EDGE_ROWS reads those from the edge).
// Also the share of reused rows of both steps (Fig. 10). The entry points (a fragment pass, or a
// compute pass whose workgroups share the screen column the blur reads) are in
// sssm_vertical_blur_fragment.wgsl and sssm_vertical_blur_compute.wgsl; each defines
// `vertical_source(texel)`, where a blur tap's pixel comes from.

// #import sssm/sssm_common.wgsl

@group(2) @binding(4) var horizontal_blur: texture_2d<f32>;
@group(2) @binding(5) var blur_source: texture_2d<f32>;
@group(2) @binding(6) var vertical_tap_source: texture_2d<f32>;

// A blur tap's pixel read from step 2's vertical_tap_source: its horizontal result, and what the
// β test and the bilateral weight compare.
fn load_vertical_source(texel: vec2<i32>) -> BlurSource {
    count_screen_target_read();
    return unpack_vertical_tap_source(textureLoad(vertical_tap_source, texel, 0));
}

// The blur's axes at the computed pixel at `point` whose step 2 result is `own` (the same as step
// 2's: blur_axes of the same blocker depth and light depth); zero where step 2 did not blur (no
// blocker, or a penumbra under half a pixel: the first blur's value stands). Recomputed rather
// than handed on: the value and the reused rows leave two of step 2's four channels, where the
// two axes need four; this costs arithmetic, no texel read.
fn step_2_axes(point: ScreenPoint, own: vec4<f32>) -> BlurAxes {
    if (own.y <= 0.0) {
        return BlurAxes(vec2<f32>(0.0), vec2<f32>(0.0));
    }
    return blur_axes(point, own.y, own.z);
}

// (visibility, share of rows reused in steps 2 and 3) of the computed pixel at `centre` (pixel
// position of its centre), whose step 2 result is `own` and blur axes `axes` (step_2_axes); each
// tap's pixel comes from `vertical_source`. The second blur runs along `axes.second`, each of its
// rows along `axes.first` (the screen's columns and rows, or the light's two sides).
fn vertical(centre: vec2<f32>, point: ScreenPoint, own: vec4<f32>, axes: BlurAxes) -> vec2<f32> {
    let n = f32(max(settings.blocker_kernel, 1u));
    if (under_half_a_pixel(axes)) {
        // No blur: only the blocker rows counted.
        return vec2<f32>(own.x, own.w / n);
    }
    let m = max(settings.blur_kernel, 1u);
    let rays = camera_rays();
    let offset = lookup_offset(point.position, point.normal);
    var blurred = 0.0;
    var total = 0.0;
    var reused = 0.0;
    for (var j = 0u; j < m; j++) {
        let tap_offset = grid_offset(j, m);
        let row = centre + tap_offset * axes.second;
        let weight = blur_weight(tap_offset);
        var reuse = false;
        if (row_read_from_screen(row)) {
            let source = vertical_source(clamped_texel(row));
            let expected = plane_distance(rays, point.position, point.normal, row);
            reuse = within_beta(source, expected);
            if (reuse) {
                let tap_weight = weight * bilateral_weight_of(point.normal, source, expected);
                blurred += tap_weight * source.value;
                total += tap_weight;
                reused += 1.0;
            } else {
                count_failed_row(false, source.eye_distance < 0.0);
            }
        } else {
            count_failed_row(true, false);
        }
        if (!reuse) {
            // β failed, or the row lies past the screen's edges: the row is recomputed from the
            // depth map on this pixel's tangent plane (Sec. 4.2).
            // A row whose every tap misses the plane (past its horizon) samples no receiver: no
            // weight, as a row on another surface.
            let recomputed = recomputed_row(rays, point, offset, row, axes.first, m);
            if (recomputed.y > 1e-6) {
                blurred += weight * recomputed.x / recomputed.y;
                total += weight;
            }
        }
    }
    let visibility = clamp(select(own.x, blurred / total, total > 1e-6), 0.0, 1.0);
    return vec2<f32>(visibility, (own.w + reused) / (n + f32(m)));
}

// A row of step 2's first blur recomputed on this pixel's tangent plane with this pixel's
// kernel: the m taps at pixel position `row` ± `first` (the first blur's half-axis), each the hard
// visibility of the point of the plane seen there, looked up with the pixel's normal offset
// `offset`; a tap whose camera ray misses the plane adds nothing. Returns the weighted sum and the
// weights' total. Up to m texel reads (none for a tap behind the light).
fn recomputed_row(rays: CameraRays, point: ScreenPoint, offset: vec3<f32>, row: vec2<f32>, first: vec2<f32>, m: u32) -> vec2<f32> {
    var row_sum = 0.0;
    var row_total = 0.0;
    for (var i = 0u; i < m; i++) {
        let tap_offset = grid_offset(i, m);
        let plane = tangent_plane_point(rays, point.position, point.normal, row + tap_offset * first);
        if (plane.w > 0.0) {
            let weight = blur_weight(tap_offset);
            row_sum += weight * tap_visibility(plane.xyz, offset);
            row_total += weight;
        }
    }
    return vec2<f32>(row_sum, row_total);
}
