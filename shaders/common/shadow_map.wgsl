// Lookups into a linear-depth light map (ssm-core's LightDepthMap): the
// stored value is the distance along the light's normal of the nearest
// surface, with bias already added; NO_SURFACE where nothing was drawn.

const NO_SURFACE: f32 = 3.40282347e38;

// Nearest-texel depth at shadow-map coordinates `uv`; NO_SURFACE outside the map.
fn shadow_map_depth(map: texture_2d<f32>, uv: vec2<f32>) -> f32 {
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) {
        return NO_SURFACE;
    }
    let size = vec2<f32>(textureDimensions(map));
    return textureLoad(map, vec2<i32>(uv * size), 0).x;
}
