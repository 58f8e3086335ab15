//! The ssm framework: real-time soft-shadow techniques as plug-ins behind one
//! trait, run on identical scenes, timed per pass, compared on the same pixels.
//!
//! - [`GpuContext`]: headless wgpu device with optional features negotiated.
//! - [`ShadowTechnique`], [`Requirements`], [`TechniqueInfo`] and
//!   [`register_technique!`]: the plug-in interface; [`Registry`] finds them.
//! - [`ParamSpec`] / [`ParamValues`]: parameters settable from strings.
//! - [`Renderer`]: uploads a [`Scene`](ssm_scene::Scene), builds the shared
//!   inputs on demand ([`GBuffer`], [`LightFrame`]s, adjacency), runs a
//!   technique into per-light screen-space visibility targets (`R32Float`,
//!   1 = lit), times every pass ([`FrameTimings`]) and reads results back.
//! - [`LightDepthMap`]: the light-space depth pass most techniques start from;
//!   [`ScreenPass`]: a full-screen pass over the G-buffer for one light.
//! - [`image_io`]: EXR and PNG output.
//!
//! Adding a technique: `ssm new <name>` writes a crate that implements the trait
//! (docs/adding-a-technique.md). The technique crates are used as below; here with the
//! ground truth this crate holds (`reference`: shadow rays traced on the CPU):
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ssm_core::{GpuContext, Registry, Renderer};
//!
//! ssm_core::reference::link();
//! let gpu = GpuContext::new()?;
//! let scene = ssm_scene::builtin("parallel-square")?.build();
//! let info = Registry::global()?.get("reference")?;
//! let params = info.params_from([("samples", "2"), ("cache", "false")])?;
//! let mut renderer = Renderer::new(&gpu, &scene, 32, 32, &(info.requirements)(&params)?)?;
//! let mut technique = renderer.create_technique(info, &params)?;
//! renderer.render(technique.as_mut(), info.name)?;
//! // Per pixel, the fraction of the light each point sees (1 lit, 0 in umbra).
//! let visibility = renderer.read_visibility(0, info.name)?;
//! assert!(visibility.iter().any(|v| *v == 0.0) && visibility.iter().any(|v| *v == 1.0));
//! # Ok(())
//! # }
//! ```

// The derives name this crate `::ssm_core`, also when used inside it.
extern crate self as ssm_core;

mod after_technique;
mod beyond_frame;
mod composite;
mod context;
mod error;
mod frame;
mod gbuffer;
mod gpu_scene;
pub mod image_io;
mod light_depth;
mod light_frame;
pub mod metrics;
mod own_surface;
mod params;
pub mod passes;
pub mod read_counts;
pub mod readback;
pub mod reference;
mod registry;
mod renderer;
mod screen_pass;
pub mod shader;
mod side_faces;
mod technique;
mod timing;
pub mod work;

pub use beyond_frame::{BEYOND_FRAME_DIAGNOSTIC, BEYOND_FRAME_PASS, beyond_frame_label};
pub use context::{ContextError, GpuContext, OPTIONAL_FEATURES};
pub use error::{BoxedError, Error, Reason, Result};
pub use frame::{CountedComputePass, CountedRenderPass, Frame, SharedInputs};
pub use gbuffer::GBuffer;
pub use gpu_scene::{CameraUniform, Geometry, GpuScene, ROLE_CASTS, ROLE_RECEIVES, SURFACE_CLOSED, SceneVertex};
pub use light_depth::{
    DepthBiasUniform, LightDepthMap, LightDepthMapDesc, NO_SURFACE, ReceiverModel, SHADOW_MAP_MAX_SIZE, SHADOW_MAP_MIN_SIZE, ShadowMapBias,
    screen_space_requirements,
};
pub use light_frame::{LightFrame, LightFrameUniform, MAX_HALF_ANGLE_TANGENT, MAX_WIDENED_HALF_ANGLE_TANGENT};
pub use own_surface::{OWN_SURFACE_SHARE_PASS, own_surface_share_label};
pub use params::{Choice, ParamError, ParamKind, ParamSpec, ParamValue, ParamValues, Settings, concat_params};
pub use registry::Registry;
pub use renderer::{Renderer, VISIBILITY_FORMAT, VISIBILITY_RANGE_TOLERANCE};
pub use screen_pass::ScreenPass;
pub use side_faces::{SIDE_FACE_WIDTH, SideFaceFrames, SideFaceMaps};
pub use ssm_derive::{Choice, Settings, UniformStruct};
pub use technique::{
    DebugOutput, ExtraImage, KnownLimit, LightSampling, LightView, PaperConfiguration, Preset, Requirements, RustLayout, ShadowTechnique,
    TechniqueInfo, TechniqueKind, TechniqueSetup, UniformCheck, UniformStruct,
};
pub use timing::{FrameTimings, MAX_TIMED_PASSES, PassTimer, PassTiming, TimingSource};
pub use work::{FrameWork, PassWork, ShaderWork};

/// Re-exported so that technique crates can register without depending on it.
pub use inventory;
/// Re-exported so that technique crates use the same scene types.
pub use ssm_scene;
