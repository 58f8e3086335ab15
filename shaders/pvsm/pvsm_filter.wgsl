// PVSM step 8 (Sec. 4.1, 4.2, 5.2), once per tile, one invocation per pixel: the filter h of the
// pixel integrated over the part of the tile's shadow map it covers, each texel a quad of constant
// depth whose weight is the exact area of its intersection with h (Eq. 2; h's vertical
// half-axis is the map's, and each one-texel-wide column of the parallelogram is taken as an
// axis-aligned box, as Sec. 4.2 does). The pixel's accumulator gets the visible covered area Σ c·o
// and the covered area Σ c, so that tiles sharing a filter merge exactly (Sec. 5.2's V·A and A).
//
// Eq. 2's sum is walked top-down over the tile's two-layer min/max depth pyramid
// (pvsm_filter_pyramid.wgsl): a block whose depths are all at or behind the receiver's (every texel
// lit) or all in front of it (every texel occluding) adds its exact covered area in one step; a
// block of two layers (a bar over a floor) lying entirely inside the filter, with the receiver
// between its layers, adds its far layer's texel count as its lit area (inside the filter every
// texel weighs its whole area), and one straddling the filter's edge settles so its children that
// lie inside the filter or hold one cluster, or at level 1 its texels, from its per-child near
// counts; only the other blocks (and such a block's children on the edge holding both clusters,
// at the cost of their counts alone) descend to their four children; texels are the leaves. The sum is the per-texel one (filter_walk = texels), within f32 summation order, and
// its cost follows where occluders' edges cross the filter's boundary or the receiver's depth, not
// the filter's area.

// #import pvsm/pvsm_common.wgsl
// #import common/read_counts.wgsl

// The settings, declared once in Rust (`TileSettingsUniform`, ssm-techniques/pvsm/src/filter.rs),
// whose derive writes this struct.
// #import rust/TileSettings

@group(2) @binding(2) var<storage, read> kernels: array<Kernel>;
// Per pixel: (Σ c·o, Σ c).
@group(2) @binding(3) var<storage, read_write> accumulated: array<vec2<f32>>;
// Per pixel: 1 once its walk hit MAX_WALK_STEPS in some tile (cleared per light).
@group(2) @binding(4) var<storage, read_write> capped: array<u32>;
// COUNTER_* of pvsm_common.wgsl (the resolve pass adds the capped and uncovered pixels).
@group(2) @binding(5) var<storage, read_write> counters: array<atomic<u32>, COUNTERS>;
// ReadCounts (ssm-core), with COUNT_READS: READ_COUNTER_TILE_FILTER and its bytes, the walk's
// reads, and READ_COUNTER_RESOLVE and its bytes.
@group(2) @binding(6) var<storage, read_write> read_counts: array<atomic<u32>>;
@group(3) @binding(0) var<uniform> tile: TileSettings;
@group(3) @binding(1) var tile_map: texture_2d<f32>;
// The tile map's two-layer min/max depth pyramid (pvsm_filter_pyramid.wgsl): mip m holds level m + 1
// (blocks of 2^(m+1) texels a side) as (nearest, farthest, near_max, far_min), and in
// tile_near_counts its near cluster's texels in each child (x, y, z, w: children (0, 0), (1, 0),
// (0, 1), (1, 1)); only the tile's region, from the top-left corner, is written.
@group(3) @binding(3) var tile_pyramid: texture_2d<f32>;
@group(3) @binding(4) var tile_near_counts: texture_2d<u32>;

// The ReadCounts counters of this pass and the resolve (READ_COUNTERS in src/gpu.rs): every read of
// every invocation of pvsm_tile_filter, and the bytes they fetched; the walk's reads per filter
// evaluation (the texels filtered, a diagnostic, not a pass); every read of pvsm_resolve, and its
// bytes.
const READ_COUNTER_TILE_FILTER: u32 = 10u;
const READ_COUNTER_TILE_FILTER_READ_BYTES: u32 = 11u;
const READ_COUNTER_TILE_FILTER_WALK: u32 = 12u;
const READ_COUNTER_RESOLVE: u32 = 13u;
const READ_COUNTER_RESOLVE_READ_BYTES: u32 = 14u;

// Bytes of one read (src/filter.rs's formats and buffers, checked by a test of the crate): a texel of
// the tile map, R32Float (ssm-core's LightDepthMap::FORMAT); of its pyramid, Rgba32Float
// (TILE_PYRAMID_FORMAT); of its near counts, Rgba32Uint (TILE_PYRAMID_COUNTS_FORMAT); a pixel's
// accumulated sums, a vec2<f32>; its capped flag, a u32. (A kernel record is KERNEL_RECORD_BYTES, a
// G-buffer texel GBUFFER_TEXEL_BYTES: pvsm_common.wgsl.)
const TILE_MAP_TEXEL_BYTES: u32 = 4u;
const TILE_PYRAMID_TEXEL_BYTES: u32 = 16u;
const TILE_PYRAMID_COUNTS_TEXEL_BYTES: u32 = 16u;
const ACCUMULATED_BYTES: u32 = 8u;
const CAPPED_BYTES: u32 = 4u;

// Smallest half-axis of a filter, in texels of the tile (see texel_filter).
const MIN_HALF_TEXELS: f32 = 1e-3;

// The most steps (loop iterations: texels and columns, or blocks and climbs) of one filter's walk over
// one tile: a bound on a pixel's cost whatever its filter spans, about 180² texels per-texel, and for
// the hierarchy a penumbra boundary of several thousand texels inside the filter (each boundary
// texel costs its 2×2 block's four reads and its share of the ancestors'). A walk that reaches it
// stops early, reported (pvsm_capped_pixels), never silently: the texel walk integrates what it read
// so far, the hierarchy counts each block still mixed as half lit. Half of 65,536: llvmpipe (Mesa
// 22.3) leaves a shader's loops silently after 65,535 iterations, counted together over nested loops
// and over its SIMD lanes (a loop runs while any lane needs it), so each walk is one flat loop and
// this cap comes first.
const MAX_WALK_STEPS: u32 = 32768u;

// The unit roundoff of f32 (2^-24).
const F32_ROUNDOFF: f32 = 5.9604645e-8;

// One pixel's filter h laid out in the tile's texel units (what integrate and both walks read).
struct TexelFilter {
    // The filter's centre.
    centre: vec2<f32>,
    // The columns it spans, clipped to the tile: [x_low, x_high).
    x_low: f32,
    x_high: f32,
    // Half-height of each column's box (Sec. 4.2: each one-texel-wide column of the parallelogram
    // taken as an axis-aligned box at its middle's height), and the slope of those middles.
    half_height: f32,
    slope: f32,
    // The rows any column reaches, clipped to the tile: [y_low, y_high).
    y_low: f32,
    y_high: f32,
};

// What a walk returns, in texel areas: Σ c·o, Σ c, whether it hit MAX_WALK_STEPS, the texels
// it read (each textureLoad of the tile map or of its pyramid is one: ssm-core's ReadCounts
// convention, one texel fetched) and the bytes they fetched (each its texture's texel size).
struct FilterSums {
    visible: f32,
    covered: f32,
    capped: bool,
    reads: u32,
    bytes: u32,
};

// Shadow-map coordinates of texel position `texel` of the tile (a texel's centre is its index + 0.5).
fn tile_uv(texel: vec2<f32>, scale: vec2<f32>) -> vec2<f32> {
    return tile.uv_min + texel / scale;
}

// The filter (u, v_height) centred on `centre` (shadow-map coordinates) in this tile's texels;
// x_low >= x_high where it misses the tile. A filter narrower than a texel weighs the texels under
// it by area (Eq. 2), which tends to the texel under the point as it shrinks: the hard shadow test.
// Its half-axes are floored at MIN_HALF_TEXELS only so that a filter of zero size (a point light
// with antialiasing off) is that test, not an empty integral; a floor of half a texel made it a
// one-texel box centred on the point, which blurs a hard edge over a texel. Point samples (classic
// PCF) need a texel centre inside: a filter at least one texel wide.
fn texel_filter(centre: vec2<f32>, u: vec2<f32>, v_height: f32, scale: vec2<f32>) -> TexelFilter {
    let floor_half = select(MIN_HALF_TEXELS, 0.5, settings.point_samples != 0u);
    let c = (centre - tile.uv_min) * scale;
    let ux = max(abs(u.x) * scale.x, floor_half);
    let uy = select(u.y, -u.y, u.x < 0.0) * scale.y;
    let vy = max(v_height * scale.y, floor_half);
    let reach_y = abs(uy) + vy;
    var shape: TexelFilter;
    shape.centre = c;
    shape.x_low = max(c.x - ux, 0.0);
    shape.x_high = min(c.x + ux, tile.size.x);
    shape.half_height = vy;
    shape.slope = select(0.0, uy / ux, ux > 1e-6);
    shape.y_low = max(c.y - reach_y, 0.0);
    shape.y_high = min(c.y + reach_y, tile.size.y);
    if (shape.y_low >= shape.y_high) {
        shape.x_high = shape.x_low;
    }
    return shape;
}

// The height of the rows [j0, j1) inside the column box centred at height `y_centre`.
fn column_height(shape: TexelFilter, y_centre: f32, j0: f32, j1: f32) -> f32 {
    return max(0.0, min(j1, y_centre + shape.half_height) - max(j0, y_centre - shape.half_height));
}

// The covered area of the one column `column` of the filter within rows [j0, j1): the column's
// part inside [x_low, x_high) times its box's height there, the box at the middle of that part
// (as the per-texel walk weighs it).
fn partial_column_area(shape: TexelFilter, column: f32, j0: f32, j1: f32) -> f32 {
    let left = max(column, shape.x_low);
    let right = min(column + 1.0, shape.x_high);
    if (right <= left) {
        return 0.0;
    }
    let y_centre = shape.centre.y + (0.5 * (left + right) - shape.centre.x) * shape.slope;
    return (right - left) * column_height(shape, y_centre, j0, j1);
}

// The covered area of the whole columns [lo, hi) (each inside [x_low, x_high)) within rows [j0, j1),
// in closed form. Column i's box is centred at a + b i (a the centre's height at column 0's middle,
// b the slope), and its height in the rows is column_height, a trapezoid in the box's centre, linear
// between the four breakpoints j0 ± half_height, j1 ± half_height. The columns whose centres lie
// between two consecutive breakpoints form a run of integers, over which the sum of a linear
// function is the run's length times its value at the run's mean. Outside the outer two breakpoints
// the height is 0: three runs.
fn whole_columns_area(shape: TexelFilter, lo: f32, hi: f32, j0: f32, j1: f32) -> f32 {
    if (hi <= lo) {
        return 0.0;
    }
    let b = shape.slope;
    let a = shape.centre.y + (0.5 - shape.centre.x) * b;
    if (b == 0.0) {
        return (hi - lo) * column_height(shape, a, j0, j1);
    }
    let h = shape.half_height;
    // The first column at or past each breakpoint's crossing.
    let crossings = clamp(ceil((vec4<f32>(j0 - h, j0 + h, j1 - h, j1 + h) - a) / b), vec4<f32>(lo), vec4<f32>(hi));
    // In order: a five-comparison sorting network.
    let low_pair = min(crossings.xz, crossings.yw);
    let high_pair = max(crossings.xz, crossings.yw);
    let first = min(low_pair.x, low_pair.y);
    let last = max(high_pair.x, high_pair.y);
    let middle_a = max(low_pair.x, low_pair.y);
    let middle_b = min(high_pair.x, high_pair.y);
    let cuts = vec4<f32>(first, min(middle_a, middle_b), max(middle_a, middle_b), last);
    var bounds = array<f32, 4>(cuts.x, cuts.y, cuts.z, cuts.w);
    var area = 0.0;
    for (var k = 0u; k < 3u; k++) {
        let start = bounds[k];
        let end = bounds[k + 1u];
        if (end > start) {
            area += (end - start) * column_height(shape, a + b * 0.5 * (start + end - 1.0), j0, j1);
        }
    }
    return area;
}

// The filter's covered area in the block of texels [lo, hi) (columns x, rows y): Eq. 2's Σ c over
// the block's texels, the same weights as the per-texel walk's, in a bounded number of steps.
fn block_area(shape: TexelFilter, lo: vec2<f32>, hi: vec2<f32>) -> f32 {
    let first_column = floor(shape.x_low);
    let last_column = floor(shape.x_high);
    let first_whole = ceil(shape.x_low);
    var area = whole_columns_area(shape, max(lo.x, first_whole), min(hi.x, last_column), lo.y, hi.y);
    // The partial columns at the filter's ends (one column if both ends fall in it).
    let first_partial = shape.x_low > first_column;
    if (first_partial && first_column >= lo.x && first_column < hi.x) {
        area += partial_column_area(shape, first_column, lo.y, hi.y);
    }
    let last_partial = shape.x_high > last_column && (last_column > first_column || !first_partial);
    if (last_partial && last_column >= lo.x && last_column < hi.x) {
        area += partial_column_area(shape, last_column, lo.y, hi.y);
    }
    return area;
}

// The height of the middle of whole column `column`'s box, as the per-texel walk computes it (its
// column's left and right ends are column and column + 1 there).
fn column_centre(shape: TexelFilter, column: f32) -> f32 {
    return shape.centre.y + (0.5 * (column + (column + 1.0)) - shape.centre.x) * shape.slope;
}

// Whether the block of texels [lo, hi) lies entirely inside the filter, so that each of its texels
// weighs its whole area (1 texel) in the per-texel walk: whole columns inside [x_low, x_high) (the
// walk's width min(c + 1, x_high) - max(c, x_low) is then exactly 1), each column's box reaching
// past the block's rows (the walk's height exactly 1). The boxes' centres move monotonically with
// the column (each f32 operation of column_centre is monotone), so the first and last columns'
// bound the rest; the slack, 8 roundoffs of the terms' magnitudes, covers a compiler fusing the
// per-texel walk's evaluation differently. A block this test refuses descends (exact either way).
fn inside_filter(shape: TexelFilter, lo: vec2<f32>, hi: vec2<f32>) -> bool {
    if (lo.x < shape.x_low || hi.x > shape.x_high) {
        return false;
    }
    let first = column_centre(shape, lo.x);
    let last = column_centre(shape, hi.x - 1.0);
    let magnitude = abs(shape.centre.y) + abs(shape.slope) * (hi.x + abs(shape.centre.x) + 1.0) + shape.half_height + hi.y;
    let slack = 8.0 * F32_ROUNDOFF * magnitude;
    return max(first, last) - shape.half_height <= lo.y - slack && min(first, last) + shape.half_height >= hi.y + slack;
}

// Bounds (lowest, highest) of what tap_plane_depth(receiver, uv) returns at the texel centres of the
// rectangle [uv_low, uv_high] (shadow-map coordinates of its first and last centres), as f32
// evaluates it, so that a block classified from them is classified as each of its texels would be.
// The plane's depth along a tap's ray is numerator / (c.x + c.y u + c.z v): the denominator is
// affine in uv, so its extremes over the rectangle are at its corners, and where it keeps one sign
// (and is no nearer 0 than tap_plane_depth's 1e-6) the depth is monotone in it. Slack: the f32
// evaluation of the denominator at a texel and at a corner each err by a few roundoffs of the sum of
// the terms' magnitudes (uv's own rounding included), so the denominator's range is widened by 8 of
// them, and the quotient by 4 relative roundoffs. Where the denominator can come within 1e-6 of 0 or
// change sign, a texel may get the fallback or a depth arbitrarily far: the bounds are then
// (min(fallback, 0), NO_SURFACE), with which no block but one with no surface at all (lit whatever the
// receiver) is decided without descending.
fn compared_bounds(receiver: TapPlane, uv_low: vec2<f32>, uv_high: vec2<f32>) -> vec2<f32> {
    let c = receiver.coefficients;
    let along_u = vec2<f32>(c.y * uv_low.x, c.y * uv_high.x);
    let along_v = vec2<f32>(c.z * uv_low.y, c.z * uv_high.y);
    let lowest = c.x + min(along_u.x, along_u.y) + min(along_v.x, along_v.y);
    let highest = c.x + max(along_u.x, along_u.y) + max(along_v.x, along_v.y);
    let magnitude = abs(c.x) + max(abs(along_u.x), abs(along_u.y)) + max(abs(along_v.x), abs(along_v.y));
    let slack = 8.0 * F32_ROUNDOFF * magnitude;
    let denominator = vec2<f32>(lowest - slack, highest + slack);
    let n = receiver.numerator;
    let positive = denominator.x >= 1e-6 && n > 0.0;
    let negative = denominator.y <= -1e-6 && n < 0.0;
    if (!(positive || negative)) {
        return vec2<f32>(min(receiver.fallback, 0.0), NO_SURFACE);
    }
    let ends = vec2<f32>(n / denominator.x, n / denominator.y);
    let relative = 4.0 * F32_ROUNDOFF;
    return vec2<f32>(min(ends.x, ends.y) * (1.0 - relative), max(ends.x, ends.y) * (1.0 + relative));
}

// Eq. 2 texel by texel: every texel under the filter read and weighed (filter_walk = texels), or with
// `stride` > 1 every stride-th texel, each standing for a stride×stride block (filter_texels =
// predicted, not the paper's); with point_samples, classic PCF. At most MAX_WALK_STEPS texels.
fn walk_texels(shape: TexelFilter, receiver: TapPlane, scale: vec2<f32>, stride: vec2<f32>) -> FilterSums {
    var sums = FilterSums(0.0, 0.0, false, 0u, 0u);
    var steps = 0u;
    var column = floor(shape.x_low / stride.x) * stride.x;
    // One loop over columns and their rows, a texel or a new column per iteration (see
    // MAX_WALK_STEPS: llvmpipe counts the iterations of nested loops together, over its SIMD lanes).
    var in_column = false;
    var row = 0.0;
    var width = 0.0;
    var y_centre = 0.0;
    var bottom = 0.0;
    var top = 0.0;
    loop {
        if (column >= shape.x_high) {
            break;
        }
        if (steps >= MAX_WALK_STEPS) {
            sums.capped = true;
            break;
        }
        steps += 1u;
        if (!in_column) {
            // The next column of h, taken as an axis-aligned box at its middle's height.
            let left = max(column, shape.x_low);
            let right = min(column + stride.x, shape.x_high);
            width = right - left;
            y_centre = shape.centre.y + (0.5 * (left + right) - shape.centre.x) * shape.slope;
            bottom = max(y_centre - shape.half_height, 0.0);
            top = min(y_centre + shape.half_height, tile.size.y);
            row = floor(bottom / stride.y) * stride.y;
            in_column = width > 0.0;
            if (!in_column) {
                column += stride.x;
            }
            continue;
        }
        if (row >= top) {
            in_column = false;
            column += stride.x;
            continue;
        }
        var height = min(row + stride.y, top) - max(row, bottom);
        let texel = vec2<f32>(column, row) + 0.5 * stride;
        if (settings.point_samples != 0u) {
            // Classic PCF: the whole texel when its centre is inside the filter, else nothing.
            let inside = texel.x >= shape.x_low && texel.x < shape.x_high && texel.y >= y_centre - shape.half_height
                && texel.y < y_centre + shape.half_height;
            height = select(0.0, stride.y, inside);
        }
        if (height > 0.0) {
            let z = textureLoad(tile_map, vec2<i32>(min(texel, tile.size - vec2<f32>(0.5))), 0).x;
            sums.reads += 1u;
            sums.bytes += TILE_MAP_TEXEL_BYTES;
            let compared = tap_plane_depth(receiver, tile_uv(texel, scale));
            let area = select(width, stride.x, settings.point_samples != 0u) * height;
            // o(t) = 1 when the receiver is no farther than the texel's occluder (Eq. 2); the
            // tile map's depths carry the depth bias already.
            sums.visible += select(0.0, area, compared <= z);
            sums.covered += area;
        }
        row += stride.y;
    }
    return sums;
}

// The child `child` at `level` of a two-layer block around the receiver that straddles the
// filter's edge, `near` of its texels in the near cluster (occluding; the others lit): (lit area,
// covered area, 0) where it is settled here (inside the filter: its far texels, each weighing one;
// on the edge, all of one cluster: its covered area lit or not; a texel: its covered area if far),
// (0, 0, 1) where it must be walked (on the edge, texels of both clusters: two layers around the
// receiver itself, since its parent's cut lies in its gap), zeros where the filter misses it.
fn settle_child(shape: TexelFilter, child: vec2<u32>, level: u32, near: u32) -> vec3<f32> {
    let lo = vec2<f32>(child << vec2<u32>(level));
    let hi = min(vec2<f32>((child + 1u) << vec2<u32>(level)), tile.size);
    if (any(lo >= tile.size)) {
        return vec3<f32>(0.0);
    }
    let area = block_area(shape, lo, hi);
    if (area <= 0.0) {
        return vec3<f32>(0.0);
    }
    if (level == 0u) {
        return vec3<f32>(select(area, 0.0, near != 0u), area, 0.0);
    }
    let texels = u32(hi.x - lo.x) * u32(hi.y - lo.y);
    if (inside_filter(shape, lo, hi)) {
        return vec3<f32>(f32(texels - near), area, 0.0);
    }
    // On the edge: wholly far (lit) or wholly near (occluding), or walked.
    if (near == 0u) {
        return vec3<f32>(area, area, 0.0);
    }
    if (near == texels) {
        return vec3<f32>(0.0, area, 0.0);
    }
    return vec3<f32>(0.0, 0.0, 1.0);
}

// Eq. 2 over the tile's two-layer min/max pyramid, top-down (filter_walk = hierarchy): from the (at
// most 2×2) blocks of the coarsest level that hold the filter's rows and columns, a block the
// filter does not cover is skipped unread; one whose nearest depth is no nearer than the receiver's
// farthest compared depth over it (every texel lit, o = 1) or whose farthest depth is nearer than
// the receiver's nearest (every texel occluding, o = 0) adds its covered area (block_area) at once;
// one of two layers whose near layer is in front of every compared depth and whose far layer is
// behind them, lying inside the filter (inside_filter: every texel weighs 1), adds its covered
// area and, as lit area, its far layer's texels (its near counts, one more read); such a block
// straddling the filter's edge reads its near counts too and settles so (settle_child) each child
// inside the filter, each on the edge holding one cluster and, at level 1, each texel, descending
// only to the children on the edge holding both clusters, whose near counts alone are then read
// (`settled`, `pending`); another block descends to its four children; a texel is tested as the
// per-texel walk tests it. The same weights and the same tests: the per-texel sum, in another
// order (every texel of a two-layer block's far cluster is behind every compared depth, so lit,
// every texel of the near cluster in front, so occluding, whatever the level it is settled at).
// The walk is depth-first and needs no stack: after a block, the next is its next sibling, or its
// parent's (climbing while it is the fourth child), so that the state is one block and its level,
// and per level which children of the block last descended from are walked.
fn walk_hierarchy(shape: TexelFilter, receiver: TapPlane, scale: vec2<f32>) -> FilterSums {
    var sums = FilterSums(0.0, 0.0, false, 0u, 0u);
    var steps = 0u;
    let first = vec2<u32>(vec2<f32>(floor(shape.x_low), floor(shape.y_low)));
    let last = vec2<u32>(vec2<f32>(ceil(shape.x_high), ceil(shape.y_high))) - 1u;
    // The finest level at which the filter's texels span at most two blocks along each axis (at
    // most 14 for tiles of 16384 texels).
    var top_level = 0u;
    while (top_level < 15u && any((last >> vec2<u32>(top_level)) - (first >> vec2<u32>(top_level)) > vec2<u32>(1u))) {
        top_level += 1u;
    }
    let low = first >> vec2<u32>(top_level);
    let high = last >> vec2<u32>(top_level);
    let pyramid_levels = textureNumLevels(tile_pyramid);
    let pyramid_base = textureDimensions(tile_pyramid, 0);
    // One loop, a block or a climb to its parent per iteration (see MAX_WALK_STEPS: llvmpipe counts
    // the iterations of nested loops together, over its SIMD lanes). `next` set: the current block
    // is done, move on to its next sibling or its parent's; at the top level, to the next start block.
    var start = 0u;
    var block = low;
    var level = top_level;
    var next = false;
    // Bit l: the blocks at level l now visited are children of a straddling two-layer block, which
    // settled those inside the filter (set or cleared at each descent to level l; top_level's never).
    var settled = 0u;
    // Per level: which of those children (bit dx + 2 dy) are walked.
    var pending: array<u32, 16>;
    loop {
        if (steps >= MAX_WALK_STEPS + 256u) {
            // Past the cap no block descends, and the siblings left (at most three per level) end the
            // walk well within this bound, which only guards it.
            sums.capped = true;
            break;
        }
        steps += 1u;
        if (next) {
            if (level >= top_level) {
                start += 1u;
                if (start >= 4u) {
                    break;
                }
                block = low + vec2<u32>(start & 1u, start >> 1u);
                next = any(block > high);
            } else if ((block.x & 1u) == 0u) {
                block.x += 1u;
                next = false;
            } else if ((block.y & 1u) == 0u) {
                block = vec2<u32>(block.x - 1u, block.y + 1u);
                next = false;
            } else {
                block = block >> vec2<u32>(1u);
                level += 1u;
            }
            continue;
        }
        next = true;
        let lo = vec2<f32>(block << vec2<u32>(level));
        let hi = min(vec2<f32>((block + 1u) << vec2<u32>(level)), tile.size);
        let area = block_area(shape, lo, hi);
        if (area <= 0.0) {
            continue;
        }
        // A child of a two-layer block around the receiver on the filter's edge: that block
        // settled it unless its bit in `pending` is set (it straddles the edge and holds texels of
        // both clusters); then it is two layers around the receiver too (the parent's cut lies in
        // its gap), and only its near counts are read.
        var settling = false;
        if ((settled & (1u << level)) != 0u) {
            let child = (block.x & 1u) + 2u * (block.y & 1u);
            if ((pending[level] & (1u << child)) == 0u) {
                continue;
            }
            settling = true;
        }
        // (nearest, farthest) depth of the block's texels, and the bounds of what they are compared
        // with; a texel is a block whose bounds are its own test's values, never mixed. Loads are
        // clamped to the texture: a real walk never leaves it. (A mip's size from the base's:
        // textureDimensions with a level returns the base level's size on llvmpipe.)
        var pyramid_texel = vec2<i32>(0);
        var mip = 0u;
        if (level > 0u) {
            mip = min(level - 1u, pyramid_levels - 1u);
            let mip_size = max(pyramid_base >> vec2<u32>(mip), vec2<u32>(1u));
            pyramid_texel = vec2<i32>(min(block, mip_size - 1u));
        }
        // Its near counts per child, where it is two layers around the receiver and straddles the
        // filter's edge: its children are settled below.
        var quadrants = vec4<u32>(0u);
        var straddling = false;
        if (settling) {
            if (steps >= MAX_WALK_STEPS) {
                // The cap (reported): the block counted half lit rather than walked further.
                sums.capped = true;
                sums.visible += 0.5 * area;
                sums.covered += area;
                continue;
            }
            quadrants = textureLoad(tile_near_counts, pyramid_texel, i32(mip));
            sums.reads += 1u;
            sums.bytes += TILE_PYRAMID_COUNTS_TEXEL_BYTES;
            straddling = true;
        } else {
            var depths: vec4<f32>;
            var compared: vec2<f32>;
            if (level == 0u) {
                let z = textureLoad(tile_map, min(vec2<i32>(block), vec2<i32>(tile.size) - 1), 0).x;
                sums.reads += 1u;
                sums.bytes += TILE_MAP_TEXEL_BYTES;
                // A texel is one layer (near_max = far_min).
                depths = vec4<f32>(z);
                compared = vec2<f32>(tap_plane_depth(receiver, tile_uv(lo + 0.5, scale)));
            } else {
                depths = textureLoad(tile_pyramid, pyramid_texel, i32(mip));
                sums.reads += 1u;
                sums.bytes += TILE_PYRAMID_TEXEL_BYTES;
                compared = compared_bounds(receiver, tile_uv(lo + 0.5, scale), tile_uv(hi - 0.5, scale));
            }
            if (compared.y <= depths.x) {
                // Every texel at or behind the receiver: lit (o = 1, Eq. 2).
                sums.visible += area;
                sums.covered += area;
            } else if (compared.x > depths.y) {
                // Every texel in front of the receiver: occluding.
                sums.covered += area;
            } else if (depths.z < depths.w && compared.x > depths.z && compared.y <= depths.w
                && (inside_filter(shape, lo, hi) || steps < MAX_WALK_STEPS)) {
                // Two layers, the receiver between them: the near cluster's texels occlude, the far
                // cluster's are lit. Its near counts per child: one more read.
                quadrants = textureLoad(tile_near_counts, pyramid_texel, i32(mip));
                sums.reads += 1u;
                sums.bytes += TILE_PYRAMID_COUNTS_TEXEL_BYTES;
                if (inside_filter(shape, lo, hi)) {
                    // Inside the filter each texel weighs one, so the lit area is the far cluster's
                    // texel count.
                    let texels = u32(hi.x - lo.x) * u32(hi.y - lo.y);
                    sums.visible += f32(texels - (quadrants.x + quadrants.y + quadrants.z + quadrants.w));
                    sums.covered += area;
                } else {
                    straddling = true;
                }
            } else if (steps >= MAX_WALK_STEPS) {
                // The cap (reported): the block counted half lit rather than walked further.
                sums.capped = true;
                sums.visible += 0.5 * area;
                sums.covered += area;
            } else {
                // Mixed: its first child next.
                level -= 1u;
                block = 2u * block;
                next = false;
                settled &= ~(1u << level);
            }
        }
        if (straddling) {
            // On the filter's edge: each child inside the filter, or of one cluster, or at level 1
            // each texel, is settled here from its near count; the others descend. Unrolled, not a
            // loop: llvmpipe's loop limit (MAX_WALK_STEPS) counts inner loops' iterations with the
            // walk's (a loop here made the walk end early, unflagged).
            let first = settle_child(shape, 2u * block, level - 1u, quadrants.x);
            let second = settle_child(shape, 2u * block + vec2<u32>(1u, 0u), level - 1u, quadrants.y);
            let third = settle_child(shape, 2u * block + vec2<u32>(0u, 1u), level - 1u, quadrants.z);
            let fourth = settle_child(shape, 2u * block + vec2<u32>(1u, 1u), level - 1u, quadrants.w);
            sums.visible += first.x + second.x + third.x + fourth.x;
            sums.covered += first.y + second.y + third.y + fourth.y;
            let walked = u32(first.z) | (u32(second.z) << 1u) | (u32(third.z) << 2u) | (u32(fourth.z) << 3u);
            if (walked != 0u) {
                level -= 1u;
                block = 2u * block;
                next = false;
                settled |= 1u << level;
                pending[level] = walked;
            }
        }
    }
    return sums;
}

// Eq. 2 for the filter (u, v_height) centred on `centre` (shadow-map coordinates) over this tile,
// for a receiver at light depth `depth` with tangent plane (`position`, `normal`): (Σ c·o, Σ c) in
// shadow-map area, whether the walk was capped, and the texels it read. With
// settings.predicted_stride, a tile finer than the pixel's predicted texel size `predicted` (a
// neighbour in the tile needed more) is read at every k-th texel, k the ratio: the prediction says
// that many texels suffice, and a pixel's cost stays about ρ² whatever the tile's resolution.
fn integrate(centre: vec2<f32>, u: vec2<f32>, v_height: f32, depth: f32, position: vec3<f32>, normal: vec3<f32>, predicted: vec2<f32>) -> FilterSums {
    let scale = tile.size / (tile.uv_max - tile.uv_min);
    let shape = texel_filter(centre, u, v_height, scale);
    if (shape.x_low >= shape.x_high) {
        return FilterSums(0.0, 0.0, false, 0u, 0u);
    }
    // What each texel is compared with (the settings' receiver model), prepared once.
    let receiver = receiver_tap_plane(frame, position, normal, depth, settings.receiver_plane != 0u);
    let stride = max(vec2<f32>(1.0), select(vec2<f32>(1.0), floor(predicted * scale), settings.predicted_stride != 0u));
    var sums: FilterSums;
    if (settings.texel_walk != 0u || settings.point_samples != 0u || any(stride > vec2<f32>(1.0))) {
        sums = walk_texels(shape, receiver, scale, stride);
    } else {
        sums = walk_hierarchy(shape, receiver, scale);
    }
    // In shadow-map coordinates, not texels: tiles of different resolutions merge by true area.
    let texel_area = 1.0 / (scale.x * scale.y);
    sums.visible *= texel_area;
    sums.covered *= texel_area;
    return sums;
}

// Records one invocation's texel reads (with COUNT_READS, the settings' count_reads), one per
// textureLoad or per element of a per-pixel storage array (ReadCounts' convention), and the bytes
// they fetched: every invocation reads its pixel's kernel record (step 3's output); one that
// filters (`filtered`) also the G-buffer's two texels, its accumulated sums (the tiles' before it)
// and the walk's `walk_reads` (of `walk_bytes`), which the walk counter keeps apart
// (pvsm_texels_filtered).
fn record_filter_reads(pixel: vec2<u32>, walk_reads: u32, walk_bytes: u32, filtered: bool) {
    if (COUNT_READS) {
        let word = read_count_word(READ_COUNTER_TILE_FILTER, vec2<i32>(pixel));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], select(1u, 4u + walk_reads, filtered));
        let filtered_bytes = KERNEL_RECORD_BYTES + 2u * GBUFFER_TEXEL_BYTES + ACCUMULATED_BYTES + walk_bytes;
        let bytes_word = read_count_word(READ_COUNTER_TILE_FILTER_READ_BYTES, vec2<i32>(pixel));
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], select(KERNEL_RECORD_BYTES, filtered_bytes, filtered));
        if (filtered) {
            let walk_word = read_count_word(READ_COUNTER_TILE_FILTER_WALK, vec2<i32>(pixel));
            atomicAdd(&read_counts[walk_word], 1u);
            atomicAdd(&read_counts[walk_word + 1u], walk_reads);
        }
    }
}

@compute @workgroup_size(8, 8)
fn pvsm_tile_filter(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.viewport.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let index = id.y * size.x + id.x;
    let kernel = kernels[index];
    if (kernel.flags != KERNEL_ACTIVE) {
        record_filter_reads(id.xy, 0u, 0u, false);
        return;
    }
    let point = screen_point_at(vec2<i32>(id.xy));
    // The normal offset, in this tile's texels at the pixel's depth (a coarser predicted texel would
    // move the point past nearby occluders), within the kernel's bound. A tile's texels can be far
    // longer along one axis than the other (Eq. 5 per axis). Compared with the receiver's tangent
    // plane, a texel's depth differs from the plane's only by the surface's curvature, and the
    // finer side is offset enough; an offset of the longer side moved the lookup across narrow
    // penumbrae along the finer axis (thin bars' shadows shifted by half their width). Compared with
    // the receiver's own depth, the longer side's slope needs the longer side's offset.
    let tile_texel = 2.0 * kernel.depth * frame.projection.xy * (tile.uv_max - tile.uv_min) / tile.size;
    let world_texel = select(max(tile_texel.x, tile_texel.y), min(tile_texel.x, tile_texel.y), settings.receiver_plane != 0u);
    let offset = min(settings.normal_offset * world_texel, kernel.offset);
    let k = max(settings.supersampling, 1u);
    if (k == 1u) {
        let lookup = offset_point(point.position, point.normal, offset);
        let uvd = light_uv_depth(frame, lookup);
        let sums = integrate(uvd.xy, kernel.u_axis, kernel.v_height, uvd.z, lookup, point.normal, kernel.texel);
        accumulated[index] += vec2<f32>(sums.visible, sums.covered);
        if (sums.capped) {
            capped[index] = 1u;
        }
        record_filter_reads(id.xy, sums.reads, sums.bytes, true);
        return;
    }
    // Screen-space supersampling (Fig. 11's comparison): k×k points of the pixel's tangent plane,
    // each filtered on its own; their sums add up, as their filters have the same area.
    var sum = vec2<f32>(0.0);
    var any_capped = false;
    var reads = 0u;
    var bytes = 0u;
    for (var j = 0u; j < k; j++) {
        for (var i = 0u; i < k; i++) {
            let pixel = vec2<f32>(id.xy) + (vec2<f32>(f32(i), f32(j)) + 0.5) / f32(k);
            let hit = tangent_point(point.position, point.normal, pixel);
            if (hit.w == 0.0 || !in_front_of_light(frame, hit.xyz)) {
                continue;
            }
            let sub_lookup = offset_point(hit.xyz, point.normal, offset);
            let uvd = light_uv_depth(frame, sub_lookup);
            let sums = integrate(uvd.xy, kernel.u_axis, kernel.v_height, uvd.z, sub_lookup, point.normal, kernel.texel);
            sum += vec2<f32>(sums.visible, sums.covered);
            any_capped = any_capped || sums.capped;
            reads += sums.reads;
            bytes += sums.bytes;
        }
    }
    accumulated[index] += sum;
    if (any_capped) {
        capped[index] = 1u;
    }
    record_filter_reads(id.xy, reads, bytes, true);
}

// The final visibility (Sec. 5.2's merge: V = Σ V·A / Σ A) into the framework's target.
@group(3) @binding(2) var visibility: texture_storage_2d<r32float, read_write>;

@compute @workgroup_size(8, 8)
fn pvsm_resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(camera.viewport.xy);
    if (any(id.xy >= size)) {
        return;
    }
    let index = id.y * size.x + id.x;
    let kernel = kernels[index];
    var value = 1.0;
    if (COUNT_READS) {
        // The pixel's kernel record, and a filtered pixel's sums and capped flag.
        let filtered = kernel.flags == KERNEL_ACTIVE;
        let word = read_count_word(READ_COUNTER_RESOLVE, vec2<i32>(id.xy));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], select(1u, 3u, filtered));
        let bytes_word = read_count_word(READ_COUNTER_RESOLVE_READ_BYTES, vec2<i32>(id.xy));
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], select(KERNEL_RECORD_BYTES, KERNEL_RECORD_BYTES + ACCUMULATED_BYTES + CAPPED_BYTES, filtered));
    }
    if (kernel.flags == KERNEL_DARK) {
        value = 0.0;
    } else if (kernel.flags == KERNEL_ACTIVE) {
        let sums = accumulated[index];
        // No tile under the shape. Every grid cell a filter can read asks for a tile, so this is a
        // lookup point that the normal offset moved into a cell no pixel asked for, or one outside
        // the light frame. Read as lit, and counted (pvsm_uncovered_pixels).
        value = select(1.0, clamp(sums.x / sums.y, 0.0, 1.0), sums.y > 0.0);
        if (sums.y <= 0.0) {
            atomicAdd(&counters[COUNTER_UNCOVERED], 1u);
        }
        if (capped[index] != 0u) {
            atomicAdd(&counters[COUNTER_CAPPED], 1u);
        }
    }
    textureStore(visibility, vec2<i32>(id.xy), vec4<f32>(value));
}
