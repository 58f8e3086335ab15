// The shared G-buffer: world position (w = 1 where geometry covers the pixel)
// and the shading normal turned towards the camera (w: flags, 1 on receivers,
// + 2 on closed meshes; decoded by common/screen_pass.wgsl).

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
    // Surfaces are two-sided: the normal of the side the camera sees. That side is the facet's
    // (its plane from the position's screen derivatives, whatever the winding), not the shading
    // normal's: near a silhouette an interpolated normal can face away from the camera while the
    // facet faces it, and flipping it there would point a closed mesh's normal inwards.
    let to_eye = camera.position.xyz - in.world;
    let across = dpdx(in.world);
    let down = dpdy(in.world);
    var facet = cross(across, down);
    // An edge-on facet has no usable plane: the shading normal decides.
    if (dot(facet, facet) <= 1e-12 * dot(across, across) * dot(down, down)) {
        facet = normal;
    }
    if (dot(facet, to_eye) < 0.0) {
        facet = -facet;
    }
    if (dot(normal, facet) < 0.0) {
        normal = -normal;
    }
    var out: GBufferTargets;
    out.position = vec4<f32>(in.world, 1.0);
    let flags = select(0u, GBUFFER_RECEIVES, (in.role & ROLE_RECEIVES) != 0u) | select(0u, GBUFFER_CLOSED, (in.role & SURFACE_CLOSED) != 0u);
    out.normal = vec4<f32>(normal, f32(flags));
    return out;
}
