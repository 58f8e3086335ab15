// PVSM step 8's hierarchy: one level of the two-layer min/max depth pyramid of a tile's map, which
// the filter walks top-down (pvsm_filter.wgsl's walk_hierarchy). Level l's texel (i, j) describes
// the tile map's texels [2^l i, 2^l (i + 1)) × [2^l j, 2^l (j + 1)) inside the tile's region (the
// top-left tile.size texels of the map), from the four texels of level l - 1 below it:
// - (nearest, farthest): their depths' range. A block whose depths all lie on one side of the
//   receiver adds its covered area at once (Eq. 2).
// - (near_max, far_min) and the near counts: where near_max < far_min, the block is two layers:
//   every one of its texels is at or nearer than near_max (the near cluster) or at or farther than
//   far_min (the far cluster), split at the widest gap between its depths that the children's own
//   clusters show; a bar over a floor is two layers. The near cluster's texels are counted per
//   child (quadrant): (x, y, z, w) for children (0, 0), (1, 0), (0, 1), (1, 1); their sum is the
//   near count. A block lying entirely inside a filter (every texel weighing its whole area) whose
//   receiver is behind the near cluster and in front of the far one adds its lit area, its far
//   texels, at once; one straddling the filter's edge settles so each child inside the filter,
//   and at level 1 each texel, from its quadrant's count. Otherwise (no gap: one layer) near_max =
//   far_min = farthest and every texel counts as near.
// Exact, not estimated: each child's clusters are intervals holding a known number of texels, and
// the parent's gap is a depth interval that no child's interval enters, so the texels below it are
// counted exactly. One compute pass per level, level 1 from the map itself.

// #import common/read_counts.wgsl

// common/shadow_map.wgsl's NO_SURFACE, written out: importing that file would bring group 0's light
// frame, where this pass binds its tile.
const NO_SURFACE: f32 = 3.40282347e38;

// The tile's settings, declared once in Rust (`TileSettingsUniform`, ssm-techniques/pvsm/src/filter.rs),
// whose derive writes this struct.
// #import rust/TileSettings

// One level's settings of the tile's min/max pyramid, declared once in Rust (`TilePyramidLevelUniform`, ssm-techniques/pvsm/src/filter.rs),
// whose derive writes this struct.
// #import rust/PyramidLevel

@group(0) @binding(0) var<uniform> tile: TileSettings;
@group(1) @binding(0) var<uniform> pyramid_level: PyramidLevel;
// The level below: the tile map (depth in x), or (nearest, farthest, near_max, far_min).
@group(1) @binding(1) var finer: texture_2d<f32>;
@group(1) @binding(2) var coarser: texture_storage_2d<rgba32float, write>;
// ReadCounts (ssm-core), with COUNT_READS: READ_COUNTER_TILE_PYRAMID (reads),
// READ_COUNTER_TILE_PYRAMID_READ_BYTES (the bytes they fetched) and
// READ_COUNTER_TILE_PYRAMID_STORAGE_BYTES (bytes written).
@group(1) @binding(3) var<storage, read_write> read_counts: array<atomic<u32>>;
// The level below's near counts per quadrant (unread when it is the map), and this level's.
@group(1) @binding(4) var finer_counts: texture_2d<u32>;
@group(1) @binding(5) var coarser_counts: texture_storage_2d<rgba32uint, write>;

// The ReadCounts counters of this pass (READ_COUNTERS in src/gpu.rs).
const READ_COUNTER_TILE_PYRAMID: u32 = 7u;
const READ_COUNTER_TILE_PYRAMID_READ_BYTES: u32 = 8u;
const READ_COUNTER_TILE_PYRAMID_STORAGE_BYTES: u32 = 9u;

// Bytes of one texel read (src/filter.rs's formats, checked by a test of the crate): the tile map's
// R32Float (ssm-core's LightDepthMap::FORMAT), the pyramid's Rgba32Float (TILE_PYRAMID_FORMAT) and
// its near counts' Rgba32Uint (TILE_PYRAMID_COUNTS_FORMAT).
const TILE_MAP_TEXEL_BYTES: u32 = 4u;
const TILE_PYRAMID_TEXEL_BYTES: u32 = 16u;
const TILE_PYRAMID_COUNTS_TEXEL_BYTES: u32 = 16u;

// Texels of the region at `level`: ceil(size / 2^level) along each axis.
fn level_size(level: u32) -> vec2<u32> {
    let size = vec2<u32>(tile.size);
    let block = vec2<u32>(1u << level);
    return (size + block - 1u) / block;
}

// The region's texels in block `block` of `level` (fewer on the region's right and bottom edges).
fn block_texels(level: u32, block: vec2<u32>) -> u32 {
    let size = vec2<u32>(tile.size);
    let side = 1u << level;
    let start = min(block * side, size);
    let span = min(size - start, vec2<u32>(side));
    return span.x * span.y;
}

@compute @workgroup_size(8, 8)
fn pvsm_tile_pyramid(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = pyramid_level.level;
    if (any(id.xy >= level_size(level))) {
        return;
    }
    let below = level_size(level - 1u);
    // The children's depth intervals, [low, high] holding `texels` texels each of child `owners`
    // (dx + 2 dy): one per child, or two for a two-layer child (its near and far clusters).
    var lows: array<f32, 8>;
    var highs: array<f32, 8>;
    var texels: array<u32, 8>;
    var owners: array<u32, 8>;
    var intervals = 0u;
    var nearest = NO_SURFACE;
    var farthest = -NO_SURFACE;
    var total = 0u;
    var reads = 0u;
    // The bytes those reads fetched: a child is a texel of the map at level 1, of the pyramid above.
    var read_bytes = 0u;
    let child_bytes = select(TILE_PYRAMID_TEXEL_BYTES, TILE_MAP_TEXEL_BYTES, pyramid_level.from_map != 0u);
    for (var dy = 0u; dy < 2u; dy++) {
        for (var dx = 0u; dx < 2u; dx++) {
            let texel = 2u * id.xy + vec2<u32>(dx, dy);
            // A block on the region's right or bottom edge has fewer texels below it.
            if (!all(texel < below)) {
                continue;
            }
            let child = textureLoad(finer, vec2<i32>(texel), 0);
            reads += 1u;
            read_bytes += child_bytes;
            let owner = dx + 2u * dy;
            owners[intervals] = owner;
            owners[intervals + 1u] = owner;
            if (pyramid_level.from_map != 0u) {
                lows[intervals] = child.x;
                highs[intervals] = child.x;
                texels[intervals] = 1u;
                intervals += 1u;
                nearest = min(nearest, child.x);
                farthest = max(farthest, child.x);
                total += 1u;
                continue;
            }
            let child_texels = block_texels(level - 1u, texel);
            nearest = min(nearest, child.x);
            farthest = max(farthest, child.y);
            total += child_texels;
            if (child.z < child.w) {
                let quadrants = textureLoad(finer_counts, vec2<i32>(texel), 0);
                reads += 1u;
                read_bytes += TILE_PYRAMID_COUNTS_TEXEL_BYTES;
                let near_count = quadrants.x + quadrants.y + quadrants.z + quadrants.w;
                lows[intervals] = child.x;
                highs[intervals] = child.z;
                texels[intervals] = near_count;
                lows[intervals + 1u] = child.w;
                highs[intervals + 1u] = child.y;
                texels[intervals + 1u] = child_texels - near_count;
                intervals += 2u;
            } else {
                lows[intervals] = child.x;
                highs[intervals] = child.y;
                texels[intervals] = child_texels;
                intervals += 1u;
            }
        }
    }
    // The widest gap: an interval's top `cut` such that every interval lies at or below it or
    // starts past it, to the lowest start past it. The texels at or below it are the near cluster.
    var near_max = farthest;
    var far_min = farthest;
    var widest = 0.0;
    for (var k = 0u; k < intervals; k++) {
        let cut = highs[k];
        var next = NO_SURFACE;
        var above = false;
        var splits = true;
        for (var j = 0u; j < intervals; j++) {
            if (lows[j] > cut) {
                next = select(lows[j], min(next, lows[j]), above);
                above = true;
            } else if (highs[j] > cut) {
                splits = false;
            }
        }
        if (splits && above && next - cut > widest) {
            widest = next - cut;
            near_max = cut;
            far_min = next;
        }
    }
    // Each child's texels in the near cluster: its intervals at or below the cut (every interval
    // lies wholly on one side of it); with no gap, the cut is the farthest depth and all count.
    var quadrants = vec4<u32>(0u);
    for (var k = 0u; k < intervals; k++) {
        if (highs[k] <= near_max) {
            quadrants[owners[k]] += texels[k];
        }
    }
    textureStore(coarser, vec2<i32>(id.xy), vec4<f32>(nearest, farthest, near_max, far_min));
    textureStore(coarser_counts, vec2<i32>(id.xy), quadrants);
    if (COUNT_READS) {
        // Texel reads as ReadCounts counts them (one per textureLoad: a child's depths, and its
        // near counts where it is two layers) and their bytes; 32 bytes written per texel (16 + 16).
        let word = read_count_word(READ_COUNTER_TILE_PYRAMID, vec2<i32>(id.xy));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
        let read_bytes_word = read_count_word(READ_COUNTER_TILE_PYRAMID_READ_BYTES, vec2<i32>(id.xy));
        atomicAdd(&read_counts[read_bytes_word], 1u);
        atomicAdd(&read_counts[read_bytes_word + 1u], read_bytes);
        let bytes_word = read_count_word(READ_COUNTER_TILE_PYRAMID_STORAGE_BYTES, vec2<i32>(id.xy));
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], 32u);
    }
}
