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
    var sum_count = vec2<f32>(0.0);
    for (var t = 0u; t < n; t++) {
        sum_count += blocker_row(vec2<f32>(uvd.x, uvd.y + grid_offset(t, n) * search.y), search.x, receiver, n);
    }
    return sum_count;
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
    count_screen_target_read();
    return unpack_blur_source(packed_hard_value(packed), packed);
}

// The blocker search of a computed pixel and its penumbra: (the hard or lit value, the blockers'
// average light depth or 0 where there is no blur, the pixel's light depth, blocker rows reused),
// from which steps 2 and 3 both find the blur's axes (blur_axes); whether the first blur remains
// to be done (else the vector is the pass's output), and the axes when it does.
struct BlockerSearch {
    result: vec4<f32>,
    blur: bool,
    axes: BlurAxes,
};

fn blocker_search(point: ScreenPoint, own: vec4<f32>) -> BlockerSearch {
    let d = own.x;
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    let receiver = compared_plane(lookup, point.normal, d);
    let search = light_half_extent_uv(frame, frame.projection.z, d);
    let n = max(settings.blocker_kernel, 1u);
    var sum = 0.0;
    var count = 0.0;
    var reused = 0.0;
    for (var t = 0u; t < n; t++) {
        let row_uv = vec2<f32>(uvd.x, uvd.y + grid_offset(t, n) * search.y);
        // The pixel that sees the point of this row at the same light depth d (Fig. 4).
        let screen = screen_position(light_point(row_uv, d));
        let from_screen = screen.z > 0.0 && row_read_from_screen(screen.xy);
        var reuse = false;
        var no_data = false;
        if (from_screen) {
            let other = textureLoad(horizontal_blocker, clamped_texel(screen.xy), 0);
            count_screen_target_read();
            no_data = other.x < 0.0;
            reuse = !no_data && abs(d - other.x) < scene_length(frame, settings.alpha);
            if (reuse) {
                sum += other.y;
                count += other.z;
                reused += 1.0;
            }
        }
        if (!reuse) {
            // |d - d_t| ≥ α, or no row to reuse: the row is read from the depth map (Fig. 4).
            count_failed_row(!from_screen, no_data);
            let partial = blocker_row(row_uv, search.x, receiver, n);
            sum += partial.x;
            count += partial.y;
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
    let no_axes = BlurAxes(vec2<f32>(0.0), vec2<f32>(0.0));
    // No blocker: fully lit (Sec. 4.2).
    if (count == 0.0) {
        return BlockerSearch(vec4<f32>(1.0, 0.0, d, reused), false, no_axes);
    }
    let blocker = sum / count;
    // Eq. 1: w_penumbra = w_light (z_receiver - z_avg) / z_avg, as the shadow-map half-extent of
    // PCSS's filter (the same kernel pcss filters over), then laid on the receiver's tangent plane
    // and projected onto the screen.
    let axes = blur_axes(point, blocker, d);
    // A penumbra under half a pixel keeps the hard value.
    if (under_half_a_pixel(axes)) {
        return BlockerSearch(vec4<f32>(own.w, 0.0, d, reused), false, no_axes);
    }
    return BlockerSearch(vec4<f32>(own.w, blocker, d, reused), true, axes);
}

// The first blur (along the screen's rows, or the light's first side) over m taps of the pixel at
// `centre` (pixel position of its centre) after its blocker search `searched` (blocker_search's
// result with blur = true, its axes `axes`); each tap's pixel comes from `horizontal_source`.
fn horizontal_blur(centre: vec2<f32>, point: ScreenPoint, own: vec4<f32>, searched: vec4<f32>, axes: BlurAxes) -> vec4<f32> {
    let m = max(settings.blur_kernel, 1u);
    let rays = camera_rays();
    var blurred = 0.0;
    var total = 0.0;
    for (var j = 0u; j < m; j++) {
        let offset = grid_offset(j, m);
        let tap = centre + offset * axes.first;
        let weight = blur_weight(offset);
        if (on_screen(tap)) {
            let source = horizontal_source(vec2<i32>(tap));
            let expected = plane_distance(rays, point.position, point.normal, tap);
            let tap_weight = weight * bilateral_weight_of(point.normal, source, expected);
            blurred += tap_weight * source.value;
            total += tap_weight;
        } else {
            // Past the screen's edges: the shadow test of the point of this pixel's tangent plane
            // seen there. Where the ray misses the plane (past its horizon) the receiver is not
            // there to sample, as a tap on another surface on the screen is not: no weight. (The
            // pixel's own value there held a kernel far wider than the screen at the hard shadow
            // over half its taps.)
            let plane = tangent_plane_point(rays, point.position, point.normal, tap);
            if (plane.w > 0.0) {
                blurred += weight * hard_visibility(plane.xyz, point.normal);
                total += weight;
            }
        }
    }
    // Every tap on other surfaces (an even m has no centre tap): keep the hard value.
    let horizontal = select(own.w, blurred / total, total > 1e-6);
    return vec4<f32>(horizontal, searched.yzw);
}
