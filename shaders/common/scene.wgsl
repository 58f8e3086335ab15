// The vertex layout of ssm-core's GpuScene: world-space positions and normals,
// and the role flags of the instance the vertex came from.

const ROLE_CASTS: u32 = 1u;
const ROLE_RECEIVES: u32 = 2u;
// The vertex's mesh is closed (ssm-core's SURFACE_CLOSED).
const SURFACE_CLOSED: u32 = 4u;

// The flags the G-buffer keeps in its normal's w (as a small whole float).
const GBUFFER_RECEIVES: u32 = 1u;
const GBUFFER_CLOSED: u32 = 2u;

struct SceneVertex {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) role: u32,
};
