// A light-space depth map: linear depth (distance along the light's normal)
// of the nearest surface per texel, with a constant and a slope-scaled bias
// added as hardware depth bias would, but in linear units.

// #import common/light_frame.wgsl
// #import common/scene.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;

struct DepthBias {
    // x: constant bias (world units), y: slope factor (times the depth change per texel), zw: unused.
    values: vec4<f32>,
};
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
    let slope = max(abs(dpdx(in.depth)), abs(dpdy(in.depth)));
    return in.depth + bias.values.x + bias.values.y * slope;
}
