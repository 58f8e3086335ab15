// The viewing camera, as uploaded by ssm-core's GpuScene.

struct Camera {
    view_proj: mat4x4<f32>,
    inverse_view_proj: mat4x4<f32>,
    // xyz: eye position, w: unused.
    position: vec4<f32>,
    // width, height, 1 / width, 1 / height.
    viewport: vec4<f32>,
};
