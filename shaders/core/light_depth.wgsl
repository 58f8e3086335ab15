// A light-space depth map: linear depth (distance along the light's normal)
// of the nearest surface per texel, with a constant and a slope-scaled bias
// added as hardware depth bias would, but in linear units. Like hardware bias,
// the slope term is clamped: on triangles nearly parallel to the light's rays
// the depth change per texel is unbounded, and an unclamped bias pushes them
// far enough back for light to leak through whole objects.

// #import common/light_frame.wgsl
// #import common/scene.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;

struct DepthBias {
    // x: constant bias (world units), y: slope factor (times the depth change per texel),
    // z, w: the map's width and height in texels.
    values: vec4<f32>,
};

// The slope term never exceeds this many texels' worth of world distance at the fragment's depth.
const SLOPE_CLAMP_TEXELS: f32 = 4.0;
@group(1) @binding(0) var<uniform> bias: DepthBias;

struct LightDepthVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) depth: f32,
};

@vertex
fn light_depth_vertex(vertex: SceneVertex) -> LightDepthVertex {
    var out: LightDepthVertex;
    out.clip = frame.view_proj * vec4<f32>(vertex.position, 1.0);
    out.depth = light_depth(frame, vertex.position);
    return out;
}

@fragment
fn light_depth_fragment(in: LightDepthVertex) -> @location(0) f32 {
    let texel = 2.0 * in.depth * max(frame.projection.x / bias.values.z, frame.projection.y / bias.values.w);
    let slope = min(max(abs(dpdx(in.depth)), abs(dpdy(in.depth))), SLOPE_CLAMP_TEXELS * texel);
    return in.depth + bias.values.x + bias.values.y * slope;
}
