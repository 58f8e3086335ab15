// One triangle covering the viewport, for screen-space and light-space passes.
// Draw 3 vertices, no vertex buffer.

struct FullscreenVertex {
    @builtin(position) clip: vec4<f32>,
    // Texture coordinates: (0, 0) at the top-left texel corner, y down.
    @location(0) uv: vec2<f32>,
};

@vertex
fn fullscreen_vertex(@builtin(vertex_index) index: u32) -> FullscreenVertex {
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: FullscreenVertex;
    out.clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}
