// SSSM step 2 (Table 1): the blocker average over the n×n window, each of its n rows reused
// from the pixel whose shadow-map position lies on that row when |d - d_t| < α (Sec. 4.1),
// else read from the depth map; the penumbra size by Eq. 1; then the horizontal screen-space
// blur of the hard shadow over m taps (Sec. 4.2). The entry points (a fragment pass, or a
// compute pass whose workgroups share the screen row the blur reads) are in
// sssm_blocker_blur_fragment.wgsl and sssm_blocker_blur_compute.wgsl; each defines
// `horizontal_source(texel)`, where a blur tap's pixel comes from, and binds `penumbra_error`, the
// target of the Table 5 measurement (with MEASURE_PENUMBRA_ERROR: per pixel, (the penumbra width
// from the reused rows − the width from every row read)², shadow-map texels²; -1 where step 2
// computed no penumbra either way). Each also hands on packed_vertical_tap_source per pixel,
// what step 3's taps read.

// #import sssm/sssm_common.wgsl

// Whether step 2 also searches every blocker row (no reuse) and writes the squared difference of
// the two penumbra widths to penumbra_error (the settings' penumbra_error, Table 5; costs a full
// search): a constant of the pipeline, so that without it the measurement is compiled out.
override MEASURE_PENUMBRA_ERROR: bool = false;

@group(2) @binding(4) var horizontal_blocker: texture_2d<f32>;
@group(2) @binding(5) var blur_source: texture_2d<f32>;
// This invocation's value for penumbra_error (blocker_search sets it).
var<private> penumbra_error_value: f32 = -1.0;

// Writes the pixel's penumbra error, when measured.
fn store_penumbra_error(texel: vec2<i32>) {
    if (MEASURE_PENUMBRA_ERROR) {
        textureStore(penumbra_error, texel, vec4<f32>(penumbra_error_value));
    }
}

// The blocker sum and count over every row of the n×n window, none reused: PCSS's search, and
// what SSSM's rows add up to with α = 0.
fn full_blocker_search(uvd: vec3<f32>, search: vec2<f32>, receiver: TapPlane, n: u32) -> vec2<f32> {
    let steps = kernel_steps(n);
    var sum = 0.0;
    var count = 0.0;
    for (var j = 0u; j < n; j++) {
        for (var i = 0u; i < n; i++) {
            let tap = uvd.xy + vec2<f32>(kernel_offset(steps, i), kernel_offset(steps, j)) * search;
            let depth = tap_depth(tap);
            if (depth < tap_plane_depth(receiver, tap)) {
                sum += depth;
                count += 1.0;
            }
        }
    }
    return vec2<f32>(sum, count);
}

// Full width in shadow-map texels (along u) of the penumbra of a blocker sum and count seen from
// light depth d: Eq. 1's w_penumbra; 0 without a blocker.
fn penumbra_texels(sum_count: vec2<f32>, d: f32) -> f32 {
    if (sum_count.y == 0.0) {
        return 0.0;
    }
    let extent = light_half_extent_uv(frame, sum_count.x / sum_count.y, d);
    return 2.0 * extent.x * f32(textureDimensions(shadow_map).x);
}

// A blur tap's pixel read from step 1's blur_source: its hard visibility, and what the bilateral
// weight compares.
fn load_horizontal_source(texel: vec2<i32>) -> BlurSource {
    let packed = textureLoad(blur_source, texel, 0);
    reads += 1u;
    return unpack_blur_source(packed_hard_value(packed), packed);
}

// The blocker search of a computed pixel, its penumbra and its blur widths: (the hard or lit
// value, blur half-width along x and along y in pixels, blocker rows reused), and whether the
// horizontal blur remains to be done (else the vector is the pass's output).
struct BlockerSearch {
    result: vec4<f32>,
    blur: bool,
};

fn blocker_search(point: ScreenPoint, own: vec4<f32>) -> BlockerSearch {
    let d = own.x;
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    let receiver = compared_plane(lookup, point.normal, d);
    let search = light_half_extent_uv(frame, frame.projection.z, d);
    let n = runtime_count(max(settings.blocker_kernel, 1u), point.texel);
    let steps = kernel_steps(n);
    var sum = 0.0;
    var count = 0.0;
    var reused = 0.0;
    // The rows' points at depth d lie on a line, and clip space is linear in them: project the two ends once.
    let first_clip = camera.view_proj * vec4<f32>(light_point(vec2<f32>(uvd.x, uvd.y - search.y), d), 1.0);
    let last_clip = camera.view_proj * vec4<f32>(light_point(vec2<f32>(uvd.x, uvd.y + search.y), d), 1.0);
    // Rows failing the α test, read after the reused ones.
    var failed_rows = FailedRows();
    for (var t = 0u; t < n; t++) {
        // The pixel that sees the point of this row at the same light depth d (Fig. 4).
        let clip = mix(first_clip, last_clip, kernel_offset(steps, t) * 0.5 + 0.5);
        let ndc = clip.xy * (1.0 / clip.w);
        let screen = vec3<f32>((ndc.x * 0.5 + 0.5) * camera.viewport.x, (0.5 - ndc.y * 0.5) * camera.viewport.y, clip.w);
        var reuse = false;
        var no_data = false;
        let visible = screen.z > 0.0 && row_read_from_screen(screen.xy);
        if (visible) {
            let other = textureLoad(horizontal_blocker, clamped_texel(screen.xy), 0);
            reads += 1u;
            no_data = other.x < 0.0;
            if (other.x >= 0.0 && abs(d - other.x) < scene_length(frame, settings.alpha)) {
                sum += other.y;
                count += other.z;
                reused += 1.0;
                reuse = true;
            }
        }
        if (!reuse) {
            mark_failed_row(&failed_rows, t);
            count_failed_row(!visible, no_data);
        }
    }
    loop {
        let failed = pop_failed_row(&failed_rows);
        if (failed < 0) {
            break;
        }
        let row_uv = vec2<f32>(uvd.x, uvd.y + kernel_offset(steps, u32(failed)) * search.y);
        for (var i = 0u; i < n; i++) {
            let tap = row_uv + vec2<f32>(kernel_offset(steps, i) * search.x, 0.0);
            let depth = tap_depth(tap);
            reads += 1u;
            if (depth < tap_plane_depth(receiver, tap)) {
                sum += depth;
                count += 1.0;
            }
        }
    }
    if (MEASURE_PENUMBRA_ERROR) {
        // Table 5: the error the reuse (α) brings into the penumbra estimate.
        let full = full_blocker_search(uvd, search, receiver, n);
        if (full.y > 0.0 || count > 0.0) {
            let difference = penumbra_texels(vec2<f32>(sum, count), d) - penumbra_texels(full, d);
            penumbra_error_value = difference * difference;
        }
    }
    // No blocker: fully lit (Sec. 4.2).
    if (count == 0.0) {
        return BlockerSearch(vec4<f32>(1.0, 0.0, 0.0, reused), false);
    }
    let blocker = sum / count;
    // Eq. 1: w_penumbra = w_light (z_receiver - z_avg) / z_avg, as the shadow-map half-extent of
    // PCSS's filter (the same kernel pcss filters over), then laid on the receiver's tangent plane
    // and measured along each screen axis.
    let extent = light_half_extent_uv(frame, blocker, d);
    var radii = kernel_screen_radii(point.position, point.normal, light_uv_depth(frame, point.position).xy, extent);
    if (radii.x < 0.0) {
        // The plane runs along the light's rays: the width on a surface facing the camera.
        // The mean of the rectangle's half-sides: a single width.
        let light_half_size = 0.5 * (frame.u_axis.w + frame.v_axis.w);
        radii = vec2<f32>(facing_radius(point.position, light_half_size * max(d - blocker, 0.0) / max(blocker, 1e-6)));
    }
    // A penumbra under half a pixel keeps the hard value.
    if (max(radii.x, radii.y) < 0.5) {
        return BlockerSearch(vec4<f32>(own.w, 0.0, 0.0, reused), false);
    }
    return BlockerSearch(vec4<f32>(own.w, radii, reused), true);
}

// The horizontal blur over m taps of the pixel at `centre` (pixel position of its centre) after
// its blocker search `searched` (blocker_search's result with blur = true); each tap's pixel comes
// from `horizontal_source`.
fn horizontal_blur(centre: vec2<f32>, point: ScreenPoint, own: vec4<f32>, searched: vec4<f32>) -> vec4<f32> {
    let radii = searched.yz;
    let m = runtime_count(max(settings.blur_kernel, 1u), point.texel);
    let steps = kernel_steps(m);
    let rays = camera_rays();
    let line = tap_line(rays, point.position, point.normal, centre, vec2<f32>(radii.x, 0.0));
    var blurred = 0.0;
    var total = 0.0;
    // The taps on the screen are a run of consecutive taps (the tap's x grows with its index).
    var first_on_screen = m;
    var last_on_screen = -1;
    let bilateral = bilateral_weights(point.normal);
    for (var j = 0u; j < m; j++) {
        let offset = kernel_offset(steps, j);
        let tap = vec2<f32>(centre.x + offset * radii.x, centre.y);
        if (on_screen(tap)) {
            let source = horizontal_source(vec2<i32>(tap));
            var weight = tap_weight(j);
            if (settings.bilateral_depth > 0.0) {
                weight *= bilateral_weight_of(bilateral, source, tap_line_distance(line, offset));
            }
            blurred += weight * source.value;
            total += weight;
            first_on_screen = min(first_on_screen, j);
            last_on_screen = i32(j);
        }
    }
    // The taps past the screen's edges (those before the run and after it; none for most pixels):
    // the shadow test of the point of this pixel's tangent plane seen there. In a loop of their own
    // so that the loop above does not carry this code for every tap: a SIMD processor (lavapipe's
    // vectors, a GPU's warps) executes a branch's code for all its lanes when any lane takes it.
    let before = first_on_screen;
    let after = select(m - 1u - u32(last_on_screen), 0u, last_on_screen < 0);
    for (var k = 0u; k < before + after; k++) {
        let j = select(k, u32(last_on_screen + 1) + (k - before), k >= before);
        let tap = vec2<f32>(centre.x + kernel_offset(steps, j) * radii.x, centre.y);
        let plane = tangent_plane_point(rays, point.position, point.normal, tap);
        let weight = tap_weight(j);
        blurred += weight * select(own.w, hard_visibility(plane.xyz, point.normal), plane.w > 0.0);
        total += weight;
    }
    // Every tap on other surfaces (an even m has no centre tap): keep the hard value.
    let horizontal = select(own.w, blurred / total, total > 1e-6);
    return vec4<f32>(horizontal, radii, searched.w);
}
