//! `ssm view`: a live window onto one scene. The shaded image of the
//! selected technique fills the window; a panel beside it lists the
//! techniques (number keys switch between them), builds a widget for each
//! of the selected technique's parameters from its declared
//! [`ParamSpec`](ssm_core::ParamSpec)s, and shows the last frame's per-pass GPU times and, where
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
//! technique's counted work per pass ([`crate::measure::work`]): one extra, untimed frame counted after the
//! first frame of each technique and setting, not every frame (and announced on stdout as
//! `ssm view: counted <technique> [<params>] passes <n> invocations <n|-> texel_reads <n|->`).
//!
//! Each image shown is announced on stdout as one line,
//! `ssm view: showing <technique> [<params>] frame <n> view <view> image <x>,<y> <w>x<h>`,
//! with the image's place in the window in pixels, so that scripts (and the
//! Xvfb test) know what the window shows and where.
//!
//! Here: what `ssm view` is given and the viewer's state; `window.rs` the window (its event
//! loop, surface and painting), `ui.rs` the panel (its widgets and keys, and what they change),
//! `render_loop.rs` a frame (the selected technique rendered, its error against the cached
//! ground truth, its counted work, the image shown).

mod render_loop;
mod ui;
mod window;

use std::path::PathBuf;
use std::sync::Arc;

use glam::{Quat, Vec3};
use ssm_core::metrics::ErrorMetrics;
use ssm_core::reference::ReferenceCache;
use ssm_core::{FrameTimings, FrameWork, ParamValues, Renderer, ShadowTechnique, TechniqueInfo};
use ssm_scene::{Camera, Scene};
use winit::window::Window;

pub use window::run;

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
    /// Why it is not counted (the ground truth: [`crate::data::work::GROUND_TRUTH_NOT_COUNTED`]).
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
