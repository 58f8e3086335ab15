// The vertex layout of ssm-core's GpuScene: world-space positions and normals,
// and the role flags of the instance the vertex came from.

const ROLE_CASTS: u32 = 1u;
const ROLE_RECEIVES: u32 = 2u;

struct SceneVertex {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) role: u32,
};
