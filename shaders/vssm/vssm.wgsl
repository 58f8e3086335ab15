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
// What this adds to the published method, each for a failure the README's "What differs" shows:
// each sub-region is compared with the receiver's tangent plane where it lies (not with the
// point's depth), texels with no surface are counted apart (lit, at no depth), the search is
// confined to the map, retried over smaller regions when it finds nothing, and repeated over the
// region its own estimate implies.

// #import common/screen_pass.wgsl
// #import common/shadow_map.wgsl
// #import common/read_counts.wgsl
// #import vssm/vssm_common.wgsl

// The settings, declared once in Rust (`VssmSettingsUniform`, ssm-techniques/vssm/src/lib.rs),
// whose derive writes this struct.
// #import rust/VssmSettings

@group(2) @binding(0) var moment_table: texture_2d<u32>;
@group(2) @binding(1) var<uniform> settings: VssmSettings;
// The depth map the table was built from, for its size and the normal offset's texel.
@group(2) @binding(2) var shadow_map: texture_2d<f32>;
// Counters 6 and 7 (after vssm_sat.wgsl's six): vssm_filter's (pixels, texel reads) and (pixels,
// bytes those fetched) per bucket (common/read_counts.wgsl), written only with COUNT_READS (a
// counting frame, TechniqueSetup::count_work).
@group(2) @binding(3) var<storage, read_write> read_counts: array<atomic<u32>>;

// Texel reads of this invocation, each a textureLoad (1 texel, of 16 bytes in the table): the
// G-buffer's two at every pixel, and every table entry loaded (table_at; an entry before the
// table's first row or column is 0 and not loaded). The normal offset reads none (it takes the
// map's size only). With one sub-region a query loads 16 entries (four columns of four),
// neighbouring sub-regions share their columns: 8(k + 1) a row of k. `read_bytes`: the bytes
// those fetched, each texel at its format's size.
var<private> reads: u32 = 0u;
var<private> read_bytes: u32 = 0u;

// Bytes of one texel of the G-buffer's position and normal (Rgba32Float: ssm-core's
// GBuffer::POSITION_FORMAT and NORMAL_FORMAT).
const GBUFFER_TEXEL_BYTES: u32 = 16u;

// The table at texel (i, j): the moments' sums over [0, i] × [0, j]; 0 for i or j below 0.
fn table_at(i: i32, j: i32) -> vec4<u32> {
    if (i < 0 || j < 0) {
        return vec4<u32>(0u);
    }
    let last = i32(settings.size) - 1;
    reads += 1u;
    read_bytes += TABLE_TEXEL_BYTES;
    return textureLoad(moment_table, vec2<i32>(min(i, last), min(j, last)), 0);
}

// The table at one x, X, differenced along y (128-bit, exact) for a row of sub-regions whose
// y edges fall in texel rows Y0 and Y1: the sums over [0, X] of the whole rows Y0 ≤ y < Y1
// (`band`), of row Y0 and of row Y1. Neighbouring sub-regions share a column's differences.
struct TableColumn {
    band: vec4<u32>,
    first_row: vec4<u32>,
    last_row: vec4<u32>,
};

fn table_column(x: i32, y0: i32, y1: i32) -> TableColumn {
    let y0_before = table_at(x, y0 - 1);
    let y1_before = table_at(x, y1 - 1);
    return TableColumn(
        subtract_sums(y1_before, y0_before),
        subtract_sums(table_at(x, y0), y0_before),
        subtract_sums(table_at(x, y1), y1_before),
    );
}

// The sums (Σz², Σz, area with a surface) over the region [low, high) of the map (texels, inside
// the map), with fractional edges: each texel weighted by its area in the region (a texel is a
// quad of constant depth). Exact: with X0 = ⌊low.x⌋, X1 = ⌊high.x⌋ and a, b their fractions,
// Σ w_i c_i = Σ_{X0 ≤ i < X1} c_i − a c_X0 + b c_X1 along each axis, every sum an integer
// difference of table entries, rounded to f32 only then. The columns hold the table at
// x = X0 − 1, X0, X1 − 1, X1.
fn weighted_sums(c0: TableColumn, c1: TableColumn, c2: TableColumn, c3: TableColumn, f_low: vec2<f32>, f_high: vec2<f32>) -> vec3<f32> {
    // Per axis: the whole texels, the first (weight −a) and the last (weight +b).
    let inner = sums_to_float(subtract_sums(c2.band, c0.band));
    let column_first = sums_to_float(subtract_sums(c1.band, c0.band));
    let column_last = sums_to_float(subtract_sums(c3.band, c2.band));
    let row_first = sums_to_float(subtract_sums(c2.first_row, c0.first_row));
    let row_last = sums_to_float(subtract_sums(c2.last_row, c0.last_row));
    let texel_first_first = sums_to_float(subtract_sums(c1.first_row, c0.first_row));
    let texel_last_first = sums_to_float(subtract_sums(c3.first_row, c2.first_row));
    let texel_first_last = sums_to_float(subtract_sums(c1.last_row, c0.last_row));
    let texel_last_last = sums_to_float(subtract_sums(c3.last_row, c2.last_row));
    let along_x = inner - f_low.x * column_first + f_high.x * column_last;
    let first_row = row_first - f_low.x * texel_first_first + f_high.x * texel_last_first;
    let last_row = row_last - f_low.x * texel_first_last + f_high.x * texel_last_last;
    return along_x - f_low.y * first_row + f_high.y * last_row;
}

// What region_grid answers for a region.
struct RegionAnswer {
    // Σ over the sub-regions of their lit fractions, of their blocker fractions and of blocker
    // fraction × average blocker depth (z units).
    lit: f32,
    blockers: f32,
    blocker_depths: f32,
    // The number of sub-regions.
    count: f32,
};

// Chebyshev's answers over a grid of equal sub-regions of [low, high) (texels), `k` per axis at
// most and none narrower than a texel: a texel holds one depth for its whole square, so a window
// of less than a texel sees its texel's depth, up to half a texel's depth change away from the
// surface's depth at the window, where a window of a texel or more averages the texels to the
// surface's depth at its centre (a box of one texel over texel centres is their bilinear
// interpolation).
// Each sub-region is compared with the receiver's tangent plane where it lies (`receiver`,
// receiver_depth_near), not with the point's depth: a sub-region off the point holds the
// receiver's own texels at that plane's depth, and a receiver that the light sees at a slant
// would otherwise shadow itself in the sub-regions nearer the light (with k = 2 each holds them
// spread evenly over h g either side of t − h g, g the depth change a texel and h the
// sub-region's half side, and Chebyshev's bound calls three quarters of them blockers, whatever
// the slope g).
// The part of a sub-region with no surface (empty texels, or outside the map) is lit and enters
// no moment: an empty texel is at no depth, and one counted at the far plane, beyond the
// receiver, loosens the bound and breaks the blocker estimate (which takes the non-blockers at t).
// Along a row of sub-regions, neighbours share the table's columns at their common boundary:
// 8(k + 1) reads a row.
fn region_grid(low: vec2<f32>, high: vec2<f32>, k: u32, receiver: TapPlane, far: f32) -> RegionAnswer {
    let size = settings.size;
    let counts = clamp(vec2<u32>(floor(high - low)), vec2<u32>(1u), vec2<u32>(k));
    let step = (high - low) / vec2<f32>(counts);
    let whole_area = max(step.x * step.y, 1e-12);
    var result = RegionAnswer(0.0, 0.0, 0.0, f32(counts.x * counts.y));
    for (var c = 0u; c < counts.y; c++) {
        let y_low = clamp(low.y + f32(c) * step.y, 0.0, size);
        let y_high = clamp(low.y + f32(c + 1u) * step.y, 0.0, size);
        let y_centre = low.y + (f32(c) + 0.5) * step.y;
        let y0 = i32(floor(y_low));
        let y1 = i32(floor(y_high));
        var x_low = clamp(low.x, 0.0, size);
        var column_before_low = table_column(i32(floor(x_low)) - 1, y0, y1);
        var column_low = table_column(i32(floor(x_low)), y0, y1);
        for (var i = 0u; i < counts.x; i++) {
            let x_high = clamp(low.x + f32(i + 1u) * step.x, 0.0, size);
            let whole_x_high = i32(floor(x_high));
            let column_before_high = table_column(whole_x_high - 1, y0, y1);
            let column_high = table_column(whole_x_high, y0, y1);
            let inside_area = (x_high - x_low) * (y_high - y_low);
            var surface_share = 0.0;
            var p = vec2<f32>(1.0, 0.0);
            var t = 1.0;
            if (inside_area > 0.0) {
                let f_low = vec2<f32>(x_low - floor(x_low), y_low - floor(y_low));
                let f_high = vec2<f32>(x_high - floor(x_high), y_high - floor(y_high));
                let inside = weighted_sums(column_before_low, column_low, column_before_high, column_high, f_low, f_high);
                let surface_area = min(inside.z, inside_area);
                surface_share = min(surface_area / whole_area, 1.0);
                if (surface_area > 1e-6) {
                    let centre = vec2<f32>(low.x + (f32(i) + 0.5) * step.x, y_centre) / size;
                    t = receiver_depth_near(receiver, centre, (1.0 - surface_share) * (0.5 * step + 0.5) / size) / far;
                    p = lit_fraction(inside.yx / surface_area, t);
                }
            }
            let blocker = surface_share * (1.0 - p.x);
            result.lit += 1.0 - blocker;
            // This sub-region's z_occ, from its surfaces. Negative when the spread of depths is
            // too wide for two depths with the upper one at t (σ² > μ (t − μ): surfaces beyond
            // the receiver, not blockers, make the variance): it then says nothing of the
            // blockers' depth, and such a sub-region would drag the average to the light.
            let occluder = (p.y - p.x * t) / max(1.0 - p.x, 1e-12);
            if (blocker > 0.0 && occluder >= 0.0) {
                result.blockers += blocker;
                result.blocker_depths += blocker * min(occluder, t);
            }
            x_low = x_high;
            column_before_low = column_before_high;
            column_low = column_high;
        }
    }
    return result;
}

// The nearest depth of the receiver's tangent plane along the rays through uv ± reach (shadow-map
// coordinates; along a line the plane's depth is monotonic, so the nearest is at a corner), or
// its fallback where none of them meets it. With reach 0, the depth at uv. A sub-region whose
// surfaces cover only part of it (its share s) may hold them off its centre: their area's
// centroid lies within (1 − s) of half the sub-region of it, their texels' centres within half a
// texel more, and the plane's depth at the centre would make the receiver's own texels nearer the
// light blockers; the nearest depth within that reach makes none of them one.
fn receiver_depth_near(receiver: TapPlane, uv: vec2<f32>, reach: vec2<f32>) -> f32 {
    var nearest = 3.0e38;
    for (var corner = 0u; corner < 4u; corner++) {
        let sign = vec2<f32>(f32(corner & 1u), f32(corner >> 1u)) * 2.0 - 1.0;
        let at = uv + sign * reach;
        let denominator = receiver.coefficients.x + receiver.coefficients.y * at.x + receiver.coefficients.z * at.y;
        let depth = receiver.numerator / denominator;
        if (abs(denominator) >= 1e-6 && depth > 0.0) {
            nearest = min(nearest, depth);
        }
    }
    return select(nearest, receiver.fallback, nearest >= 3.0e38);
}

// Most sub-regions per axis (the setting's range).
const MAX_SUBDIVISION: u32 = 8u;
// Each retry of a blocker search that found nothing covers this share of the last one's side.
const SEARCH_SHRINK: f32 = 0.25;
// Enough retries to shrink the whole map (a half side of 1) to a texel of the largest map
// (0.5 / 4096 = 2^-13, and 4^7 > 2^13).
const MAX_RETRIES: u32 = 7u;
// Blocker searches over the region the last one's estimate implies (PCSS's filter region at that depth).
const SEARCH_REFINEMENTS: u32 = 2u;

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

// The average blocker depth (world units) over the part inside the map of the region uv ± extent,
// or 0 where it holds no blocker. Nothing outside the map blocks (the light frame holds every
// occluder between the light and a receiver), and the search counts only what is in it.
fn blocker_search(uvd: vec3<f32>, extent: vec2<f32>, k: u32, receiver: TapPlane, far: f32) -> f32 {
    let size = vec2<f32>(settings.size);
    let low = clamp((uvd.xy - extent) * size, vec2<f32>(0.0), size);
    let high = clamp((uvd.xy + extent) * size, vec2<f32>(0.0), size);
    if (any(high <= low)) {
        return 0.0;
    }
    let answer = region_grid(low, high, k, receiver, far);
    if (answer.blockers <= 1e-6 * answer.count) {
        return 0.0;
    }
    // Blockers at the light itself: keep the depth positive, which says "found".
    return max(answer.blocker_depths / answer.blockers * far, 1e-30);
}

@fragment
fn vssm_filter(in: FullscreenVertex) -> @location(0) f32 {
    let point = screen_point(in);
    reads = 2u;
    read_bytes = 2u * GBUFFER_TEXEL_BYTES;
    let visibility = vssm_visibility(point);
    if (COUNT_READS) {
        let word = read_count_word(6u, point.texel);
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
        let bytes_word = read_count_word(7u, point.texel);
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], read_bytes);
    }
    return visibility;
}

// The visibility at a pixel's point: steps 1 to 3.
fn vssm_visibility(point: ScreenPoint) -> f32 {
    let trivial = trivial_visibility(point);
    if (trivial >= 0.0) {
        return trivial;
    }
    let lookup = normal_offset_position(frame, shadow_map, point.position, point.normal, settings.normal_offset);
    let uvd = light_uv_depth(frame, lookup);
    let far = frame.projection.w;
    // What each sub-region is compared with: the receiver's tangent plane (the point's own depth
    // where a ray misses it).
    let receiver = tap_plane(frame, lookup, point.normal, uvd.z);
    let k = clamp(settings.subdivision, 1u, MAX_SUBDIVISION);
    // A region is never narrower than one texel: a point light's filter is the texel under the point.
    let least = vec2<f32>(0.5 / settings.size);

    // 1. Blocker search over the light's back-projection through the near plane (at most the whole
    // map). Where the frame's near plane is at the light (walls beside it: a room, a box around
    // it; a floor running up to its plane) that is most of the map, and a small blocker among
    // surfaces spread over many depths (a floor the light sees at a slant) leaves the bound saying
    // lit: the search is retried over regions a quarter the side each time, down to a texel,
    // each one plain VSM query (it looks for a blocker near the point, not for their layout).
    var search = clamp(light_half_extent_uv(frame, frame.projection.z, uvd.z), least, vec2<f32>(1.0));
    var blocker_depth = blocker_search(uvd, search, k, receiver, far);
    for (var retry = 0u; retry < MAX_RETRIES && blocker_depth <= 0.0 && any(search > least); retry++) {
        search = max(search * SEARCH_SHRINK, least);
        blocker_depth = blocker_search(uvd, search, 1u, receiver, far);
    }
    // The region at the near plane is PCSS's bound over every blocker depth, and its average is
    // pulled towards the light by surfaces in it that cannot block the point (a wall's far parts):
    // the search is repeated over the region that its estimate implies, never a larger one.
    for (var refinement = 0u; refinement < SEARCH_REFINEMENTS && blocker_depth > 0.0; refinement++) {
        search = min(max(light_half_extent_uv(frame, blocker_depth, uvd.z), least), search);
        blocker_depth = blocker_search(uvd, search, k, receiver, far);
    }
    if (blocker_depth <= 0.0) {
        return 1.0;
    }

    // 2. Penumbra extent (within the last search region, as PCSS's is within its search), 3. the
    // fraction lit over it.
    let extent = min(max(light_half_extent_uv(frame, blocker_depth, uvd.z), least), search);
    let size = vec2<f32>(settings.size);
    let lit = region_grid((uvd.xy - extent) * size, (uvd.xy + extent) * size, k, receiver, far);
    return clamp(lit.lit / lit.count, 0.0, 1.0);
}
