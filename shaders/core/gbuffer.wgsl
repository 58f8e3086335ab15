// The shared G-buffer: world position (w = 1 where geometry covers the pixel)
// and the shading normal turned towards the camera (w = 1 on receivers).

// #import common/camera.wgsl
// #import common/scene.wgsl

@group(0) @binding(0) var<uniform> camera: Camera;

struct GBufferVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) role: u32,
};

@vertex
fn gbuffer_vertex(vertex: SceneVertex) -> GBufferVertex {
    var out: GBufferVertex;
    out.clip = camera.view_proj * vec4<f32>(vertex.position, 1.0);
    out.world = vertex.position;
    out.normal = vertex.normal;
    out.role = vertex.role;
    return out;
}

struct GBufferTargets {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
};

@fragment
fn gbuffer_fragment(in: GBufferVertex) -> GBufferTargets {
    var normal = normalize(in.normal);
    // Surfaces are two-sided: shade the side the camera sees.
    if (dot(normal, camera.position.xyz - in.world) < 0.0) {
        normal = -normal;
    }
    var out: GBufferTargets;
    out.position = vec4<f32>(in.world, 1.0);
    out.normal = vec4<f32>(normal, select(0.0, 1.0, (in.role & ROLE_RECEIVES) != 0u));
    return out;
}
