//! The error type of ssm-core.

use std::path::PathBuf;

use crate::context::ContextError;
use crate::params::ParamError;

/// Everything that can go wrong between a scene and a written image.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// No GPU context.
    #[error(transparent)]
    Context(#[from] ContextError),
    /// The scene is invalid.
    #[error(transparent)]
    Scene(#[from] ssm_scene::SceneError),
    /// A parameter name or value is wrong.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// No registered technique has this name.
    #[error("unknown technique `{name}`; registered techniques: {known}")]
    UnknownTechnique {
        /// Name asked for.
        name: String,
        /// Names registered.
        known: String,
    },
    /// Two registrations share a name.
    #[error("two techniques are registered under the name `{name}`: {first} and {second}")]
    DuplicateTechnique {
        /// The shared name.
        name: String,
        /// Summary of the first registration.
        first: String,
        /// Summary of the second.
        second: String,
    },
    /// The device lacks features the technique needs.
    #[error("technique `{technique}` needs device features {features:?} that this adapter ({adapter}) does not offer")]
    MissingFeatures {
        /// Technique name.
        technique: String,
        /// The missing features.
        features: wgpu::Features,
        /// Adapter description.
        adapter: String,
    },
    /// The device's limits are too small for the technique as configured.
    #[error("technique `{technique}` needs {what}, but this adapter allows {allowed}")]
    LimitTooLow {
        /// Technique name.
        technique: String,
        /// What is needed.
        what: String,
        /// What the adapter allows.
        allowed: String,
    },
    /// A technique used a shared input it did not declare in its requirements.
    #[error("technique `{technique}` uses the shared {input} but did not declare it in its Requirements")]
    UndeclaredRequirement {
        /// Technique name.
        technique: String,
        /// The shared input (`G-buffer`, `adjacency`).
        input: &'static str,
    },
    /// wgpu reported validation or out-of-memory errors.
    #[error("GPU error during {during}: {}", messages.join("; "))]
    Gpu {
        /// What was being done.
        during: String,
        /// wgpu's messages.
        messages: Vec<String>,
    },
    /// A shader failed to assemble.
    #[error("shader `{shader}`: {problem}")]
    Shader {
        /// Shader label.
        shader: String,
        /// What is wrong (an unknown import, say).
        problem: String,
    },
    /// A technique wrote non-finite or out-of-range visibility.
    #[error(
        "technique `{technique}` wrote {count} visibility values that are not finite numbers in [0, 1] (first at pixel ({x}, {y}): {value})"
    )]
    InvalidOutput {
        /// Technique name.
        technique: String,
        /// Number of bad pixels.
        count: usize,
        /// First bad pixel's x.
        x: u32,
        /// First bad pixel's y.
        y: u32,
        /// Its value.
        value: f32,
    },
    /// The technique cannot represent this scene at these settings (its
    /// approximation breaks down there): a refusal, not a wrong image.
    #[error("technique `{technique}` cannot render this scene: {reason}")]
    Unrepresentable {
        /// Technique name.
        technique: String,
        /// What about the scene or the settings is beyond it, and what would help.
        reason: String,
    },
    /// The technique failed in a way of its own.
    #[error("technique `{technique}`: {message}")]
    Technique {
        /// Technique name.
        technique: String,
        /// What went wrong.
        message: String,
    },
    /// Reading a GPU resource back failed.
    #[error("reading back {what} failed")]
    Readback {
        /// The resource.
        what: String,
        /// Why.
        #[source]
        source: BoxedError,
    },
    /// The requested image size is unusable.
    #[error("image size {width}x{height} is invalid: {problem}")]
    InvalidSize {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Why.
        problem: String,
    },
    /// Reading an image file failed.
    #[error("{}: cannot read", file.display())]
    Read {
        /// The file.
        file: PathBuf,
        /// Why.
        #[source]
        source: BoxedError,
    },
    /// Writing an output file failed.
    #[error("{}: cannot write", file.display())]
    Write {
        /// The file.
        file: PathBuf,
        /// Why.
        #[source]
        source: BoxedError,
    },
}

/// A cause from any library (I/O, image codecs, wgpu), kept for `source()`.
pub type BoxedError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// A cause that is only a sentence (no underlying error to keep).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Reason(pub String);

impl Error {
    /// [`Error::Write`] for `file`, caused by `source`.
    pub fn write(file: impl Into<PathBuf>, source: impl Into<BoxedError>) -> Self {
        Self::Write { file: file.into(), source: source.into() }
    }

    /// [`Error::Readback`] of `what`, caused by `source`.
    pub fn readback(what: impl Into<String>, source: impl Into<BoxedError>) -> Self {
        Self::Readback { what: what.into(), source: source.into() }
    }
}

/// Shorthand for results of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
