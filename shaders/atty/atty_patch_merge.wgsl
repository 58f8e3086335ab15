// The occluder map's depth range per aligned block (min-max pyramid): level 0 holds each texel's
// (depth, depth), NO_SURFACE where the texel is empty; texel t of level L the smallest and
// largest depth over texels t·2^L to (t + 1)·2^L − 1 of level 0 (sizes halve rounding down, so
// a block never runs past the map). The accumulation merges a block whose depths agree into one
// micro-patch (atty_accumulation.wgsl).

// #import common/shadow_map.wgsl
// #import atty/atty_counts.wgsl

@group(0) @binding(0) var finer: texture_2d<f32>;
@group(0) @binding(1) var coarser: texture_storage_2d<rg32float, write>;
// This pyramid's counters (atty_counts.wgsl): 0, texel reads; 1, the bytes they fetched; 2, bytes
// stored (8 per Rg32Float texel).
@group(0) @binding(2) var<storage, read_write> read_counts: array<atomic<u32>>;

// Bytes of one texel read (the pipelines set them from the formats: DepthPyramid in src/lib.rs):
// of the map level 0 is built from (the occluder map, R32Float), and of this pyramid's levels
// (Rg32Float).
override MAP_TEXEL_BYTES: u32;
override PYRAMID_TEXEL_BYTES: u32;

@compute @workgroup_size(8, 8, 1)
fn atty_merge_base(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if (any(id.xy >= size)) {
        return;
    }
    let depth = textureLoad(finer, vec2<i32>(id.xy), 0).x;
    textureStore(coarser, vec2<i32>(id.xy), vec4<f32>(depth, depth, 0.0, 0.0));
    record_count(0u, vec2<i32>(id.xy), 1u);
    record_count(1u, vec2<i32>(id.xy), MAP_TEXEL_BYTES);
    record_count(2u, vec2<i32>(id.xy), 8u);
}

@compute @workgroup_size(8, 8, 1)
fn atty_merge_reduce(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if (any(id.xy >= size)) {
        return;
    }
    var nearest = NO_SURFACE;
    var farthest = 0.0;
    for (var corner = 0; corner < 4; corner++) {
        let range = textureLoad(finer, vec2<i32>(id.xy) * 2 + vec2<i32>(corner & 1, corner >> 1u), 0).xy;
        nearest = min(nearest, range.x);
        farthest = max(farthest, range.y);
    }
    textureStore(coarser, vec2<i32>(id.xy), vec4<f32>(nearest, farthest, 0.0, 0.0));
    record_count(0u, vec2<i32>(id.xy), 4u);
    record_count(1u, vec2<i32>(id.xy), 4u * PYRAMID_TEXEL_BYTES);
    record_count(2u, vec2<i32>(id.xy), 8u);
}
