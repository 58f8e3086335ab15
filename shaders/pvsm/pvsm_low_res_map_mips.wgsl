// PVSM step 2, continued: the minimum-depth mip chain of the conservative low-resolution map.
// Each texel of level l + 1 keeps the nearest depth of its four texels of level l, so that the
// blocker search can look at every texel of its region at a level where the region is a few
// texels wide, and still see every occluder the conservative map holds (Sec. 5.2: a pixel with
// no occluder there is fully lit, and skipped).

// #import common/read_counts.wgsl

@group(0) @binding(0) var finer: texture_2d<f32>;
@group(0) @binding(1) var coarser: texture_storage_2d<r32float, write>;
// ReadCounts (ssm-core), with COUNT_READS: READ_COUNTER_LOW_RES_MIPS (texel reads) and
// READ_COUNTER_LOW_RES_MIPS_READ_BYTES (the bytes they fetched).
@group(0) @binding(2) var<storage, read_write> read_counts: array<atomic<u32>>;

// The ReadCounts counters of this pass (READ_COUNTERS in src/gpu.rs).
const READ_COUNTER_LOW_RES_MIPS: u32 = 0u;
const READ_COUNTER_LOW_RES_MIPS_READ_BYTES: u32 = 1u;

// Bytes of one texel of the low-resolution map's levels: R32Float (ssm-core's
// LightDepthMap::FORMAT, checked by a test of the crate).
const LOW_RES_TEXEL_BYTES: u32 = 4u;

@compute @workgroup_size(8, 8)
fn pvsm_low_res_mip(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if (any(id.xy >= size)) {
        return;
    }
    // Texels 2i and 2i + 1 of the finer level; the last texel of a coarser level also takes the
    // finer level's odd last texel (a side that is not a power of two), so none is dropped.
    let finer_size = vec2<i32>(textureDimensions(finer));
    let low = vec2<i32>(id.xy) * 2;
    let high = select(min(low + 1, finer_size - 1), finer_size - 1, id.xy == size - 1u);
    var nearest = textureLoad(finer, low, 0).x;
    for (var y = low.y; y <= high.y; y++) {
        for (var x = low.x; x <= high.x; x++) {
            nearest = min(nearest, textureLoad(finer, vec2<i32>(x, y), 0).x);
        }
    }
    textureStore(coarser, vec2<i32>(id.xy), vec4<f32>(nearest));
    if (COUNT_READS) {
        // One read per textureLoad (ReadCounts' convention), the first texel's twice as the code
        // reads it; every one a texel of the finer level.
        let span = high - low + 1;
        let reads = 1u + u32(span.x * span.y);
        let word = read_count_word(READ_COUNTER_LOW_RES_MIPS, vec2<i32>(id.xy));
        atomicAdd(&read_counts[word], 1u);
        atomicAdd(&read_counts[word + 1u], reads);
        let bytes_word = read_count_word(READ_COUNTER_LOW_RES_MIPS_READ_BYTES, vec2<i32>(id.xy));
        atomicAdd(&read_counts[bytes_word], 1u);
        atomicAdd(&read_counts[bytes_word + 1u], reads * LOW_RES_TEXEL_BYTES);
    }
}
