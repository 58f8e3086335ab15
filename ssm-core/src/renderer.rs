//! The frame driver: uploads a scene, builds the shared inputs that the
//! techniques in use declared, runs a technique per light into the
//! visibility targets, times it, and reads results back.

use std::time::Instant;

use ssm_scene::{Adjacency, Mesh, Scene};

use crate::composite::Composite;
use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::frame::{Frame, SharedInputs};
use crate::gbuffer::GBuffer;
use crate::gpu_scene::GpuScene;
use crate::params::ParamValues;
use crate::passes::{labelled_view, render_texture};
use crate::readback::read_texture;
use crate::technique::{Requirements, ShadowTechnique, TechniqueInfo, create_checked};
use crate::timing::{FrameTimings, PassTimer, PassTiming};
use crate::work::{FrameWork, StatisticsQueries};

/// Format of the visibility targets.
pub const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Largest error tolerated when checking that visibility lies in `[0, 1]`
/// (floating-point accumulation may overshoot by a few ulps).
pub const VISIBILITY_RANGE_TOLERANCE: f32 = 1e-4;

/// Drives frames of one scene at one size.
pub struct Renderer {
    /// The GPU.
    pub gpu: GpuContext,
    /// The uploaded scene.
    pub scene: GpuScene,
    /// The scene on the CPU, shared with techniques that need it.
    pub cpu_scene: std::sync::Arc<Scene>,
    /// The shared inputs built for the techniques in use.
    pub shared: SharedInputs,
    visibility: Vec<wgpu::Texture>,
    visibility_views: Vec<wgpu::TextureView>,
    composite: Option<Composite>,
    timer: PassTimer,
    /// Times of the shared passes (the G-buffer), measured once when built.
    pub shared_timings: Vec<PassTiming>,
}

impl Renderer {
    /// Uploads `scene` for `width` × `height` images and builds the shared
    /// inputs `needs` asks for (the union of the techniques' [`TechniqueInfo::needs`], plus
    /// the G-buffer when shaded images or positions will be read).
    ///
    /// # Errors
    /// [`Error::Scene`] for an invalid scene, [`Error::InvalidSize`], or a GPU error.
    pub fn new(gpu: &GpuContext, scene: &Scene, width: u32, height: u32, needs: &Requirements) -> Result<Self> {
        scene.validate()?;
        let max = gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::InvalidSize { width, height, problem: format!("each side must be in [1, {max}] on this adapter") });
        }
        let gpu = gpu.clone();
        let gpu_scene = GpuScene::new(&gpu, scene, width, height, needs.roles);
        let mut timer = PassTimer::new(&gpu);
        let mut shared = SharedInputs::default();
        let mut shared_timings = Vec::new();
        if needs.gbuffer {
            let gbuffer = GBuffer::new(&gpu, &gpu_scene)?;
            shared_timings = render_gbuffer(&gpu, &gbuffer, &gpu_scene, &mut timer)?;
            shared.gbuffer = Some(gbuffer);
        }
        if needs.adjacency {
            shared.adjacency = Some(casting_adjacency(scene));
        }
        let visibility: Vec<wgpu::Texture> = (0..gpu_scene.light_count())
            .map(|light| {
                render_texture(
                    &gpu.device,
                    &format!("visibility_target_{light}"),
                    width,
                    height,
                    VISIBILITY_FORMAT,
                    wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::STORAGE_BINDING,
                )
            })
            .collect();
        let visibility_views =
            visibility.iter().enumerate().map(|(light, texture)| labelled_view(texture, &format!("visibility_target_{light}"))).collect();
        let renderer = Self {
            gpu,
            scene: gpu_scene,
            cpu_scene: std::sync::Arc::new(scene.clone()),
            shared,
            visibility,
            visibility_views,
            composite: None,
            timer,
            shared_timings,
        };
        renderer.check_gpu_errors("uploading the scene")?;
        Ok(renderer)
    }

    fn check_gpu_errors(&self, during: &str) -> Result<()> {
        let messages = self.gpu.take_errors();
        if messages.is_empty() { Ok(()) } else { Err(Error::Gpu { during: during.into(), messages }) }
    }

    /// Creates a technique with `params`, after checking what it needs
    /// ([`TechniqueInfo::needs`]) against the device and the shared inputs built. A technique
    /// that samples the light from its centre comes followed by the framework's own-surface
    /// share ([`LightSampling::Centre`](crate::LightSampling::Centre)).
    ///
    /// # Errors
    /// [`Error::MissingFeatures`], [`Error::LimitTooLow`], [`Error::UndeclaredRequirement`],
    /// or whatever the technique's constructor reports.
    pub fn create_technique(&self, info: &TechniqueInfo, params: &ParamValues) -> Result<Box<dyn ShadowTechnique>> {
        create_checked(info, &self.gpu, (&self.scene, &self.cpu_scene), (&self.shared, &self.visibility_views), params, false)
    }

    /// Counts the work of one frame of technique `info` with `params` (every light): builds it
    /// for counting ([`TechniqueSetup::count_work`](crate::TechniqueSetup::count_work)), renders
    /// one untimed frame with each pass's pipeline statistics queried, and joins what its shaders
    /// counted ([`ShadowTechnique::counted_work`]). The visibility it writes is the technique's
    /// own (counting changes no result), so a timed frame rendered after it reads the same.
    ///
    /// # Errors
    /// As [`Renderer::create_technique`] and [`Renderer::render`].
    pub fn count_work(&mut self, info: &TechniqueInfo, params: &ParamValues) -> Result<FrameWork> {
        let mut technique =
            create_checked(info, &self.gpu, (&self.scene, &self.cpu_scene), (&self.shared, &self.visibility_views), params, true)?;
        let mut statistics = StatisticsQueries::new(&self.gpu);
        self.timer.reset();
        let frame = Frame::new(&self.gpu, &self.scene, &self.shared, &mut self.timer, info.name).counting(&mut statistics);
        let mut encoder = record_lights(frame, &self.visibility_views, technique.as_mut())?;
        statistics.resolve(&mut encoder);
        self.gpu.queue.submit([encoder.finish()]);
        let during = format!("counting the work of `{}`", info.name);
        self.gpu.wait_idle().map_err(|e| Error::Gpu { during: during.clone(), messages: vec![e] })?;
        self.check_gpu_errors(&during)?;
        self.timer.reset();
        let mut work = statistics.read(&self.gpu)?;
        if let Some(shader_work) = technique.counted_work(&self.gpu)? {
            work.add_shader_work(&shader_work);
        }
        work.diagnostics = technique.diagnostics(&self.gpu);
        Ok(work)
    }

    /// Renders one frame of `technique` (registered as `name`) for every
    /// light, waits for the GPU, and returns its timings.
    ///
    /// # Errors
    /// The technique's own errors, or [`Error::Gpu`] if wgpu reported any.
    pub fn render(&mut self, technique: &mut dyn ShadowTechnique, name: &str) -> Result<FrameTimings> {
        let start = Instant::now();
        self.timer.reset();
        let frame = Frame::new(&self.gpu, &self.scene, &self.shared, &mut self.timer, name);
        let mut encoder = record_lights(frame, &self.visibility_views, technique)?;
        self.timer.resolve(&mut encoder);
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.wait_idle().map_err(|e| Error::Gpu { during: format!("rendering `{name}`"), messages: vec![e] })?;
        let cpu_wall_ms = start.elapsed().as_secs_f64() * 1e3;
        self.check_gpu_errors(&format!("rendering `{name}`"))?;
        self.timer.read(&self.gpu, cpu_wall_ms)
    }

    /// Reads light `light`'s visibility, row-major from the top-left, after
    /// checking that every value is finite and in `[0, 1]`.
    ///
    /// # Errors
    /// [`Error::InvalidOutput`] naming `technique` and the first bad pixel, or a readback error.
    pub fn read_visibility(&self, light: usize, technique: &str) -> Result<Vec<f32>> {
        let texture = self
            .visibility
            .get(light)
            .ok_or_else(|| Error::readback(format!("visibility of light {light}"), crate::error::Reason("no such light".into())))?;
        let bytes = read_texture(&self.gpu, texture, 4, "visibility")?;
        let values: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        let bad = |v: &f32| !(v.is_finite() && *v >= -VISIBILITY_RANGE_TOLERANCE && *v <= 1.0 + VISIBILITY_RANGE_TOLERANCE);
        if let Some(first) = values.iter().position(bad) {
            let width = self.scene.width as usize;
            return Err(Error::InvalidOutput {
                technique: technique.into(),
                count: values.iter().filter(|v| bad(v)).count(),
                x: (first % width) as u32,
                y: (first / width) as u32,
                value: values[first],
            });
        }
        Ok(values.into_iter().map(|v| v.clamp(0.0, 1.0)).collect())
    }

    /// The G-buffer's world positions (`w` = coverage), row-major from the top-left.
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`] without a G-buffer, or a readback error.
    pub fn read_positions(&self) -> Result<Vec<[f32; 4]>> {
        let gbuffer = self.shared.gbuffer("renderer outputs")?;
        let bytes = read_texture(&self.gpu, &gbuffer.position, 16, "G-buffer positions")?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// The G-buffer's normals (`w`: the flags [`GBuffer::flags`] decodes), row-major from the top-left.
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`] without a G-buffer, or a readback error.
    pub fn read_normals(&self) -> Result<Vec<[f32; 4]>> {
        let gbuffer = self.shared.gbuffer("renderer outputs")?;
        let bytes = read_texture(&self.gpu, &gbuffer.normal, 16, "G-buffer normals")?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// Shades `visibility` (one row-major image per light, each clamped to `[0, 1]`) as
    /// [`Renderer::shade`] shades a technique's: what an image of that visibility looks like (the
    /// ground truth moved by its own noise, for the noise floor of FLIP). It overwrites the
    /// visibility targets: read a technique's own first.
    ///
    /// # Errors
    /// [`Error::InvalidSize`] when an image or the number of images does not match, or as
    /// [`Renderer::shade`].
    pub fn shade_visibility(&mut self, visibility: &[Vec<f32>]) -> Result<Vec<u8>> {
        let (width, height) = (self.scene.width, self.scene.height);
        if visibility.len() != self.visibility.len() || visibility.iter().any(|image| image.len() != (width * height) as usize) {
            return Err(Error::InvalidSize {
                width,
                height,
                problem: format!(
                    "{} visibility images for {} lights, each of width × height values",
                    visibility.len(),
                    self.visibility.len()
                ),
            });
        }
        for (texture, image) in self.visibility.iter().zip(visibility) {
            let clamped: Vec<f32> = image.iter().map(|v| v.clamp(0.0, 1.0)).collect();
            self.gpu.queue.write_texture(
                texture.as_image_copy(),
                bytemuck::cast_slice(&clamped),
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(width * 4), rows_per_image: Some(height) },
                wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            );
        }
        self.shade()
    }

    /// Shades the current visibility (Lambert × visibility + ambient) and reads
    /// the sRGB image back as RGBA8.
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`] without a G-buffer, or a GPU error.
    pub fn shade(&mut self) -> Result<Vec<u8>> {
        self.shade_on_gpu()?;
        let Some(composite) = &self.composite else { unreachable!("built by shade_on_gpu") };
        let pixels = read_texture(&self.gpu, &composite.target, 4, "shaded image")?;
        self.check_gpu_errors("composite shading")?;
        Ok(pixels)
    }

    /// Shades the current visibility into the composite target and returns
    /// it (the composite format, `COPY_SRC`) without reading it back: what a
    /// live viewer copies to its window.
    ///
    /// # Errors
    /// [`Error::UndeclaredRequirement`] without a G-buffer, or a GPU error.
    pub fn shade_on_gpu(&mut self) -> Result<&wgpu::Texture> {
        let gbuffer = self.shared.gbuffer("composite shading")?;
        if self.composite.is_none() {
            self.composite = Some(Composite::new(&self.gpu, &self.scene, &self.visibility_views)?);
        }
        let Some(composite) = &self.composite else { unreachable!("built above") };
        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("composite_encoder") });
        composite.encode(&mut encoder, &self.scene, gbuffer);
        self.gpu.queue.submit([encoder.finish()]);
        self.check_gpu_errors("composite shading")?;
        Ok(&composite.target)
    }

    /// Moves the camera: updates the uploaded camera and the CPU scene's,
    /// and renders the G-buffer again (its times replace
    /// [`Renderer::shared_timings`]). Techniques read the camera from the
    /// scene's buffer each frame, but one that keeps what it derived from
    /// the view (the ground truth keeps its traced points) must be created
    /// again.
    ///
    /// # Errors
    /// [`Error::Scene`] for an invalid camera, or a GPU error.
    pub fn set_camera(&mut self, camera: &ssm_scene::Camera) -> Result<()> {
        camera.validate(std::path::Path::new("<camera>"))?;
        std::sync::Arc::make_mut(&mut self.cpu_scene).camera = *camera;
        self.scene.set_camera(&self.gpu.queue, &self.cpu_scene);
        if let Some(gbuffer) = &self.shared.gbuffer {
            self.timer.reset();
            self.shared_timings = render_gbuffer(&self.gpu, gbuffer, &self.scene, &mut self.timer)?;
        }
        self.check_gpu_errors("moving the camera")
    }

    /// Output width.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.scene.width
    }

    /// Output height.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.scene.height
    }
}

/// Renders the G-buffer for the scene's current camera and returns its pass times.
/// Records `technique`'s passes for every light into `frame` (each light's target cleared to lit
/// first), and returns the encoder to submit.
fn record_lights(
    mut frame: Frame<'_>,
    visibility_views: &[wgpu::TextureView],
    technique: &mut dyn ShadowTechnique,
) -> Result<wgpu::CommandEncoder> {
    for (light, view) in visibility_views.iter().enumerate() {
        frame.begin_light(light, view);
        let result = technique.render(&mut frame, light, view);
        frame.end_light();
        result?;
    }
    Ok(frame.finish())
}

fn render_gbuffer(gpu: &GpuContext, gbuffer: &GBuffer, scene: &GpuScene, timer: &mut PassTimer) -> Result<Vec<PassTiming>> {
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("gbuffer_encoder") });
    encoder.push_debug_group("gbuffer");
    gbuffer.encode(&mut encoder, scene, timer);
    encoder.pop_debug_group();
    timer.resolve(&mut encoder);
    let start = Instant::now();
    gpu.queue.submit([encoder.finish()]);
    gpu.wait_idle().map_err(|e| Error::Gpu { during: "rendering the G-buffer".into(), messages: vec![e] })?;
    let passes = timer.read(gpu, start.elapsed().as_secs_f64() * 1e3)?.passes;
    timer.reset();
    Ok(passes)
}

/// World-space adjacency of every triangle that casts shadows.
fn casting_adjacency(scene: &Scene) -> Adjacency {
    let mut positions = Vec::new();
    for triangle in scene.world_triangles().filter(|t| t.role.casts()) {
        positions.extend_from_slice(&triangle.corners);
    }
    let indices = (0..positions.len() as u32).collect();
    // Normals are not used by adjacency; welding happens on positions.
    let mesh = Mesh { name: "casting geometry".into(), normals: vec![glam::Vec3::Y; positions.len()], positions, indices };
    Adjacency::of(&mesh)
}
