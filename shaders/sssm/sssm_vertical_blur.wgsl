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
    reads += 1u;
    return unpack_vertical_tap_source(textureLoad(vertical_tap_source, texel, 0));
}

// The vertical blur's half-width in pixels at a computed pixel whose step 2 result is `own`
// (0 where the penumbra is under half a pixel and the horizontal value stands).
fn vertical_radius(own: vec4<f32>) -> f32 {
    return select(own.z, 0.0, max(own.y, own.z) < 0.5);
}

// (visibility, share of rows reused in steps 2 and 3) of the computed pixel at `centre` (pixel
// position of its centre), whose step 2 result is `own`; each tap's pixel comes from `vertical_source`.
fn vertical(centre: vec2<f32>, point: ScreenPoint, own: vec4<f32>) -> vec2<f32> {
    let n = f32(max(settings.blocker_kernel, 1u));
    let radii = own.yz;
    if (max(radii.x, radii.y) < 0.5) {
        // No blur: only the blocker rows counted.
        return vec2<f32>(own.x, own.w / n);
    }
    let m = runtime_count(max(settings.blur_kernel, 1u), point.texel);
    let steps = kernel_steps(m);
    let rays = camera_rays();
    let own_hard = packed_hard_value(textureLoad(blur_source, point.texel, 0));
    reads += 1u;
    let offset = lookup_offset(point.position, point.normal);
    var blurred = 0.0;
    var total = 0.0;
    var reused = 0.0;
    // Rows failing the β test, recomputed after the reused ones.
    var failed_rows = FailedRows();
    let line = tap_line(rays, point.position, point.normal, centre, vec2<f32>(0.0, radii.y));
    let column = VerticalColumn(steps, centre, radii.y, line, bilateral_weights(point.normal));
    // The taps in pairs about the centre, weighted as recomputed_row's (settings.blur_weight_steps).
    let half = m / 2u;
    let odd = m % 2u;
    let weights = settings.blur_weight_steps;
    if (odd == 1u) {
        vertical_tap(column, half, weights.centre, &blurred, &total, &reused, &failed_rows);
    }
    var pair_weight = weights.first_pair;
    var ratio = weights.first_ratio;
    for (var k = 0u; k < half; k++) {
        vertical_tap(column, half - 1u - k, pair_weight, &blurred, &total, &reused, &failed_rows);
        vertical_tap(column, half + odd + k, pair_weight, &blurred, &total, &reused, &failed_rows);
        pair_weight *= ratio;
        ratio *= weights.ratio_step;
    }
    let rows = recomputed_rows(rays, point, offset, own_hard, centre.x, radii.x, m);
    // Popped before the loop and again at the end of its body: lavapipe ends a loop only when no
    // SIMD lane is left in it, checked at the end of the body, so with the pop at the top a vector
    // of pixels ran one more row, masked, after its last (about 3% of this pass at 7/15).
    var failed = pop_failed_row(&failed_rows);
    loop {
        if (failed < 0) {
            break;
        }
        let row = centre + vec2<f32>(0.0, kernel_offset(steps, u32(failed)) * radii.y);
        // The table's weight: the pair weight the loop above gave this row, to (k + 1)² units in
        // the last place at pair k, which a popped row no longer knows.
        let weight = tap_weight(u32(failed));
        blurred += weight * recomputed_row(rows, row.y);
        total += weight;
        failed = pop_failed_row(&failed_rows);
        if (failed < 0) {
            break;
        }
    }
    let visibility = clamp(select(own.x, blurred / total, total > 1e-6), 0.0, 1.0);
    return vec2<f32>(visibility, (own.w + reused) / (n + f32(m)));
}

// What every vertical tap of a pixel shares.
struct VerticalColumn {
    steps: KernelSteps,
    centre: vec2<f32>,
    radius_y: f32,
    line: TapLine,
    bilateral: BilateralWeights,
};

// Vertical tap j of weight `weight`: its row reused (added to blurred, total and reused) when the
// β test passes, else marked failed. Selects rather than branches: every lane of a SIMD vector
// runs every tap anyway. A row off the screen reads the nearest on-screen texel, whose value it
// uses only with CLAMP_EDGE_ROWS.
fn vertical_tap(column: VerticalColumn, j: u32, weight: f32, blurred: ptr<function, f32>, total: ptr<function, f32>, reused: ptr<function, f32>, failed_rows: ptr<function, FailedRows>) {
    let offset = kernel_offset(column.steps, j);
    let row = column.centre + vec2<f32>(0.0, offset * column.radius_y);
    let source = vertical_source(clamped_texel(row));
    let expected = tap_line_distance(column.line, offset);
    let read_from_screen = row_read_from_screen(row);
    let reuse = read_from_screen && within_beta(source, expected);
    let tap_weight_value = select(0.0, weight * bilateral_weight_of(column.bilateral, source, expected), reuse);
    *blurred += tap_weight_value * source.value;
    *total += tap_weight_value;
    *reused += select(0.0, 1.0, reuse);
    mark_failed_row_if(failed_rows, j, !reuse);
    if (COUNT_READS && !reuse) {
        count_failed_row(!read_from_screen, source.eye_distance < 0.0);
    }
}

// A row of step 2's horizontal blur recomputed on this pixel's tangent plane with this pixel's
// kernel: the m taps along the screen row at pixel height `row_y`, the blur's half-width either
// side of the pixel's column (`rows`, what the pixel's rows share), each the hard visibility of
// the point of the plane seen there (the pixel's own hard value where the camera ray misses the
// plane). That point, offset by the pixel's lookup offset, projects into the shadow map as
// a projective function of the tap's index, so the taps are stepped in homogeneous coordinates:
// with den = ray·normal, H = (eye + offset - light centre)·den + (point - eye)·normal · ray is the
// looked-up point's offset from the light's centre times den, and ray, den and H are linear in
// the index. Each tap costs a few additions and a division instead of a ray-plane intersection
// and a light projection (mathematically the same taps as tangent_plane_point and tap_visibility).
fn recomputed_row(rows: RecomputedRows, row_y: f32) -> f32 {
    let first_ray = rows.first_ray_x + row_y * rows.per_y;
    let first_den = dot(first_ray, rows.normal);
    let first_ray_light = first_ray * rows.axes;
    let first_h = rows.lookup_light * first_den + rows.plane_offset * first_ray_light;
    // The plane point's own light depth times den (the one-sided emitter's test, without the offset).
    let first_front = rows.eye_light_z * first_den + rows.plane_offset * first_ray_light.z;
    // den and the plane point's front distance are linear in the tap index: where each has one
    // sign at both ends of the row it has that sign at every tap, and so have the plane test
    // (meets_plane below) and the light test (in_front). Where both pass at every tap, each tap
    // only compares depths: the same values as the general loop after it, which handles the rows
    // that cross the eye's or the light's plane (grazing views).
    let last_den = first_den + rows.last * rows.den_step;
    let last_front = first_front + rows.last * rows.front_step;
    let den_kept = first_den * last_den > 0.0 && min(abs(first_den), abs(last_den)) >= 1e-12;
    let front_kept = first_front * last_front > 0.0;
    // The taps pair up about the row's centre and share a weight (settings.blur_weight_steps):
    // pair k is taps half - 1 - k and half + odd + k, after the centre tap of an odd kernel. The
    // weights follow by two products a pair rather than tap_weight's table: on lavapipe a lookup
    // indexed by the loop counter is a load per SIMD lane (dropping it saved about 5% of this
    // pass at 29/41 on leaves; the sssm README has the figures).
    let half = rows.half;
    let odd = rows.odd;
    let weights = settings.blur_weight_steps;
    var row_sum = 0.0;
    var weight = weights.first_pair;
    var ratio = weights.first_ratio;
    if (den_kept && front_kept && rows.plane_offset * first_den > 0.0 && first_front * first_den > 0.0) {
        // With den's sign s: s·h.z <= the map's depth · s·den is h.z / den <= the map's depth.
        let den_sign = select(-1.0, 1.0, first_den > 0.0);
        let stepped = DepthOnlyRow(den_sign * first_h, den_sign * rows.h_step, den_sign * first_den, den_sign * rows.den_step, rows.half_inverse_projection);
        if (odd == 1u) {
            row_sum = weights.centre * depth_only_lit(stepped, f32(half));
        }
        for (var k = 0u; k < half; k++) {
            row_sum += weight * (depth_only_lit(stepped, f32(half - 1u - k)) + depth_only_lit(stepped, f32(half + odd + k)));
            weight *= ratio;
            ratio *= weights.ratio_step;
        }
        return row_sum / settings.blur_weight_total;
    }
    let stepped = GeneralRow(first_h, rows.h_step, first_den, rows.den_step, first_front, rows.front_step, rows.plane_offset, rows.own_hard, rows.half_inverse_projection);
    if (odd == 1u) {
        row_sum = weights.centre * general_visibility(stepped, f32(half));
    }
    for (var k = 0u; k < half; k++) {
        row_sum += weight * (general_visibility(stepped, f32(half - 1u - k)) + general_visibility(stepped, f32(half + odd + k)));
        weight *= ratio;
        ratio *= weights.ratio_step;
    }
    return row_sum / settings.blur_weight_total;
}

// What every recomputed row of a pixel shares (recomputed_rows), computed once per pixel rather
// than in each row's setup (no change in time measured on lavapipe, whose LLVM may hoist it; it
// keeps each row's work to what depends on the row).
struct RecomputedRows {
    normal: vec3<f32>,
    // (point - eye) · normal.
    plane_offset: f32,
    // Columns: the light's u, v and normal axes, so that `v * axes` is v's light-frame components.
    axes: mat3x3<f32>,
    // The eye's light-frame depth.
    eye_light_z: f32,
    // The eye plus the pixel's lookup offset, from the light's centre, in the light frame.
    lookup_light: vec3<f32>,
    // The camera ray of a row's first tap, less its row's y · per_y.
    first_ray_x: vec3<f32>,
    per_y: vec3<f32>,
    // Per tap: the ray's dot with the normal, H and the front distance.
    den_step: f32,
    h_step: vec3<f32>,
    front_step: f32,
    half_inverse_projection: vec2<f32>,
    // The pixel's hard value, for taps whose ray misses the plane.
    own_hard: f32,
    // m - 1, m / 2 and m % 2.
    last: f32,
    half: u32,
    odd: u32,
};

// The shared part of the recomputed rows of the pixel at `point`, its blur `radius_x` pixels
// either side of `centre_x` over m taps.
fn recomputed_rows(rays: CameraRays, point: ScreenPoint, offset: vec3<f32>, own_hard: f32, centre_x: f32, radius_x: f32, m: u32) -> RecomputedRows {
    let eye = camera.position.xyz;
    let normal = point.normal;
    let plane_offset = dot(point.position - eye, normal);
    let axes = mat3x3<f32>(frame.u_axis.xyz, frame.v_axis.xyz, frame.normal.xyz);
    let eye_light = (eye - frame.centre.xyz) * axes;
    let lookup_light = (eye + offset - frame.centre.xyz) * axes;
    let first_ray_x = rays.base + (centre_x + kernel_offset(kernel_steps(m), 0u) * radius_x) * rays.per_x;
    let ray_step = (2.0 * radius_x / f32(m)) * rays.per_x;
    let den_step = dot(ray_step, normal);
    let ray_step_light = ray_step * axes;
    let h_step = lookup_light * den_step + plane_offset * ray_step_light;
    let front_step = eye_light.z * den_step + plane_offset * ray_step_light.z;
    return RecomputedRows(normal, plane_offset, axes, eye_light.z, lookup_light, first_ray_x, rays.per_y, den_step, h_step, front_step, 0.5 / frame.projection.xy, own_hard, f32(m - 1u), m / 2u, m % 2u);
}

// A recomputed row whose taps all lie on the plane in front of the eye and of the light, its
// stepped values multiplied by den's sign (recomputed_row).
struct DepthOnlyRow {
    first_h: vec3<f32>,
    h_step: vec3<f32>,
    first_den: f32,
    den_step: f32,
    half_inverse_projection: vec2<f32>,
};

// 1 where tap `index` of `row` is lit, else 0: only a depth comparison.
fn depth_only_lit(row: DepthOnlyRow, index: f32) -> f32 {
    let h = row.first_h + index * row.h_step;
    let uv = 0.5 + h.xy * row.half_inverse_projection * (1.0 / h.z);
    reads += 1u;
    return select(0.0, 1.0, h.z <= tap_depth(uv) * (row.first_den + index * row.den_step));
}

// Any recomputed row (recomputed_row's stepped values), for rows that cross the eye's or the light's plane.
struct GeneralRow {
    first_h: vec3<f32>,
    h_step: vec3<f32>,
    first_den: f32,
    den_step: f32,
    first_front: f32,
    front_step: f32,
    plane_offset: f32,
    own_hard: f32,
    half_inverse_projection: vec2<f32>,
};

// The hard visibility of tap `index` of `row`. Selects rather than branches, and products rather
// than quotients where a sign decides: a tap costs one division (its light depth's reciprocal)
// and the same few instructions in every lane.
fn general_visibility(row: GeneralRow, index: f32) -> f32 {
    let den = row.first_den + index * row.den_step;
    // The ray meets the plane in front of the eye (tangent_plane_point's w).
    let meets_plane = abs(den) >= 1e-12 && row.plane_offset * den > 0.0;
    // In front of the light's plane (tap_visibility's first test).
    let in_front = (row.first_front + index * row.front_step) * den > 0.0;
    let h = row.first_h + index * row.h_step;
    // One reciprocal for both coordinates.
    let uv = 0.5 + h.xy * row.half_inverse_projection * (1.0 / h.z);
    reads += 1u;
    // h.z / den <= the map's depth, with den's sign.
    let map_depth = tap_depth(uv) * den;
    let lit = select(h.z >= map_depth, h.z <= map_depth, den > 0.0);
    return select(row.own_hard, select(0.0, select(0.0, 1.0, lit), in_front), meets_plane);
}
