//! `ssm view`: a live window onto one scene. The shaded image of the
//! selected technique fills the window; a panel beside it lists the
//! techniques (number keys switch between them), builds a widget for each
//! of the selected technique's parameters from its declared
//! [`ParamSpec`]s, and shows the last frame's per-pass GPU times and, where
//! the ground truth of this view is in the reference cache, the error
//! against it. S, V and E switch the image between the shaded frame, one
//! light's visibility and its signed error against the cached ground truth
//! (the HTML report's keys). Dragging the image orbits the camera around its
//! target, the wheel moves it closer or further.
//!
//! A frame is rendered only when something changed (technique, parameter,
//! camera, or the "render continuously" box): on a software rasteriser a
//! frame of some techniques takes seconds, and the panel must stay usable.
//!
//! With "count work" (the box, the W key, or `--count-work`), the panel also shows the selected
//! technique's counted work per pass ([`crate::work`]): one extra, untimed frame counted after the
//! first frame of each technique and setting, not every frame (and announced on stdout as
//! `ssm view: counted <technique> [<params>] passes <n> invocations <n|-> texel_reads <n|->`).
//!
//! Each image shown is announced on stdout as one line,
//! `ssm view: showing <technique> [<params>] frame <n> view <view> image <x>,<y> <w>x<h>`,
//! with the image's place in the window in pixels, so that scripts (and the
//! Xvfb test) know what the window shows and where.

use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, Result};
use glam::{Quat, Vec3};
use ssm_core::metrics::{self, ErrorMetrics};
use ssm_core::reference::{ReferenceCache, surface_points};
use ssm_core::{
    FrameTimings, FrameWork, GpuContext, ParamKind, ParamSpec, ParamValue, ParamValues, Renderer, ShadowTechnique, TechniqueInfo,
    TechniqueKind,
};
use ssm_scene::{Camera, Scene};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

/// Width of the panel beside the image, in logical pixels.
const PANEL_WIDTH: f32 = 340.0;

/// What `ssm view` shows: a scene, the techniques to switch between, and the image size.
pub struct ViewOptions {
    /// The scene as named on the command line (the window's title).
    pub scene_name: String,
    /// The scene.
    pub scene: Scene,
    /// The techniques, in key order (key 1 is the first), with their starting parameters.
    pub techniques: Vec<(&'static TechniqueInfo, ParamValues)>,
    /// Rendered image width in pixels.
    pub width: u32,
    /// Rendered image height in pixels.
    pub height: u32,
    /// Start with "count work" on.
    pub count_work: bool,
}

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

/// One technique the viewer can show.
struct Slot {
    info: &'static TechniqueInfo,
    params: ParamValues,
    /// Made when first shown and again after a parameter change (and, for
    /// the ground truth, which keeps the points it traced, after the camera moved).
    instance: Option<Box<dyn ShadowTechnique>>,
}

/// The camera as an orbit around its target.
struct Orbit {
    camera: Camera,
    up: Vec3,
}

impl Orbit {
    /// Turns the eye around the target: `yaw` about the up axis, `pitch`
    /// towards it, both in radians; stops short of the poles.
    fn rotate(&mut self, yaw: f32, pitch: f32) {
        let offset = Quat::from_axis_angle(self.up, yaw) * (self.camera.position - self.camera.target);
        let right = offset.cross(self.up).normalize_or_zero();
        let pitched = if right == Vec3::ZERO { offset } else { Quat::from_axis_angle(right, pitch) * offset };
        let polar = pitched.angle_between(self.up);
        let offset = if (0.05..std::f32::consts::PI - 0.05).contains(&polar) { pitched } else { offset };
        self.camera.position = self.camera.target + offset;
    }

    /// Scales the eye's distance to the target by `factor`, within the clip range.
    fn dolly(&mut self, factor: f32) {
        let offset = self.camera.position - self.camera.target;
        // min then max, not clamp: a camera whose far plane is within 8× its near plane has no such range.
        let distance = (offset.length() * factor).min(self.camera.far * 0.5).max(self.camera.near * 4.0);
        self.camera.position = self.camera.target + offset.normalize_or(Vec3::Z) * distance;
    }
}

/// What the last frame measured.
#[derive(Default)]
struct FrameReport {
    timings: Option<FrameTimings>,
    /// Error against the cached ground truth, averaged over the lights.
    error: Option<ErrorMetrics>,
    /// Why there is no error, or what went wrong.
    note: Option<String>,
    failure: Option<String>,
}

/// The counted work of one technique and setting, shown while it stays selected.
struct CountedWork {
    /// The slot and its parameters (as text) when counted: counting is redone when either changes.
    slot: usize,
    params: String,
    outcome: WorkOutcome,
}

enum WorkOutcome {
    Counted(FrameWork),
    /// Why it is not counted (the ground truth: [`crate::work::GROUND_TRUTH_NOT_COUNTED`]).
    NotCounted(&'static str),
    Failed(String),
}

/// The ground truth of the current view where the cache holds it.
struct TruthLookup {
    cache: ReferenceCache,
    cache_dir: PathBuf,
    /// Per light, for the current camera: `None` when not cached.
    images: Vec<Option<ssm_core::reference::ReferenceImage>>,
    covered: Vec<bool>,
}

struct Live {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    surface_config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    /// The image as egui samples it (gamma-encoded `Rgba8Unorm`): the composite target copied, or a view written.
    display: wgpu::Texture,
    display_id: egui::TextureId,
    scene_name: String,
    slots: Vec<Slot>,
    current: usize,
    orbit: Orbit,
    camera_moved: bool,
    dirty: bool,
    continuous: bool,
    frame: u64,
    report: FrameReport,
    truth: TruthLookup,
    /// The announcement to print once the frame showing it is presented.
    announce: Option<String>,
    /// Where the image's top-left pixel is in the window, in pixels.
    image_origin: [i64; 2],
    /// What the image shows.
    mode: ViewMode,
    /// The light whose visibility or error is shown (the shaded view has every light).
    light: usize,
    /// "count work": count the selected technique's work once per technique and setting.
    count_work: bool,
    /// The last counted work.
    work: Option<CountedWork>,
}

/// What the viewer's image shows (keys S, V, E, as in the HTML report).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ViewMode {
    /// The shaded image, every light.
    Shaded,
    /// One light's visibility, grey.
    Visibility,
    /// One light's signed error against the cached ground truth.
    SignedError,
}

impl ViewMode {
    fn name(self) -> &'static str {
        match self {
            Self::Shaded => "shaded",
            Self::Visibility => "visibility",
            Self::SignedError => "signed-error",
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

        let needs = crate::requirements_of(techniques.iter().map(|(info, params)| (*info, params)))?;
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

    /// Reads the G-buffer's points for the current view and looks the
    /// ground truth of each light up in the cache (the reference technique's
    /// current samples and seed; centre sampling unless it asks otherwise).
    fn look_up_truth(&mut self) -> Result<()> {
        let positions = self.renderer.read_positions()?;
        let normals = self.renderer.read_normals()?;
        self.truth.covered = positions.iter().map(|p| p[3] > 0.5).collect();
        // The reference technique's parameters, or its defaults when it is not among those shown.
        let defaults = ParamValues::defaults(ssm_core::reference::NAME, ssm_core::reference::PARAMS);
        let reference = self.slots.iter().find(|s| s.info.kind == TechniqueKind::GroundTruth).map_or(&defaults, |s| &s.params);
        // The parameters' declared ranges make the conversions exact.
        let sampling = ssm_core::reference::Sampling {
            samples_per_axis: u32::try_from(reference.int("samples")?)?,
            refine: u32::try_from(reference.int("refine")?)?,
        };
        let seed = u64::try_from(reference.int("seed")?)?;
        let footprint = reference.choice("footprint")? == "pixel";
        let points = surface_points(&positions, &normals, &self.renderer.scene.camera, footprint);
        self.truth.images = self
            .renderer
            .scene
            .light_frames
            .iter()
            .map(|frame| self.truth.cache.cached(&frame.light, &points, sampling, seed, &self.truth.cache_dir))
            .collect();
        Ok(())
    }

    /// Renders the selected technique when something changed, then draws the panel and presents.
    fn redraw(&mut self) -> Result<()> {
        if self.camera_moved {
            self.camera_moved = false;
            self.renderer.set_camera(&self.orbit.camera)?;
            // The ground truth keeps the points it traced: it must see the new view.
            for slot in self.slots.iter_mut().filter(|s| s.info.kind == TechniqueKind::GroundTruth) {
                slot.instance = None;
            }
            self.look_up_truth()?;
            self.dirty = true;
        }
        let mut encoder = self.renderer.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("view_encoder") });
        if self.dirty || self.continuous {
            self.dirty = false;
            self.render_technique(&mut encoder);
        }

        let raw_input = self.egui_state.take_egui_input(&self.window);
        let mut actions = Actions::default();
        let mut full_output = {
            let ctx = self.egui_ctx.clone();
            ctx.run_ui(raw_input, |ui| self.panel(ui, &mut actions))
        };
        self.egui_state.handle_platform_output(&self.window, std::mem::take(&mut full_output.platform_output));
        self.apply(actions);
        // egui's font atlas and images: uploaded before anything can return early, freed at the end.
        let gpu = self.renderer.gpu.clone();
        for (id, deltas) in full_output.textures_delta.set.drain() {
            for delta in &deltas {
                self.egui_renderer.update_texture(&gpu.device, &gpu.queue, id, delta);
            }
        }
        let freed: Vec<egui::TextureId> = full_output.textures_delta.free.drain().collect();
        let result = self.paint(encoder, full_output);
        for id in &freed {
            self.egui_renderer.free_texture(id);
        }
        result
    }

    /// Draws the panel (and the image in it) into the window and presents it.
    fn paint(&mut self, mut encoder: wgpu::CommandEncoder, full_output: egui::FullOutput) -> Result<()> {
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

    /// Renders one frame of the selected technique, measures it, and copies its shaded image to the display texture.
    fn render_technique(&mut self, encoder: &mut wgpu::CommandEncoder) {
        self.report = FrameReport::default();
        let slot = &mut self.slots[self.current];
        if slot.instance.is_none() {
            match self.renderer.create_technique(slot.info, &slot.params) {
                Ok(instance) => slot.instance = Some(instance),
                Err(error) => {
                    self.report.failure = Some(format!("{error}"));
                    return;
                }
            }
        }
        let Some(instance) = slot.instance.as_deref_mut() else { return };
        let timings = match self.renderer.render(instance, slot.info.name) {
            Ok(timings) => timings,
            Err(error) => {
                self.report.failure = Some(format!("{error}"));
                // A failed frame may have left the instance half-way: make it afresh next time.
                slot.instance = None;
                return;
            }
        };
        let name = slot.info.name;
        let params = slot.params.to_string();
        let traced_truth = slot.info.kind == TechniqueKind::GroundTruth;
        self.report.timings = Some(timings);
        self.count_work_once();
        // The ground truth just traced this view into the cache: the other techniques' error can now be shown.
        if traced_truth && let Err(error) = self.look_up_truth() {
            self.report.failure = Some(format!("{error}"));
        }
        let lights = self.renderer.scene.light_count();
        // Read back only what is shown or measured: the shaded view without a cached truth needs nothing.
        let read = self.mode != ViewMode::Shaded || self.truth.images.iter().all(Option::is_some);
        let visibility = match (0..if read { lights } else { 0 })
            .map(|light| self.renderer.read_visibility(light, name))
            .collect::<ssm_core::Result<Vec<_>>>()
        {
            Ok(visibility) => visibility,
            Err(error) => {
                self.report.failure = Some(format!("{error}"));
                return;
            }
        };
        self.measure_error(&visibility);
        self.light = self.light.min(lights.saturating_sub(1));
        let shown = self.show(encoder, &visibility);
        self.frame += 1;
        self.announce = Some(format!("ssm view: showing {name} [{params}] frame {} view {}", self.frame, shown.name()));
    }

    /// With "count work" on, counts the selected technique's work in one extra, untimed frame,
    /// unless it was counted at these settings already, and announces it on stdout.
    fn count_work_once(&mut self) {
        let slot = &self.slots[self.current];
        let params = slot.params.to_string();
        let counted = self.work.as_ref().is_some_and(|w| w.slot == self.current && w.params == params);
        if !self.count_work || counted {
            return;
        }
        let outcome = match crate::work::count(&mut self.renderer, slot.info, &slot.params) {
            Ok(Some(work)) => WorkOutcome::Counted(work),
            Ok(None) => WorkOutcome::NotCounted(crate::work::GROUND_TRUTH_NOT_COUNTED),
            Err(error) => WorkOutcome::Failed(format!("{error}")),
        };
        let summary = match &outcome {
            WorkOutcome::Counted(work) => {
                let totals = crate::work::Totals::of(work);
                format!(
                    "passes {} invocations {} texel_reads {}",
                    work.passes.len(),
                    crate::work::cell(totals.invocations()),
                    crate::work::cell(totals.texel_reads)
                )
            }
            WorkOutcome::NotCounted(why) => (*why).to_owned(),
            WorkOutcome::Failed(error) => format!("failed: {error}"),
        };
        let mut stdout = std::io::stdout();
        // A closed stdout (the caller stopped reading) must not stop the viewer.
        let _ = writeln!(stdout, "ssm view: counted {} [{params}] {summary}", slot.info.name);
        let _ = stdout.flush();
        self.work = Some(CountedWork { slot: self.current, params, outcome });
    }

    /// Puts the frame just rendered into the display texture as the chosen view; returns the
    /// view shown (the signed error falls back to the visibility without a cached ground truth).
    fn show(&mut self, encoder: &mut wgpu::CommandEncoder, visibility: &[Vec<f32>]) -> ViewMode {
        let (width, height) = (self.renderer.width(), self.renderer.height());
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let image = visibility.get(self.light).map_or(&[][..], Vec::as_slice);
        let truth = self.truth.images.get(self.light).and_then(Option::as_ref).map(|truth| truth.visibility.as_slice());
        let (mode, rgba): (ViewMode, Vec<u8>) = match (self.mode, truth) {
            (ViewMode::Shaded, _) => {
                match self.renderer.shade_on_gpu() {
                    Ok(shaded) => encoder.copy_texture_to_texture(shaded.as_image_copy(), self.display.as_image_copy(), size),
                    Err(error) => self.report.failure = Some(format!("{error}")),
                }
                return ViewMode::Shaded;
            }
            // The static report's heat map: red where darker than the truth, blue where lighter, full at 0.5.
            (ViewMode::SignedError, Some(truth)) => (
                ViewMode::SignedError,
                metrics::heat_map(truth, image, &self.truth.covered, 0.5).chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect(),
            ),
            _ => (
                ViewMode::Visibility,
                image.iter().map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8).flat_map(|v| [v, v, v, 255]).collect(),
            ),
        };
        if rgba.len() == (width * height * 4) as usize {
            self.renderer.gpu.queue.write_texture(
                self.display.as_image_copy(),
                &rgba,
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * width), rows_per_image: Some(height) },
                size,
            );
        }
        mode
    }

    /// The error of the frame just rendered against the cached ground truth, averaged over the lights.
    fn measure_error(&mut self, visibility: &[Vec<f32>]) {
        let (width, height) = (self.renderer.width() as usize, self.renderer.height() as usize);
        if self.truth.images.iter().any(Option::is_none) {
            let key = self.slots.iter().position(|s| s.info.kind == TechniqueKind::GroundTruth).map(|i| i + 1);
            self.report.note = Some(match key {
                Some(key) => format!("no ground truth cached for this view: key {key} traces it"),
                None => "no ground truth cached for this view".into(),
            });
            return;
        }
        let per_light: Vec<ErrorMetrics> = self
            .truth
            .images
            .iter()
            .zip(visibility)
            .filter_map(|(truth, image)| {
                truth.as_ref().map(|truth| {
                    metrics::compare_with_noise(&truth.visibility, Some(&truth.noise), image, &self.truth.covered, width, height)
                })
            })
            .collect();
        if !per_light.is_empty() {
            self.report.error = Some(crate::report::average(&per_light));
        }
    }

    /// The panel and the image; what the user did is collected in `actions`.
    fn panel(&mut self, ui: &mut egui::Ui, actions: &mut Actions) {
        let number_keys = [
            egui::Key::Num1,
            egui::Key::Num2,
            egui::Key::Num3,
            egui::Key::Num4,
            egui::Key::Num5,
            egui::Key::Num6,
            egui::Key::Num7,
            egui::Key::Num8,
            egui::Key::Num9,
            egui::Key::Num0,
        ];
        let typing = ui.ctx().egui_wants_keyboard_input();
        for (index, key) in number_keys.iter().enumerate().take(self.slots.len()) {
            if !typing && ui.input(|i| i.key_pressed(*key)) {
                actions.select = Some(index);
            }
        }
        for (key, mode) in [(egui::Key::S, ViewMode::Shaded), (egui::Key::V, ViewMode::Visibility), (egui::Key::E, ViewMode::SignedError)] {
            if !typing && ui.input(|i| i.key_pressed(key)) {
                actions.mode = Some(mode);
            }
        }
        if !typing && ui.input(|i| i.key_pressed(egui::Key::W)) {
            actions.count_work = Some(!self.count_work);
        }
        egui::Panel::right("view_panel").exact_size(PANEL_WIDTH).resizable(false).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.heading(format!("ssm view: {}", self.scene_name));
                ui.label(format!("{}×{} px on {}", self.renderer.width(), self.renderer.height(), self.renderer.gpu.describe()));
                ui.separator();
                ui.strong("technique (number keys)");
                for (index, slot) in self.slots.iter().enumerate() {
                    let label = format!("{}  {}", (index + 1) % 10, slot.info.name);
                    if ui.selectable_label(index == self.current, label).on_hover_text(slot.info.summary).clicked() {
                        actions.select = Some(index);
                    }
                }
                ui.separator();
                ui.strong("view (S, V, E)");
                ui.horizontal(|ui| {
                    for (mode, label) in
                        [(ViewMode::Shaded, "shaded"), (ViewMode::Visibility, "visibility"), (ViewMode::SignedError, "signed error")]
                    {
                        if ui.selectable_label(self.mode == mode, label).clicked() {
                            actions.mode = Some(mode);
                        }
                    }
                });
                let lights = self.renderer.scene.light_count();
                if lights > 1 && self.mode != ViewMode::Shaded {
                    let mut light = self.light;
                    ui.add(egui::Slider::new(&mut light, 0..=lights - 1).text("light"));
                    if light != self.light {
                        actions.light = Some(light);
                    }
                }
                if self.mode == ViewMode::SignedError {
                    ui.label(if self.truth.images.get(self.light).is_some_and(Option::is_some) {
                        "red: darker than the ground truth, blue: lighter; full colour at ±0.5"
                    } else {
                        "no cached ground truth for this view: showing the visibility"
                    });
                }
                ui.separator();
                let slot = &self.slots[self.current];
                ui.strong(format!("{} parameters", slot.info.name));
                for spec in slot.info.params {
                    if let Some(value) = parameter_widget(ui, spec, &slot.params) {
                        actions.set = Some((spec.name, value));
                    }
                }
                if !slot.info.params.is_empty() && ui.button("defaults").clicked() {
                    actions.defaults = true;
                }
                ui.checkbox(&mut self.continuous, "render continuously");
                let mut count_work = self.count_work;
                ui.checkbox(&mut count_work, "count work per pass (W)").on_hover_text(
                    "one extra, untimed frame per technique and setting: invocations, texel reads, bytes stored (shown under the times)",
                );
                if count_work != self.count_work {
                    actions.count_work = Some(count_work);
                }
            });
        });
        egui::CentralPanel::default().show(ui, |ui| {
            let pixels_per_point = ui.ctx().pixels_per_point();
            let size = egui::vec2(self.renderer.width() as f32, self.renderer.height() as f32) / pixels_per_point;
            let image = egui::Image::new(egui::load::SizedTexture::new(self.display_id, size)).sense(egui::Sense::click_and_drag());
            let response = ui.add(image);
            let rect = response.rect;
            self.image_origin = [rect.min.x * pixels_per_point, rect.min.y * pixels_per_point].map(|v| v.round() as i64);
            let drag = response.drag_delta();
            if drag != egui::Vec2::ZERO {
                actions.orbit = Some((-drag.x * 0.01, -drag.y * 0.01));
            }
            if response.hovered() {
                let scroll = ui.input(|i| i.smooth_scroll_delta.y);
                if scroll != 0.0 {
                    actions.dolly = Some((-scroll * 0.002).exp());
                }
            }
            ui.label("drag: orbit · wheel: closer / further");
            ui.separator();
            egui::ScrollArea::vertical().show(ui, |ui| self.report_ui(ui));
        });
    }

    fn report_ui(&self, ui: &mut egui::Ui) {
        if let Some(failure) = &self.report.failure {
            ui.colored_label(egui::Color32::from_rgb(230, 80, 80), failure);
        }
        self.error_ui(ui);
        ui.add_space(8.0);
        self.timings_ui(ui);
        if self.count_work {
            ui.add_space(8.0);
            self.work_ui(ui);
        }
    }

    /// The selected technique's counted work per pass: invocations (vertex, fragment, compute),
    /// texel reads and bytes stored to targets; `-` where not counted.
    fn work_ui(&self, ui: &mut egui::Ui) {
        use crate::work::{Totals, cell};
        let params = self.slots[self.current].params.to_string();
        let Some(work) = self.work.as_ref().filter(|w| w.slot == self.current && w.params == params) else {
            ui.label("counted work: at the next frame");
            return;
        };
        match &work.outcome {
            WorkOutcome::NotCounted(why) => {
                ui.label(format!("counted work: {why}"));
            }
            WorkOutcome::Failed(error) => {
                ui.colored_label(egui::Color32::from_rgb(230, 80, 80), format!("counting the work failed: {error}"));
            }
            WorkOutcome::Counted(frame) => {
                ui.strong("counted work per pass (one untimed frame, every light)");
                egui::Grid::new("view_work").striped(true).show(ui, |ui| {
                    for heading in ["pass", "vertex", "fragment", "compute", "texel reads", "target bytes"] {
                        ui.label(heading);
                    }
                    ui.end_row();
                    let totals = Totals::of(frame);
                    let rows = frame.passes.iter().map(|p| (p.name.as_str(), Totals::of_passes(frame, std::slice::from_ref(p))));
                    for (name, counts) in rows.chain([("frame", totals)]) {
                        ui.label(name);
                        ui.label(cell(counts.vertex_invocations));
                        ui.label(cell(counts.fragment_invocations));
                        ui.label(cell(counts.compute_invocations));
                        ui.label(cell(counts.texel_reads));
                        ui.label(counts.target_bytes.to_string());
                        ui.end_row();
                    }
                });
                for note in crate::work::notes(&[(self.slots[self.current].info.name, frame)]) {
                    ui.label(note.replace('`', ""));
                }
            }
        }
    }

    fn timings_ui(&self, ui: &mut egui::Ui) {
        if let Some(timings) = &self.report.timings {
            match timings.gpu_ms {
                Some(ms) => ui.strong(format!("frame {:.2} ms GPU ({:.1} ms wall)", ms, timings.cpu_wall_ms)),
                None => ui.strong(format!("frame {:.1} ms wall (no GPU timestamps)", timings.cpu_wall_ms)),
            };
            egui::Grid::new("view_passes").striped(true).show(ui, |ui| {
                for pass in &timings.passes {
                    ui.label(&pass.name);
                    ui.label(format!("light {}", pass.light));
                    ui.label(format!("{:.3} ms", pass.ms));
                    ui.end_row();
                }
            });
        }
    }

    fn error_ui(&self, ui: &mut egui::Ui) {
        match (&self.report.error, &self.report.note) {
            (Some(error), _) => {
                ui.strong("error against the cached ground truth");
                egui::Grid::new("view_error").striped(true).show(ui, |ui| {
                    for (name, value) in [
                        ("MAE (shadowed in either)", error.mae),
                        ("± the truth's own", error.truth_noise.unwrap_or(f64::NAN)),
                        ("MAE umbra+penumbra", error.mae_penumbra),
                        ("RMSE", error.rmse),
                        ("SSIM", error.ssim),
                        ("umbra leak", error.umbra_leak),
                        ("pixels > 0.05", error.frac_over_0_05),
                    ] {
                        ui.label(name);
                        ui.label(format!("{value:.4}"));
                        ui.end_row();
                    }
                });
            }
            (None, Some(note)) => {
                ui.label(note);
            }
            (None, None) => {}
        }
    }

    fn apply(&mut self, actions: Actions) {
        if let Some(index) = actions.select
            && index != self.current
        {
            self.current = index;
            self.dirty = true;
        }
        if let Some(mode) = actions.mode
            && mode != self.mode
        {
            self.mode = mode;
            self.dirty = true;
        }
        if let Some(light) = actions.light {
            self.light = light;
            self.dirty = true;
        }
        if let Some(count_work) = actions.count_work {
            self.count_work = count_work;
            // A frame to count at (once; later frames of the same setting count nothing).
            self.dirty |= count_work;
        }
        let slot = &mut self.slots[self.current];
        let mut params_changed = false;
        if let Some((name, text)) = actions.set {
            match slot.params.set(name, &text) {
                Ok(()) => params_changed = true,
                Err(error) => self.report.failure = Some(format!("{error}")),
            }
        }
        if actions.defaults {
            slot.params = slot.info.default_params();
            params_changed = true;
        }
        if params_changed {
            slot.instance = None;
            self.dirty = true;
            // The ground truth's samples, seed and footprint are part of its cache key.
            if slot.info.kind == TechniqueKind::GroundTruth
                && let Err(error) = self.look_up_truth()
            {
                self.report.failure = Some(format!("{error}"));
            }
        }
        if let Some((yaw, pitch)) = actions.orbit {
            self.orbit.rotate(yaw, pitch);
            self.camera_moved = true;
        }
        if let Some(factor) = actions.dolly {
            self.orbit.dolly(factor);
            self.camera_moved = true;
        }
        if self.dirty || self.camera_moved {
            self.window.request_redraw();
        }
    }
}

/// What the user asked for during one pass of the panel.
#[derive(Default)]
struct Actions {
    select: Option<usize>,
    /// A parameter's new value, as text for [`ParamValues::set`].
    set: Option<(&'static str, String)>,
    defaults: bool,
    mode: Option<ViewMode>,
    light: Option<usize>,
    /// "count work" switched on or off.
    count_work: Option<bool>,
    orbit: Option<(f32, f32)>,
    dolly: Option<f32>,
}

/// A widget for one parameter, built from its declared kind; the new value
/// as text when the user changed it.
fn parameter_widget(ui: &mut egui::Ui, spec: &ParamSpec, params: &ParamValues) -> Option<String> {
    let current = params.iter().find(|(name, _)| *name == spec.name).map(|(_, value)| value)?;
    let response = ui.horizontal(|ui| {
        match (spec.kind, current) {
            (ParamKind::Bool { .. }, ParamValue::Bool(mut value)) => {
                ui.checkbox(&mut value, spec.name).changed().then(|| value.to_string())
            }
            (ParamKind::Int { min, max, .. }, ParamValue::Int(mut value)) => {
                // A slider over a range of billions (a seed) is useless: drag the number instead.
                let widget: egui::Response = if max - min <= 100_000 {
                    ui.add(egui::Slider::new(&mut value, min..=max).logarithmic(min > 0 && max / min.max(1) >= 64).text(spec.name))
                } else {
                    ui.add(egui::DragValue::new(&mut value).range(min..=max)) | ui.label(spec.name)
                };
                widget.changed().then(|| value.to_string())
            }
            (ParamKind::Float { min, max, .. }, ParamValue::Float(mut value)) => {
                let logarithmic = min > 0.0 && max / min >= 100.0;
                ui.add(egui::Slider::new(&mut value, min..=max).logarithmic(logarithmic).text(spec.name))
                    .changed()
                    .then(|| format!("{value}"))
            }
            (ParamKind::Choice { options, .. }, ParamValue::Choice(value)) => {
                let mut chosen = value;
                egui::ComboBox::from_label(spec.name).selected_text(value).show_ui(ui, |ui| {
                    for option in options {
                        ui.selectable_value(&mut chosen, *option, *option);
                    }
                });
                (chosen != value).then(|| chosen.to_string())
            }
            _ => None,
        }
    });
    response.response.on_hover_text(spec.doc);
    response.inner
}
