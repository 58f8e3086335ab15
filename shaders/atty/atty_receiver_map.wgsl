// The receiver map with each receiver's tangent plane, for the receiver-plane test
// (`receiver_plane`; atty_accumulation.wgsl and atty_projection.wgsl): per texel of the light frame,
// the nearest receiver's linear depth z_R (as the plain receiver map, ssm-core's light_depth.wgsl,
// without bias) and the slope of its triangle's plane. A plane's 1/depth is affine in the frame's
// ndc q, 1/z(q) = (1 + slope·(q − q_R)) / z_R (atty_geometry.wgsl), and so in framebuffer
// position: its screen-space derivative is exact within a triangle (the rasteriser interpolates
// 1/w the same way), so slope = z_R · ∇_q(1/z) is read from the fragment's own triangle, crease or
// depth edge or not.

// #import common/light_frame.wgsl
// #import common/scene.wgsl
// #import atty/atty_settings.wgsl

@group(0) @binding(0) var<uniform> frame: LightFrame;
@group(1) @binding(0) var<uniform> settings: AttySettings;

struct ReceiverVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) depth: f32,
};

@vertex
fn atty_receiver_vertex(vertex: SceneVertex) -> ReceiverVertex {
    var out: ReceiverVertex;
    out.clip = frame.view_proj * vec4<f32>(vertex.position, 1.0);
    out.depth = light_depth(frame, vertex.position);
    return out;
}

@fragment
fn atty_receiver_fragment(in: ReceiverVertex) -> @location(0) vec4<f32> {
    let inverse_depth = 1.0 / in.depth;
    // Framebuffer x and y run along the frame's u and v, one texel per 2 / size ndc units.
    let per_texel = vec2<f32>(dpdxFine(inverse_depth), dpdyFine(inverse_depth));
    let slope = in.depth * per_texel * settings.soft_shadow_map_size * 0.5;
    return vec4<f32>(in.depth, slope, 0.0);
}
