//! The viewer's window: the event loop ([`run`]), the window and its surface made and kept the
//! size of the window, and the panel painted into it and presented.

use std::io::Write;
use std::sync::Arc;

use anyhow::{Context, Result};
use glam::Vec3;
use ssm_core::reference::ReferenceCache;
use ssm_core::{GpuContext, Renderer};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

use super::{FrameReport, Live, Orbit, PANEL_WIDTH, Slot, TruthLookup, ViewMode, ViewOptions};

/// Opens the window and runs until it is closed.
///
/// # Errors
/// No display, no adapter that can present to the window, or a scene the
/// renderer rejects. A technique's own errors are shown in the panel instead.
pub fn run(options: ViewOptions) -> Result<()> {
    anyhow::ensure!(!options.techniques.is_empty(), "ssm view: no technique to show");
    let event_loop = EventLoop::new().context("ssm view needs a display (X11 or Wayland): none could be opened")?;
    event_loop.set_control_flow(ControlFlow::Wait);
    let mut app = App { options: Some(options), live: None, error: None };
    event_loop.run_app(&mut app).context("running the window's event loop")?;
    match app.error {
        Some(error) => Err(error),
        None => Ok(()),
    }
}

struct App {
    options: Option<ViewOptions>,
    live: Option<Live>,
    error: Option<anyhow::Error>,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.live.is_some() {
            return;
        }
        let Some(options) = self.options.take() else { return };
        match Live::new(event_loop, options) {
            Ok(live) => {
                live.window.request_redraw();
                self.live = Some(live);
            }
            Err(error) => {
                self.error = Some(error);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _window: WindowId, event: WindowEvent) {
        let Some(live) = &mut self.live else { return };
        let response = live.egui_state.on_window_event(&live.window, &event);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                live.surface_config.width = size.width.max(1);
                live.surface_config.height = size.height.max(1);
                live.surface.configure(&live.renderer.gpu.device, &live.surface_config);
                live.window.request_redraw();
            }
            WindowEvent::RedrawRequested => {
                if let Err(error) = live.redraw() {
                    self.error = Some(error);
                    event_loop.exit();
                }
            }
            _ => {
                if response.repaint {
                    live.window.request_redraw();
                }
            }
        }
    }
}

impl Live {
    fn new(event_loop: &ActiveEventLoop, options: ViewOptions) -> Result<Self> {
        let ViewOptions { scene_name, scene, techniques, width, height, count_work } = options;
        let attributes = Window::default_attributes()
            .with_title(format!("ssm view: {scene_name}"))
            .with_inner_size(winit::dpi::PhysicalSize::new(width + PANEL_WIDTH as u32 + 24, (height + 320).max(600)));
        let window = Arc::new(event_loop.create_window(attributes).context("creating the window")?);
        let (gpu, surface) = GpuContext::for_window(Arc::clone(&window))?;
        let size = window.inner_size();
        let capabilities = surface.get_capabilities(&gpu.adapter);
        // egui draws into a gamma-space target best (its README); take one when offered.
        let format = capabilities
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or_else(|| capabilities.formats.first().copied())
            .context("the window's surface offers no format")?;
        let mut surface_config = surface
            .get_default_config(&gpu.adapter, size.width.max(1), size.height.max(1))
            .context("the adapter cannot present to this window")?;
        surface_config.format = format;
        surface.configure(&gpu.device, &surface_config);

        let needs = crate::measure::needs::requirements_of(techniques.iter().map(|(info, params)| (*info, params)))?;
        let renderer = Renderer::new(&gpu, &scene, width, height, &needs).context("uploading the scene")?;
        let display = ssm_core::passes::render_texture(
            &gpu.device,
            "view_display_image",
            width,
            height,
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        let display_view = ssm_core::passes::labelled_view(&display, "view_display_image");
        let mut egui_renderer = egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        // Nearest: at 1:1 every rendered pixel is one window pixel, unsmoothed.
        let display_id = egui_renderer.register_native_texture(&gpu.device, &display_view, wgpu::FilterMode::Nearest);
        let egui_ctx = egui::Context::default();
        let max_side = gpu.device.limits().max_texture_dimension_2d as usize;
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(max_side),
        );
        let up = scene.camera.up.normalize_or(Vec3::Y);
        let orbit = Orbit { camera: scene.camera, up };
        // The cache's key only: building the tracer (its BVH) is left to the `reference` technique, if selected.
        let truth = TruthLookup {
            cache: ReferenceCache::of(&scene),
            cache_dir: ssm_core::reference::default_cache_dir(),
            images: Vec::new(),
            covered: Vec::new(),
        };
        let slots = techniques.into_iter().map(|(info, params)| Slot { info, params, instance: None }).collect();
        let mut live = Self {
            window,
            surface,
            surface_config,
            renderer,
            egui_ctx,
            egui_state,
            egui_renderer,
            display,
            display_id,
            scene_name,
            slots,
            current: 0,
            orbit,
            camera_moved: false,
            dirty: true,
            continuous: false,
            frame: 0,
            report: FrameReport::default(),
            truth,
            announce: None,
            image_origin: [0, 0],
            mode: ViewMode::Shaded,
            light: 0,
            count_work,
            work: None,
        };
        live.look_up_truth()?;
        Ok(live)
    }

    /// Draws the panel (and the image in it) into the window and presents it.
    pub(super) fn paint(&mut self, mut encoder: wgpu::CommandEncoder, full_output: egui::FullOutput) -> Result<()> {
        let surface_texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(texture) | wgpu::CurrentSurfaceTexture::Suboptimal(texture) => texture,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.renderer.gpu.device, &self.surface_config);
                self.window.request_redraw();
                return Ok(());
            }
            _ => {
                self.window.request_redraw();
                return Ok(());
            }
        };
        let target =
            surface_texture.texture.create_view(&wgpu::TextureViewDescriptor { label: Some("view_surface"), ..Default::default() });
        let pixels_per_point = full_output.pixels_per_point;
        let screen =
            egui_wgpu::ScreenDescriptor { size_in_pixels: [self.surface_config.width, self.surface_config.height], pixels_per_point };
        let primitives = self.egui_ctx.tessellate(full_output.shapes, pixels_per_point);
        let gpu = self.renderer.gpu.clone();
        let extra = self.egui_renderer.update_buffers(&gpu.device, &gpu.queue, &mut encoder, &primitives, &screen);
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("view_panel_pass"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let mut pass = pass.forget_lifetime();
            self.egui_renderer.render(&mut pass, &primitives, &screen);
        }
        gpu.queue.submit(extra.into_iter().chain([encoder.finish()]));
        gpu.queue.present(surface_texture);
        if let Some(line) = self.announce.take() {
            let mut stdout = std::io::stdout();
            let [x, y] = self.image_origin;
            // A closed stdout (the caller stopped reading) must not stop the viewer.
            let _ = writeln!(stdout, "{line} image {x},{y} {}x{}", self.renderer.width(), self.renderer.height());
            let _ = stdout.flush();
        }
        let messages = gpu.take_errors();
        anyhow::ensure!(messages.is_empty(), "drawing the window: {}", messages.join("; "));
        let repaint = full_output.viewport_output.get(&egui::ViewportId::ROOT).is_some_and(|v| v.repaint_delay.is_zero());
        if repaint || self.dirty || self.continuous || self.camera_moved {
            self.window.request_redraw();
        }
        Ok(())
    }
}
