//! The scene on the GPU: world-space geometry sorted by role, the camera, and
//! one light frame per light.

use std::ops::Range;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};
use ssm_scene::{Aabb, Role, Scene};
use wgpu::util::DeviceExt;

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::light_frame::{LightFrame, LightFrameUniform};

/// One vertex as the GPU sees it: world space, with its instance's role.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SceneVertex {
    /// World-space position.
    pub position: [f32; 3],
    /// World-space unit normal.
    pub normal: [f32; 3],
    /// Role flags: [`ROLE_CASTS`] | [`ROLE_RECEIVES`] | [`SURFACE_CLOSED`].
    pub role: u32,
}

/// Role flag: the vertex's instance casts shadows.
pub const ROLE_CASTS: u32 = 1;
/// Role flag: the vertex's instance receives shadows.
pub const ROLE_RECEIVES: u32 = 2;
/// Flag: the vertex's mesh is closed ([`ssm_scene::Scene::closed_meshes`]), so that where the
/// whole light is behind its tangent plane the surface itself hides the light (the G-buffer
/// records it for `trivial_visibility` in `shaders/common/screen_pass.wgsl`).
pub const SURFACE_CLOSED: u32 = 4;

impl SceneVertex {
    /// Attributes: 0 position, 1 normal, 2 role (as in `shaders/common/scene.wgsl`).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 3] = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Uint32];

    /// The vertex buffer layout every scene pipeline uses.
    #[must_use]
    pub const fn layout() -> wgpu::VertexBufferLayout<'static> {
        wgpu::VertexBufferLayout {
            array_stride: size_of::<Self>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &Self::ATTRIBUTES,
        }
    }
}

/// Which triangles a pass draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    /// Everything.
    All,
    /// Instances with role `occluder` or `both`.
    Occluders,
    /// Instances with role `receiver` or `both`.
    Receivers,
}

/// The camera as a uniform (`shaders/common/camera.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, crate::UniformStruct)]
pub struct CameraUniform {
    /// World to clip.
    pub view_proj: [[f32; 4]; 4],
    /// Clip to world.
    pub inverse_view_proj: [[f32; 4]; 4],
    /// Eye position, w unused.
    pub position: [f32; 4],
    /// Width, height, 1/width, 1/height.
    pub viewport: [f32; 4],
}

/// Uploaded scene: geometry, camera and light frames, built once per scene and size.
#[derive(Debug)]
pub struct GpuScene {
    /// World-space vertices ([`SceneVertex`]).
    pub vertex_buffer: wgpu::Buffer,
    /// Triangle list, `u32`. With roles, sorted occluder-only, both,
    /// receiver-only so that each [`Geometry`] is one contiguous range;
    /// without, in scene order.
    pub index_buffer: wgpu::Buffer,
    ranges: [Range<u32>; 3],
    /// Whether the geometry was sorted by role, because a technique in use
    /// declared [`Requirements::roles`](crate::Requirements).
    pub has_roles: bool,
    /// Number of triangles.
    pub triangle_count: u32,
    /// World-space bounds.
    pub bounds: Aabb,
    /// World-space bounds of the receiving geometry (roles `receiver` and `both`).
    pub receiver_bounds: Aabb,
    /// The camera matrices.
    pub camera: CameraUniform,
    /// Its uniform buffer.
    pub camera_buffer: wgpu::Buffer,
    /// Layout of a bind group holding one uniform buffer (camera or light frame) at binding 0
    /// ([`GpuContext::uniform_layout`]).
    pub uniform_layout: wgpu::BindGroupLayout,
    /// The camera's bind group (layout [`GpuScene::uniform_layout`]).
    pub camera_bind_group: wgpu::BindGroup,
    /// One frame per light.
    pub light_frames: Vec<LightFrame>,
    /// One uniform buffer per light.
    pub light_buffers: Vec<wgpu::Buffer>,
    /// One bind group per light (layout [`GpuScene::uniform_layout`]).
    pub light_bind_groups: Vec<wgpu::BindGroup>,
    /// Per mesh of the scene, whether it is closed ([`ssm_scene::Scene::closed_meshes`]).
    pub closed_meshes: Vec<bool>,
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
}

impl GpuScene {
    /// Uploads a validated scene for images of `width` × `height`, sorted by
    /// role when `roles` (some technique in use draws occluders and receivers
    /// apart).
    #[must_use]
    pub fn new(gpu: &GpuContext, scene: &Scene, width: u32, height: u32, roles: bool) -> Self {
        let device = &gpu.device;
        let mut vertices = Vec::new();
        // Three index lists, concatenated in role order afterwards.
        let mut by_role: [Vec<u32>; 3] = Default::default();
        let closed = scene.closed_meshes();
        for triangle in scene.world_triangles() {
            let flags = (u32::from(triangle.role.casts()) * ROLE_CASTS)
                | (u32::from(triangle.role.receives()) * ROLE_RECEIVES)
                | (u32::from(closed.get(triangle.mesh).copied().unwrap_or(false)) * SURFACE_CLOSED);
            let slot = match triangle.role {
                _ if !roles => 0,
                Role::Occluder => 0,
                Role::Both => 1,
                Role::Receiver => 2,
            };
            let base = vertices.len() as u32;
            for k in 0..3 {
                vertices.push(SceneVertex {
                    position: triangle.corners[k].to_array(),
                    normal: triangle.normals[k].to_array(),
                    role: flags,
                });
            }
            by_role[slot].extend_from_slice(&[base, base + 1, base + 2]);
        }
        let [occluder_only, both, receiver_only] = by_role.each_ref().map(|list| list.len() as u32);
        let indices: Vec<u32> = by_role.concat();
        let all = 0..indices.len() as u32;
        let ranges = if roles {
            [all, 0..occluder_only + both, occluder_only..occluder_only + both + receiver_only]
        } else {
            [all.clone(), all.clone(), all]
        };
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene_vertex_buffer"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE,
        });
        let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene_index_buffer"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::STORAGE,
        });

        let bounds = scene.bounds();
        let camera = camera_uniform(&scene.camera, width, height);
        let camera_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene_camera_uniform"),
            contents: bytemuck::bytes_of(&camera),
            // COPY_DST: a live viewer moves the camera ([`GpuScene::set_camera`]).
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let uniform_layout = gpu.uniform_layout().clone();
        let uniform_group = |label: &str, buffer: &wgpu::Buffer| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout: &uniform_layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
            })
        };
        let camera_bind_group = uniform_group("scene_camera_bind_group", &camera_buffer);
        let receivers = scene.bounds_where(Role::receives);
        let casting_points: Vec<glam::Vec3> =
            vertices.iter().filter(|v| v.role & ROLE_CASTS != 0).map(|v| glam::Vec3::from_array(v.position)).collect();
        let triangle_corners: Vec<glam::Vec3> = vertices.iter().map(|v| glam::Vec3::from_array(v.position)).collect();
        let light_frames: Vec<LightFrame> = scene
            .lights
            .iter()
            .map(|light| LightFrame {
                sealed: scene.separates_light_from(&closed, light, scene.camera.position),
                enclosed: scene.encloses_light(&closed, light),
                ..LightFrame::fit_to_geometry(light, &bounds, &receivers, &casting_points, &triangle_corners)
            })
            .collect();
        let light_buffers: Vec<wgpu::Buffer> = light_frames
            .iter()
            .enumerate()
            .map(|(index, frame)| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("light_frame_uniform_{index}")),
                    contents: bytemuck::bytes_of(&LightFrameUniform::from(frame)),
                    // COPY_DST: whether the light is sealed from the camera changes with the camera.
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                })
            })
            .collect();
        let light_bind_groups = light_buffers
            .iter()
            .enumerate()
            .map(|(index, buffer)| uniform_group(&format!("light_frame_bind_group_{index}"), buffer))
            .collect();
        Self {
            vertex_buffer,
            index_buffer,
            ranges,
            has_roles: roles,
            triangle_count: indices.len() as u32 / 3,
            bounds,
            receiver_bounds: receivers,
            camera,
            camera_buffer,
            uniform_layout,
            camera_bind_group,
            light_frames,
            light_buffers,
            light_bind_groups,
            closed_meshes: closed,
            width,
            height,
        }
    }

    /// Index range of `geometry` in [`GpuScene::index_buffer`].
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`] naming `technique` when `geometry`
    /// selects by role and no technique in use declared roles.
    pub fn index_range(&self, technique: &str, geometry: Geometry) -> Result<Range<u32>> {
        if geometry != Geometry::All && !self.has_roles {
            return Err(Error::UndeclaredRequirement { technique: technique.into(), input: "occluder/receiver roles" });
        }
        Ok(match geometry {
            Geometry::All => self.ranges[0].clone(),
            Geometry::Occluders => self.ranges[1].clone(),
            Geometry::Receivers => self.ranges[2].clone(),
        })
    }

    /// Index range of every triangle.
    #[must_use]
    pub fn all(&self) -> Range<u32> {
        self.ranges[0].clone()
    }

    /// Binds the geometry buffers at vertex slot 0 and draws `range` (from [`GpuScene::index_range`]).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, range: Range<u32>) {
        if range.is_empty() {
            return;
        }
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(range, 0, 0..1);
    }

    /// Number of lights.
    #[must_use]
    pub fn light_count(&self) -> usize {
        self.light_frames.len()
    }

    /// Points the camera at `scene`'s camera: recomputes [`GpuScene::camera`] and whether each
    /// light is sealed from it ([`LightFrame::sealed`], the frames' only part that depends on
    /// the camera), and writes their buffers on `queue`. The G-buffer must be rendered again
    /// afterwards ([`Renderer::set_camera`](crate::Renderer::set_camera) does both).
    pub fn set_camera(&mut self, queue: &wgpu::Queue, scene: &Scene) {
        self.camera = camera_uniform(&scene.camera, self.width, self.height);
        queue.write_buffer(&self.camera_buffer, 0, bytemuck::bytes_of(&self.camera));
        for (frame, buffer) in self.light_frames.iter_mut().zip(&self.light_buffers) {
            let sealed = scene.separates_light_from(&self.closed_meshes, &frame.light, scene.camera.position);
            if sealed != frame.sealed {
                frame.sealed = sealed;
                queue.write_buffer(buffer, 0, bytemuck::bytes_of(&LightFrameUniform::from(&*frame)));
            }
        }
    }
}

fn camera_uniform(camera: &ssm_scene::Camera, width: u32, height: u32) -> CameraUniform {
    let aspect = width as f32 / height.max(1) as f32;
    let view_proj: Mat4 = camera.projection(aspect) * camera.view();
    CameraUniform {
        view_proj: view_proj.to_cols_array_2d(),
        inverse_view_proj: view_proj.inverse().to_cols_array_2d(),
        position: Vec4::from((camera.position, 1.0)).to_array(),
        viewport: [width as f32, height as f32, 1.0 / width as f32, 1.0 / height as f32],
    }
}
