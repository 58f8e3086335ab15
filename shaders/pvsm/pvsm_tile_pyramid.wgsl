// PVSM step 8's hierarchy: one level of the min/max depth pyramid of a tile's map, which the filter
// walks top-down (pvsm_filter.wgsl's walk_hierarchy). Level l's texel (i, j) holds the nearest and
// farthest depth of the tile map's texels [2^l i, 2^l (i + 1)) × [2^l j, 2^l (j + 1)) inside the tile's
// region (the top-left tile.size texels of the map), from the four texels of level l - 1 below it:
// a block whose depths all lie on one side of the receiver adds its covered area at once (Eq. 2).
// One compute pass per level, level 1 from the map itself.

// #import common/read_counts.wgsl

const NO_SURFACE: f32 = 3.40282347e38;

struct TileSettings {
    uv_min: vec2<f32>,
    uv_max: vec2<f32>,
    // Texels of the tile's map region.
    size: vec2<f32>,
    _pad0: f32,
    _pad1: f32,
};

struct PyramidLevel {
    // The level written (1 or more); its texels are in mip level - 1 of the pyramid.
    level: u32,
    // 1: the level below is the tile map (one depth per texel); 0: a pyramid level (nearest, farthest).
    from_map: u32,
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var<uniform> tile: TileSettings;
@group(1) @binding(0) var<uniform> pyramid_level: PyramidLevel;
@group(1) @binding(1) var finer: texture_2d<f32>;
@group(1) @binding(2) var coarser: texture_storage_2d<rg32float, write>;
// ReadCounts (ssm-core), with COUNT_READS: READ_COUNTER_TILE_PYRAMID (reads) and
// READ_COUNTER_TILE_PYRAMID_BYTES (bytes written).
@group(1) @binding(3) var<storage, read_write> read_counts: array<atomic<u32>>;

// The ReadCounts counters of this pass (PvsmReadCounter in src/lib.rs).
const READ_COUNTER_TILE_PYRAMID: u32 = 4u;
const READ_COUNTER_TILE_PYRAMID_BYTES: u32 = 5u;

// Texels of the region at `level`: ceil(size / 2^level) along each axis.
fn level_size(level: u32) -> vec2<u32> {
    let size = vec2<u32>(tile.size);
    let block = vec2<u32>(1u << level);
    return (size + block - 1u) / block;
}

@compute @workgroup_size(8, 8)
fn pvsm_tile_pyramid(@builtin(global_invocation_id) id: vec3<u32>) {
    let level = pyramid_level.level;
    if (any(id.xy >= level_size(level))) {
        return;
    }
    let below = level_size(level - 1u);
    var nearest = NO_SURFACE;
    var farthest = -NO_SURFACE;
    var reads = 0u;
    for (var dy = 0u; dy < 2u; dy++) {
        for (var dx = 0u; dx < 2u; dx++) {
            let texel = 2u * id.xy + vec2<u32>(dx, dy);
            // A block on the region's right or bottom edge has fewer texels below it.
            if (all(texel < below)) {
                let depths = textureLoad(finer, vec2<i32>(texel), 0);
                nearest = min(nearest, depths.x);
                farthest = max(farthest, select(depths.y, depths.x, pyramid_level.from_map != 0u));
                reads += 1u;
            }
        }
    }
    textureStore(coarser, vec2<i32>(id.xy), vec4<f32>(nearest, farthest, 0.0, 0.0));
    if (COUNT_READS) {
        // Texel reads as ReadCounts counts them (one per textureLoad); 8 bytes written per texel.
        let word = read_count_word(READ_COUNTER_TILE_PYRAMID, vec2<i32>(id.xy));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
        let bytes_word = read_count_word(READ_COUNTER_TILE_PYRAMID_BYTES, vec2<i32>(id.xy));
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], 8u);
    }
}
