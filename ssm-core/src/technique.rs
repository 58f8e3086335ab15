//! The plug-in interface: [`ShadowTechnique`], what a technique needs
//! ([`Requirements`]), and how it registers ([`TechniqueInfo`],
//! [`register_technique!`](crate::register_technique)).

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::frame::{Frame, SharedInputs};
use crate::gpu_scene::GpuScene;
use crate::params::{ParamSpec, ParamValues};

/// What a technique needs from the framework and the device. The framework
/// builds only the shared inputs some technique in use asks for, and refuses
/// with a typed error, before any rendering, when the device cannot meet them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Requirements {
    /// The camera G-buffer (depth, world position, normal).
    pub gbuffer: bool,
    /// Occluder/receiver roles: the technique draws [`Geometry::Occluders`](crate::Geometry)
    /// and [`Geometry::Receivers`](crate::Geometry) separately.
    pub roles: bool,
    /// Edge–face adjacency of the casting geometry (silhouettes).
    pub adjacency: bool,
    /// Device features it cannot run without.
    pub features: wgpu::Features,
    /// Largest 2D texture side it will allocate, in texels.
    pub max_texture_size: u32,
}

impl Requirements {
    /// Nothing at all.
    pub const NONE: Self = Self { gbuffer: false, roles: false, adjacency: false, features: wgpu::Features::empty(), max_texture_size: 0 };

    /// Everything either asks for.
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        Self {
            gbuffer: self.gbuffer || other.gbuffer,
            roles: self.roles || other.roles,
            adjacency: self.adjacency || other.adjacency,
            features: self.features | other.features,
            max_texture_size: self.max_texture_size.max(other.max_texture_size),
        }
    }

    /// Checks the device side: features and limits.
    ///
    /// # Errors
    /// [`Error::MissingFeatures`] or [`Error::LimitTooLow`] naming `technique`.
    pub fn check_device(&self, technique: &str, gpu: &GpuContext) -> Result<()> {
        let missing = self.features - gpu.features();
        if !missing.is_empty() {
            return Err(Error::MissingFeatures { technique: technique.into(), features: missing, adapter: gpu.describe() });
        }
        let allowed = gpu.device.limits().max_texture_dimension_2d;
        if self.max_texture_size > allowed {
            return Err(Error::LimitTooLow {
                technique: technique.into(),
                what: format!("{0}x{0} textures", self.max_texture_size),
                allowed: format!("{allowed}x{allowed}"),
            });
        }
        Ok(())
    }

    /// A short human description, e.g. `G-buffer, roles, FLOAT32_BLENDABLE`.
    #[must_use]
    pub fn describe(&self) -> String {
        let mut parts = Vec::new();
        if self.gbuffer {
            parts.push("G-buffer".to_owned());
        }
        if self.roles {
            parts.push("occluder/receiver roles".to_owned());
        }
        if self.adjacency {
            parts.push("mesh adjacency".to_owned());
        }
        for (name, _) in self.features.iter_names() {
            parts.push(name.to_owned());
        }
        if parts.is_empty() { "nothing".into() } else { parts.join(", ") }
    }
}

/// What a technique is given when it is created: the device, the uploaded
/// scene (geometry, camera, light frames), the shared inputs it declared, and
/// its parameter values. Pipelines and size-dependent resources are made here,
/// once, never per frame.
pub struct TechniqueSetup<'a> {
    /// The GPU.
    pub gpu: &'a GpuContext,
    /// The scene on the GPU.
    pub scene: &'a GpuScene,
    /// The scene on the CPU, for work a paper puts on the CPU (and the ground truth).
    pub cpu_scene: &'a ssm_scene::Scene,
    /// The shared inputs.
    pub shared: &'a SharedInputs,
    /// The visibility target of each light (`R32Float`, the view's size), the
    /// `output` that `render` will get for that light: bind groups that use it
    /// are made here, not per frame.
    pub outputs: &'a [wgpu::TextureView],
    /// Parameter values, complete.
    pub params: &'a ParamValues,
    /// Build the technique to count its work: true for the extra, untimed frame of
    /// `--count-work` ([`Renderer::count_work`](crate::Renderer::count_work)). The technique's
    /// shaders then count texel reads, atomics and storage bytes (its
    /// [`ReadCounts`](crate::read_counts::ReadCounts) enabled, the counting code compiled in),
    /// and [`ShadowTechnique::counted_work`] returns them. False for every timed frame.
    pub count_work: bool,
}

/// A soft-shadow technique.
///
/// Contract: `render` records the passes that compute, for every pixel of the
/// camera's view, the fraction of light `light` visible from the surface
/// seen there (1 = fully lit, 0 = fully occluded), into `output`, an
/// `R32Float` texture of the view's size that the framework has cleared to 1.
/// Values must be finite and in `[0, 1]`. Every pass goes through
/// [`Frame::render_pass`] or [`Frame::compute_pass`] with a label prefixed by
/// the technique's name, so it is labelled and timed (the frame offers no
/// other way to record one); the framework wraps the whole in a debug group
/// named after the technique.
pub trait ShadowTechnique {
    /// Records one frame's passes for `light` into `frame`, writing `output`.
    ///
    /// # Errors
    /// Anything the technique cannot do with this scene or frame.
    fn render(&mut self, frame: &mut Frame<'_>, light: usize, output: &wgpu::TextureView) -> Result<()>;

    /// Scalar diagnostics of the last frame, reported beside the error metrics
    /// (a share of work reused, a tile count...). Empty by default. May read
    /// the GPU: it is called after the frame has finished.
    fn diagnostics(&mut self, _gpu: &GpuContext) -> Vec<(String, f64)> {
        Vec::new()
    }

    /// What the shaders counted in the last frame, per pass, when built with
    /// [`TechniqueSetup::count_work`]: texel reads, atomics and storage bytes (the invocations and
    /// primitives the framework counts itself, from pipeline statistics). `None` by default: the
    /// technique does not count, and its reads are reported as unknown, not zero.
    ///
    /// # Errors
    /// A readback error.
    fn counted_work(&mut self, _gpu: &GpuContext) -> Result<Option<Vec<crate::work::ShaderWork>>> {
        Ok(None)
    }

    /// The images of the last frame named in `requested`, among the debug outputs its
    /// [`TechniqueInfo::debug_outputs`] declares (a share of work reused per pixel, say), each
    /// named as declared; `ssm render --debug-output NAME` writes them beside the visibility. Only
    /// what is asked is read back. Empty by default.
    ///
    /// # Errors
    /// A readback error.
    fn debug_outputs(&mut self, _gpu: &GpuContext, _requested: &[&str]) -> Result<Vec<ExtraImage>> {
        Ok(Vec::new())
    }
}

/// An image a technique can write besides its visibility when asked (`--debug-output NAME`),
/// listed by `ssm list`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DebugOutput {
    /// File stem and the name `--debug-output` takes.
    pub name: &'static str,
    /// What each pixel holds, and in which unit.
    pub doc: &'static str,
    /// A map of regions of the frame, drawn over the visibility in `ssm compare`'s HTML report,
    /// which therefore always asks for it.
    pub overlay: bool,
}

/// A named single-channel image a technique outputs besides its visibility.
#[derive(Clone, Debug, PartialEq)]
pub struct ExtraImage {
    /// File stem: `<name>.exr` and `<name>.png` are written.
    pub name: String,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Values, row-major from the top-left; the PNG maps [0, 1] to black–white.
    pub values: Vec<f32>,
    /// Shown over the visibility image in `ssm compare`'s HTML report (a map of regions of the
    /// frame, such as PVSM's tiles); it then has the frame's size.
    pub overlay: bool,
}

/// What a registered technique is for the tools that compare them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TechniqueKind {
    /// A real-time technique (or baseline): timed, compared and benchmarked.
    Realtime,
    /// The ground truth the others are measured against (`reference`).
    GroundTruth,
}

/// Where on the light a technique takes its visibility from, which decides what the framework
/// adds to it: the surface's own share of the light (`ssm-core/src/own_surface.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSampling {
    /// From the light's centre: one map, one frame or one set of silhouettes for the whole light
    /// (hard, pcss, vssm, sssm, atty, pvsm, wedges, and a new technique by default). Such a map
    /// cannot show the part of the light that a closed surface's own solid hides behind its
    /// tangent plane, so the framework gives it, in closed form, after the technique's passes:
    /// one compute pass per light, `<technique>_own_surface_share`, timed and counted with them.
    /// The technique needs the G-buffer for it ([`TechniqueInfo::needs`]).
    Centre,
    /// From points all over the light, each with the shared rules applied per point (multi-sm's
    /// map per light sample, the ground truth's rays): the surface's own share is in its answer
    /// already, and is not charged twice.
    PerSample,
}

/// How far from the light's normal a technique's maps see, which decides whether the framework
/// answers the receivers past them (`ssm-core/src/beyond_frame.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightView {
    /// Through one perspective frustum from the light: the shared light frame, a tile of it, or
    /// one per light sample (hard, vssm, sssm, atty, pvsm, and a new technique by default). Such a frustum stops at the frame's widest angle
    /// ([`MAX_HALF_ANGLE_TANGENT`](crate::MAX_HALF_ANGLE_TANGENT), about 84° off the light's
    /// normal). Where a light's frame reaches it, the framework renders the rest of the light's
    /// front hemisphere as a hemicube's four side faces and answers every receiver past the
    /// frame with a hard shadow from the light's centre (one pass per light,
    /// `<technique>_beyond_frame`, timed and counted with the technique's), and reports how many
    /// pixels it answered (the diagnostic `pixels_beyond_frame`): the technique's own method does
    /// not reach them. The technique needs the G-buffer for it ([`TechniqueInfo::needs`]).
    Frame,
    /// Through a perspective frame (the shared one, or one per light sample), and past its widest
    /// angle through a hemicube's four side faces of its own ([`SideFaceMaps`](crate::SideFaceMaps)),
    /// where it answers the receivers with its own method (pcss: its blocker search and filter on
    /// the face a receiver lies in; multi-sm: each sample's hard shadow through faces around that
    /// sample). The framework adds nothing.
    SideFaces,
    /// Over the light's whole front hemisphere: shadow volumes (wedges) and the ground truth's
    /// rays. The framework adds nothing.
    Hemisphere,
}

/// A named sweep a technique declares beside its parameters (the studies of
/// its paper), discovered by `ssm sweep --list-presets` and the preset benches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Preset {
    /// Name for `ssm sweep --preset`.
    pub name: &'static str,
    /// What it reproduces (the paper's figure or table) and how to read it.
    pub summary: &'static str,
    /// Scenes it is meant for (built-in names or manifest paths); the first is
    /// the one `ssm sweep --preset` uses without `--scene`.
    pub scenes: &'static [&'static str],
    /// `--vary` specifications: `<technique>.<param>[:<param>...]=<values>`,
    /// or `scene.<param>=...` (`light_scale`, `occluder_lift`, `occluder_shift`, `lights`, or
    /// a parameter of the built-in scene).
    pub varies: &'static [&'static str],
    /// The plot's x axis: `time` or a varied parameter (`mine.map_size`).
    pub x_axis: &'static str,
    /// The plot's y axis: `mae` (the headline error), `mae-penumbra`, `rmse`, `one-minus-ssim`, `flip` or `time`.
    pub y_axis: &'static str,
    /// Which pixels the errors cover: `all` or `receivers`.
    pub pixels: &'static str,
    /// The image size (width, height) the paper measured at, where it says: `ssm sweep --preset`
    /// renders at it unless `--width`/`--height` say otherwise (without one, 640×480).
    pub size: Option<(u32, u32)>,
    /// Fixed `--set` assignments of the paper's configuration that no `--vary` carries,
    /// `<technique>.<param>=<value>` (`reference.footprint=pixel`: a truth averaged over each
    /// pixel's footprint, for a technique that anti-aliases); the command line's `--set` of the
    /// same parameter wins.
    pub settings: &'static [&'static str],
}

impl Preset {
    /// A preset with the usual axes (time against the headline error, all pixels); set
    /// the other fields with struct update syntax.
    pub const DEFAULT: Self =
        Self { name: "", summary: "", scenes: &[], varies: &[], x_axis: "time", y_axis: "mae", pixels: "all", size: None, settings: &[] };
}

/// Size and field offsets of a Rust struct uploaded as a uniform
/// (`#[derive(UniformStruct)]` makes it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RustLayout {
    /// The Rust struct's name.
    pub name: &'static str,
    /// `size_of`, bytes.
    pub size: usize,
    /// Each field's name and byte offset.
    pub fields: &'static [(&'static str, usize)],
}

/// A Rust struct uploaded as a uniform: its layout, and the WGSL struct the shaders read it as,
/// written from the Rust one (`#[derive(UniformStruct)]`), so that the struct is declared once.
pub trait UniformStruct {
    /// Its layout.
    const LAYOUT: RustLayout;
    /// The WGSL struct's name.
    const WGSL_NAME: &'static str;
    /// The path a shader imports the declaration by: `rust/<WGSL_NAME>` (`// #import rust/...`).
    const WGSL_IMPORT: &'static str;
    /// The WGSL declaration (`struct <WGSL_NAME> { ... }`), each field's doc comment its comment:
    /// a technique lists it among its importable files, and its shaders `// #import` it.
    const WGSL: &'static str;
}

/// A uniform a technique uploads, paired with the WGSL struct its shaders read
/// it as: a test parses the WGSL with naga and fails on any difference of size
/// or field offset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UniformCheck {
    /// The WGSL struct's name.
    pub wgsl_struct: &'static str,
    /// A WGSL file that declares it (its imports are resolved).
    pub wgsl_source: &'static str,
    /// The technique's own importable files, as for
    /// [`create_shader_with_imports`](crate::shader::create_shader_with_imports).
    pub imports: &'static [(&'static str, &'static str)],
    /// The Rust side.
    pub rust: RustLayout,
}

/// A technique's registration: name, documentation, parameters, requirements and constructor.
///
/// Submit one per technique crate with [`register_technique!`](crate::register_technique).
pub struct TechniqueInfo {
    /// Unique name (`mine`), used on the command line.
    pub name: &'static str,
    /// One line: what it is.
    pub summary: &'static str,
    /// The paper it implements.
    pub paper: &'static str,
    /// Real-time technique or ground truth.
    pub kind: TechniqueKind,
    /// Where on the light it takes its visibility from: [`LightSampling::Centre`] gets the
    /// framework's own-surface share after its passes, [`LightSampling::PerSample`] does not.
    pub light_sampling: LightSampling,
    /// How far from the light's normal it sees: [`LightView::Frame`] gets the framework's
    /// answer past the frame's widest angle, [`LightView::SideFaces`] and
    /// [`LightView::Hemisphere`] do not.
    pub light_view: LightView,
    /// Its parameters.
    pub params: &'static [ParamSpec],
    /// Its requirements, which may depend on the parameter values.
    pub requirements: fn(&ParamValues) -> Result<Requirements>,
    /// Builds the technique (pipelines, textures) for a scene and size.
    pub create: fn(&TechniqueSetup<'_>) -> Result<Box<dyn ShadowTechnique>>,
    /// Sweeps reproducing its paper's studies.
    pub presets: &'static [Preset],
    /// Its quality knob in the cross-technique `trade` sweep, as the part of a
    /// `--vary` after the technique's name: `blocker_kernel:pcf_kernel=3:5,7:15`.
    /// `None` keeps it out of the trade plot.
    pub trade: Option<&'static str>,
    /// Its uniforms, checked against the WGSL structs that read them.
    pub uniforms: &'static [UniformCheck],
    /// The images it can write besides its visibility when asked ([`ShadowTechnique::debug_outputs`]).
    pub debug_outputs: &'static [DebugOutput],
    /// Extreme cases where its published method departs from the ground truth by more than the
    /// extremes matrix allows every technique (`tests/extremes.rs`), each with the error it is
    /// allowed there and the paper's reason. Empty for a technique that meets the common bound
    /// everywhere.
    pub limits: &'static [KnownLimit],
    /// The paper's own configuration, where the defaults depart from it: the cross-crate test
    /// `tests/paper_configuration.rs` holds every default no less accurate than it on the paper's
    /// own kind of scene.
    pub paper_configuration: PaperConfiguration,
}

/// A technique's paper's own configuration: the settings its published figures were measured
/// with, where the technique's defaults depart from them, and the scenes of the paper's own kind
/// on which the defaults must be no less accurate (`tests/paper_configuration.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperConfiguration {
    /// `param=value` of the technique's own parameters that give the paper's method; empty where
    /// the defaults are the paper's.
    pub settings: &'static [&'static str],
    /// The paper's own kind of scene: built-in names or manifests (from the workspace's root).
    pub scenes: &'static [&'static str],
    /// `param=value` of the ground truth the paper's output is judged against (`footprint=pixel`
    /// for a visibility averaged over each pixel's footprint); the defaults are judged against
    /// the ground truth at its defaults.
    pub truth: &'static [&'static str],
    /// Where one value of a parameter is decided by how the scene falls on a texel grid (its
    /// aliasing phase), `param=v1,v2,...`: both configurations are judged by their mean error over
    /// these values (a whole cycle of the phase) rather than at the default alone.
    pub averaged_over: Option<&'static str>,
}

impl PaperConfiguration {
    /// The defaults are the paper's configuration.
    pub const DEFAULTS: Self = Self { settings: &[], scenes: &[], truth: &[], averaged_over: None };
}

/// An extreme case where a technique's published method limits its accuracy: the extremes
/// matrix (`tests/extremes.rs`) allows it `mean_error` there instead of the common bound, and
/// fails when the declaration names no case of the matrix or is no longer needed (the technique
/// meets the common bound).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnownLimit {
    /// The case's name in the extremes matrix (`light resting on the receiver`, say).
    pub case: &'static str,
    /// Largest mean absolute error against the ground truth allowed there, over the pixels a
    /// surface covers, every light of the case.
    pub mean_error: f32,
    /// Why the method cannot do better there, citing the paper (section, figure or equation).
    pub reason: &'static str,
}

impl TechniqueInfo {
    /// Whether the framework follows the technique's passes with the own-surface share: it
    /// samples the light from its centre and is not the ground truth.
    #[must_use]
    pub fn gets_own_surface_share(&self) -> bool {
        self.light_sampling == LightSampling::Centre && self.kind != TechniqueKind::GroundTruth
    }

    /// Whether the framework answers, after the technique's passes, the receivers past the light
    /// frame's widest angle where a light's frame reaches it: it sees the light through one
    /// frustum ([`LightView::Frame`]) and is not the ground truth.
    #[must_use]
    pub fn gets_beyond_frame(&self) -> bool {
        self.light_view == LightView::Frame && self.kind != TechniqueKind::GroundTruth
    }

    /// What a renderer must build for the technique with `params`: its
    /// [`requirements`](TechniqueInfo::requirements), and the G-buffer that the framework's
    /// passes after it read when it gets one ([`TechniqueInfo::gets_own_surface_share`],
    /// [`TechniqueInfo::gets_beyond_frame`]).
    ///
    /// # Errors
    /// Whatever its requirements reject.
    pub fn needs(&self, params: &ParamValues) -> Result<Requirements> {
        let requirements = (self.requirements)(params)?;
        Ok(if self.gets_own_surface_share() || self.gets_beyond_frame() {
            requirements.union(Requirements { gbuffer: true, ..Requirements::NONE })
        } else {
            requirements
        })
    }

    /// Every parameter at its default.
    #[must_use]
    pub fn default_params(&self) -> ParamValues {
        ParamValues::defaults(self.name, self.params)
    }

    /// Default parameters with `name=value` assignments applied.
    ///
    /// # Errors
    /// [`Error::Param`] for an unknown name or bad value.
    pub fn params_from<'s>(&self, assignments: impl IntoIterator<Item = (&'s str, &'s str)>) -> Result<ParamValues> {
        let mut values = self.default_params();
        for (name, value) in assignments {
            values.set(name, value)?;
        }
        Ok(values)
    }
}

impl std::fmt::Debug for TechniqueInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TechniqueInfo").field("name", &self.name).field("summary", &self.summary).finish_non_exhaustive()
    }
}

inventory::collect!(TechniqueInfo);

/// Registers a technique and defines `pub fn link() -> &'static str` in the
/// calling crate: `ssm_core::register_technique!(INFO);`.
///
/// The crate must be linked into the binary for the registration to be
/// present; binaries call its `link()` (the `ssm` tool does so for every
/// technique crate through `ssm_techniques::link_all`; a standalone binary
/// calls its own technique's `link()`, then `ssm_bench::run()`).
#[macro_export]
macro_rules! register_technique {
    ($info:expr $(,)?) => {
        $crate::inventory::submit! { $info }

        /// Call from a binary so that the linker keeps this crate, and with it
        /// its technique's registration. Returns the technique's name.
        #[inline(never)]
        pub fn link() -> &'static str {
            // Named so that it cannot shadow a constant `$info` refers to.
            const SSM_REGISTERED_TECHNIQUE_NAME: &str = $info.name;
            SSM_REGISTERED_TECHNIQUE_NAME
        }
    };
}

/// Builds and checks everything a technique declared, then creates it.
pub(crate) fn create_checked(
    info: &TechniqueInfo,
    gpu: &GpuContext,
    (scene, cpu_scene): (&GpuScene, &ssm_scene::Scene),
    (shared, outputs): (&SharedInputs, &[wgpu::TextureView]),
    params: &ParamValues,
    count_work: bool,
) -> Result<Box<dyn ShadowTechnique>> {
    let requirements = info.needs(params)?;
    requirements.check_device(info.name, gpu)?;
    if requirements.gbuffer && shared.gbuffer.is_none() {
        return Err(Error::UndeclaredRequirement { technique: info.name.into(), input: "G-buffer (the renderer was built without it)" });
    }
    if requirements.adjacency && shared.adjacency.is_none() {
        return Err(Error::UndeclaredRequirement {
            technique: info.name.into(),
            input: "mesh adjacency (the renderer was built without it)",
        });
    }
    if requirements.roles && !scene.has_roles {
        return Err(Error::UndeclaredRequirement {
            technique: info.name.into(),
            input: "occluder/receiver roles (the renderer was built without them)",
        });
    }
    let setup = TechniqueSetup { gpu, scene, cpu_scene, shared, outputs, params, count_work };
    let technique = (info.create)(&setup)?;
    let technique = crate::after_technique::with_framework_passes(technique, &setup, info)?;
    let messages = gpu.take_errors();
    if messages.is_empty() { Ok(technique) } else { Err(Error::Gpu { during: format!("creating technique `{}`", info.name), messages }) }
}
