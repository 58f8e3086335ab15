// VSSM (Yang, Dong, Feng, Seidel and Kautz 2010): PCSS's three steps (Fernando 2005) answered by
// the moments of the shadow map over a region, read in constant time from their summed-area
// table (vssm_sat.wgsl), instead of by taps.
// 1. Blocker search over the light's back-projection through the near plane, as PCSS's: with the
//    region's mean μ and variance σ² of the depth z, Chebyshev's one-tailed inequality bounds the
//    fraction of texels at or beyond the receiver's depth t, p = σ² / (σ² + (t − μ)²) for t > μ
//    (Donnelly and Lauritzen 2006). Taking those texels at depth t (non-blockers lie on the
//    receiver), μ = p t + (1 − p) z_occ gives the average blocker depth
//    z_occ = (μ − p t) / (1 − p): the paper's blocker estimate. t ≤ μ: no blocker.
// 2. The penumbra's extent from z_occ by similar triangles, as PCSS's.
// 3. The filter: the fraction lit over that region, Chebyshev's p (1 where t ≤ μ), VSM's.
// The paper's answer to VSM's incorrectly lit pixels (one region's moments mix receivers and
// occluders at several depths, and the bound says lit) is to subdivide the kernel: each region
// here is cut into `subdivision`² equal sub-regions, each answered on its own, their blockers
// weighted by their blocker fractions and their fractions lit averaged.

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import vssm/vssm_common.wgsl

struct VssmSettings {
    // Side of the shadow map and its summed-area table, texels.
    size: f32,
    // Sub-regions per axis of each region (1: plain VSM).
    subdivision: u32,
    // Smallest variance the bound uses, in z² units (z = depth / far): keeps it finite on a flat
    // region, where it is 0, and absorbs the table's rounding.
    min_variance: f32,
    // Normal offset of the lookup point, in shadow-map texels.
    normal_offset: f32,
    // The depth bias the map's texels carry, world units: the receiver's own texels hold its depth
    // plus this, and Chebyshev's bound is tight (two depths, the upper one at t) only with t there.
    constant_bias: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
};

@group(2) @binding(0) var moment_table: texture_2d<u32>;
@group(2) @binding(1) var<uniform> settings: VssmSettings;
// The depth map the table was built from, for its size and the normal offset's texel.
@group(2) @binding(2) var shadow_map: texture_2d<f32>;

// The table at texel (i, j): the moments' sums over [0, i] × [0, j]; 0 for i or j below 0.
fn table_at(i: i32, j: i32) -> vec4<u32> {
    if (i < 0 || j < 0) {
        return vec4<u32>(0u);
    }
    let last = i32(settings.size) - 1;
    return textureLoad(moment_table, vec2<i32>(min(i, last), min(j, last)), 0);
}

// The table at one x and the four y a sub-region needs (Y0 − 1, Y0, Y1 − 1, Y1).
struct TableColumn {
    y0_before: vec4<u32>,
    y0: vec4<u32>,
    y1_before: vec4<u32>,
    y1: vec4<u32>,
};

fn table_column(x: i32, y0: i32, y1: i32) -> TableColumn {
    return TableColumn(table_at(x, y0 - 1), table_at(x, y0), table_at(x, y1 - 1), table_at(x, y1));
}

// The exact sum of a rectangle of texels whose table corners are `low_low` … `high_high`
// (the table at its two x below and two y below, exclusive, and at its far corner, inclusive).
fn rect_sum(low_low: vec4<u32>, high_low: vec4<u32>, low_high: vec4<u32>, high_high: vec4<u32>) -> vec2<f32> {
    return sums_to_float(add_sums(subtract_sums(high_high, low_high), subtract_sums(low_low, high_low)));
}

// The moments' sums over the region [low, high) of the map (texels, inside the map), with
// fractional edges: each texel weighted by its area in the region (a texel is a quad of
// constant depth). Exact: with X0 = ⌊low.x⌋, X1 = ⌊high.x⌋ and a, b their fractions,
// Σ w_i c_i = Σ_{X0 ≤ i < X1} c_i − a c_X0 + b c_X1 along each axis, every sum an integer
// difference of table entries. The columns hold the table at x = X0 − 1, X0, X1 − 1, X1.
fn weighted_sums(c0: TableColumn, c1: TableColumn, c2: TableColumn, c3: TableColumn, f_low: vec2<f32>, f_high: vec2<f32>) -> vec2<f32> {
    // Per axis: the whole texels, the first (weight −a) and the last (weight +b).
    let inner = rect_sum(c0.y0_before, c2.y0_before, c0.y1_before, c2.y1_before);
    let column_first = rect_sum(c0.y0_before, c1.y0_before, c0.y1_before, c1.y1_before);
    let column_last = rect_sum(c2.y0_before, c3.y0_before, c2.y1_before, c3.y1_before);
    let row_first = rect_sum(c0.y0_before, c2.y0_before, c0.y0, c2.y0);
    let row_last = rect_sum(c0.y1_before, c2.y1_before, c0.y1, c2.y1);
    let texel_first_first = rect_sum(c0.y0_before, c1.y0_before, c0.y0, c1.y0);
    let texel_last_first = rect_sum(c2.y0_before, c3.y0_before, c2.y0, c3.y0);
    let texel_first_last = rect_sum(c0.y1_before, c1.y1_before, c0.y1, c1.y1);
    let texel_last_last = rect_sum(c2.y1_before, c3.y1_before, c2.y1, c3.y1);
    let along_x = inner - f_low.x * column_first + f_high.x * column_last;
    let first_row = row_first - f_low.x * texel_first_first + f_high.x * texel_last_first;
    let last_row = row_last - f_low.x * texel_first_last + f_high.x * texel_last_last;
    return along_x - f_low.y * first_row + f_high.y * last_row;
}

// Chebyshev's answers over a k×k grid of equal sub-regions of [low, high) (texels): Σ of the
// sub-regions' lit fractions, Σ of their blocker fractions, and Σ of blocker fraction × average
// blocker depth, for a receiver at depth t (z units). Along a row of sub-regions, neighbours
// share the table's columns at their common boundary: 8(k + 1) reads a row. A sub-region's part
// outside the map counts as empty texels, at the far plane (z = z² = 1), as a tap outside the
// map finds no surface.
fn region_grid(low: vec2<f32>, high: vec2<f32>, k: u32, t: f32) -> vec3<f32> {
    let step = (high - low) / f32(k);
    let whole_area = max(step.x * step.y, 1e-12);
    let size = settings.size;
    var result = vec3<f32>(0.0);
    for (var c = 0u; c < k; c++) {
        let y_low = clamp(low.y + f32(c) * step.y, 0.0, size);
        let y_high = clamp(low.y + f32(c + 1u) * step.y, 0.0, size);
        let y0 = i32(floor(y_low));
        let y1 = i32(floor(y_high));
        var x_low = clamp(low.x, 0.0, size);
        var column_before_low = table_column(i32(floor(x_low)) - 1, y0, y1);
        var column_low = table_column(i32(floor(x_low)), y0, y1);
        for (var i = 0u; i < k; i++) {
            let x_high = clamp(low.x + f32(i + 1u) * step.x, 0.0, size);
            let whole_x_high = i32(floor(x_high));
            let column_before_high = table_column(whole_x_high - 1, y0, y1);
            let column_high = table_column(whole_x_high, y0, y1);
            let inside_area = (x_high - x_low) * (y_high - y_low);
            var means = vec2<f32>(1.0);
            if (inside_area > 0.0) {
                let f_low = vec2<f32>(x_low - floor(x_low), y_low - floor(y_low));
                let f_high = vec2<f32>(x_high - floor(x_high), y_high - floor(y_high));
                let inside = weighted_sums(column_before_low, column_low, column_before_high, column_high, f_low, f_high);
                means = (inside + vec2<f32>(whole_area - inside_area)) / whole_area;
            }
            let p = lit_fraction(means, t);
            result.x += p.x;
            if (p.x < 1.0) {
                // This sub-region's z_occ, kept between the light and the receiver.
                let occluder = clamp((p.y - p.x * t) / (1.0 - p.x), 0.0, t);
                result.y += 1.0 - p.x;
                result.z += (1.0 - p.x) * occluder;
            }
            x_low = x_high;
            column_before_low = column_before_high;
            column_low = column_high;
        }
    }
    return result;
}

// Most sub-regions per axis (the setting's range).
const MAX_SUBDIVISION: u32 = 8u;

// Chebyshev's bound on the fraction of the region's texels at or beyond depth t (z units), and
// the region's mean: (p, μ). p = 1 where t ≤ μ.
fn lit_fraction(means: vec2<f32>, t: f32) -> vec2<f32> {
    let mean = means.x;
    if (t <= mean) {
        return vec2<f32>(1.0, mean);
    }
    let variance = max(means.y - mean * mean, settings.min_variance);
    let difference = t - mean;
    return vec2<f32>(variance / (variance + difference * difference), mean);
}

@fragment
fn vssm_filter(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        return trivial;
    }
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    let far = frame.projection.w;
    // The depth the receiver's own texels hold (its depth plus the map's bias): non-blockers lie
    // there, so that is where the bound's threshold belongs (Sec. 3's z_unocc = t).
    let t = (uvd.z + settings.constant_bias) / far;
    let k = clamp(settings.subdivision, 1u, MAX_SUBDIVISION);
    // A region is never narrower than one texel: a point light's filter is the texel under the point.
    let least = vec2<f32>(0.5 / settings.size);

    // 1. Blocker search.
    let search = max(light_half_extent_uv(frame, frame.projection.z, uvd.z), least);
    let blockers = region_grid((uvd.xy - search) * settings.size, (uvd.xy + search) * settings.size, k, t);
    if (blockers.y <= 1e-6) {
        return 1.0;
    }
    let blocker_depth = blockers.z / blockers.y * far;

    // 2. Penumbra extent, 3. the fraction lit over it.
    let extent = max(light_half_extent_uv(frame, blocker_depth, uvd.z), least);
    let lit = region_grid((uvd.xy - extent) * settings.size, (uvd.xy + extent) * settings.size, k, t).x;
    return clamp(lit / f32(k * k), 0.0, 1.0);
}
