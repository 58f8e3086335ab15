// Shadow-map reads through a sampled or a storage binding of the same light depth map
// (ssm-core's ShadowMapReads): imported by the techniques that offer the choice, which bind the
// map twice (LightDepthMap::linear_depth_view and LightDepthMap::storage_view).

// #import common/shadow_map.wgsl

// Whether shadow_map_tap reads the map bound as a read-only storage texture rather than as a
// sampled texture (ssm-core's ShadowMapReads; a constant of the pipeline): the same texel either way.
override SHADOW_MAP_STORAGE_READS: bool = false;

// shadow_map_depth of `map`, read through shadow_map_texel: NO_SURFACE outside the map, else
// the nearest texel, from `storage_map` (the same texture, bound as a read-only storage texture)
// with SHADOW_MAP_STORAGE_READS.
fn shadow_map_tap(map: texture_2d<f32>, storage_map: texture_storage_2d<r32float, read>, uv: vec2<f32>) -> f32 {
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) {
        return NO_SURFACE;
    }
    return shadow_map_texel(map, storage_map, vec2<i32>(uv * vec2<f32>(textureDimensions(map))));
}

// The depth stored at `texel` of `map`, read from `storage_map` (the same texture) with
// SHADOW_MAP_STORAGE_READS; `texel` must lie inside the map.
fn shadow_map_texel(map: texture_2d<f32>, storage_map: texture_storage_2d<r32float, read>, texel: vec2<i32>) -> f32 {
    if (SHADOW_MAP_STORAGE_READS) {
        return textureLoad(storage_map, texel).x;
    }
    return textureLoad(map, texel, 0).x;
}
