// The receiver map's depth bounds (max-pyramid): level 0 holds each texel's receiver depth (0
// where there is no receiver), each further level the largest of the 2×2 texels below it. The
// accumulation reads it to bound each micro-patch's penumbra rectangle by the deepest receiver
// under it instead of the frame's far plane (atty_accumulation.wgsl, `penumbra_bound`).

// #import common/shadow_map.wgsl
// #import atty/atty_counts.wgsl

@group(0) @binding(0) var finer: texture_2d<f32>;
@group(0) @binding(1) var coarser: texture_storage_2d<r32float, write>;
// This pyramid's counters (atty_counts.wgsl): 0, texel reads; 1, the bytes they fetched; 2, bytes
// stored (4 per R32Float texel).
@group(0) @binding(2) var<storage, read_write> read_counts: array<atomic<u32>>;

// Bytes of one texel read (the pipelines set them from the formats: DepthPyramid in src/lib.rs):
// of the map level 0 is built from (the receiver map: R32Float, or Rgba32Float planes with
// receiver_plane), and of this pyramid's levels (R32Float).
override MAP_TEXEL_BYTES: u32;
override PYRAMID_TEXEL_BYTES: u32;

// Level 0 from the receiver map (`finer`): NO_SURFACE becomes 0, below every patch.
@compute @workgroup_size(8, 8, 1)
fn atty_bounds_base(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if (any(id.xy >= size)) {
        return;
    }
    let depth = textureLoad(finer, vec2<i32>(id.xy), 0).x;
    textureStore(coarser, vec2<i32>(id.xy), vec4<f32>(select(depth, 0.0, depth >= NO_SURFACE)));
    record_count(0u, vec2<i32>(id.xy), 1u);
    record_count(1u, vec2<i32>(id.xy), MAP_TEXEL_BYTES);
    record_count(2u, vec2<i32>(id.xy), 4u);
}

// One level from the one below (`finer`). Mip sizes halve rounding down, so the last texel of a
// row or column also takes the finer texel left over by an odd length: texel t of level L covers
// texels t·2^L to (t + 1)·2^L − 1 of level 0, the last one to the end of the map.
@compute @workgroup_size(8, 8, 1)
fn atty_bounds_reduce(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if (any(id.xy >= size)) {
        return;
    }
    let finer_last = vec2<i32>(textureDimensions(finer)) - 1;
    let first = vec2<i32>(id.xy) * 2;
    let last = select(first + 1, finer_last, id.xy + 1u == size);
    var deepest = 0.0;
    for (var y = first.y; y <= last.y; y++) {
        for (var x = first.x; x <= last.x; x++) {
            deepest = max(deepest, textureLoad(finer, vec2<i32>(x, y), 0).x);
        }
    }
    textureStore(coarser, vec2<i32>(id.xy), vec4<f32>(deepest));
    let block = last - first + 1;
    let reads = u32(block.x * block.y);
    record_count(0u, vec2<i32>(id.xy), reads);
    record_count(1u, vec2<i32>(id.xy), reads * PYRAMID_TEXEL_BYTES);
    record_count(2u, vec2<i32>(id.xy), 4u);
}
