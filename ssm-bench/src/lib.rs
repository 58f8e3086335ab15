//! The `ssm` command-line tool as a library, and support for it and the criterion benches: [`run`]
//! (the whole command line, for any binary that links techniques and calls it) and the registry
//! (every technique crate linked through the `ssm-techniques` facade). The modules, in the order
//! a command goes through them (its arguments, then the frames, then the rows, then the reports):
//!
//! - [`sweep`]: a sweep's plan (the presets, the grid, the scene's overrides), and [`shard`]: a
//!   sweep split across machines and merged back;
//! - [`measure`]: techniques rendered and timed, their work counted, compared with the ground
//!   truth, the pixels the errors cover, what a run writes to disk (its images, `timings.json`);
//! - [`data`]: what was measured, as rows, CSV and JSON, and the counted work's totals;
//! - [`present`]: the reports, from the data alone: Markdown, the HTML page and its viewer's data,
//!   the charts, the tables of counted work, a sweep's outputs;
//! - [`stats`]: the statistics (the median and quartiles, the errors of several lights as one,
//!   the Pareto front);
//! - [`view`]: the live viewer (`ssm view`): its window, its panel and its render loop;
//! - [`docs`]: a technique's parameter table for its README; [`bench`](mod@bench): the benches' image size.
//!
//! # Example
//!
//! The `ssm` binary of a crate of one's own (what `ssm new --standalone` writes): link the
//! techniques, then hand over the command line.
//!
//! ```no_run
//! fn main() -> std::process::ExitCode {
//!     ssm_techniques::link_all(); // or one crate's `ssm_mine::link()`
//!     ssm_bench::run()
//! }
//! ```

pub mod bench;
mod commands;
pub mod data;
pub mod docs;
pub mod measure;
pub mod present;
pub mod shard;
pub mod stats;
pub mod sweep;
pub mod view;

use std::process::ExitCode;

use ssm_core::Registry;

/// Runs the `ssm` command line: parses the arguments (clap), runs the command and returns its exit
/// status. A failure prints one line, `error:` and its causes, on stderr and exits 1; a bad
/// command line prints clap's message and exits 2; a reader that stopped reading (`ssm list |
/// head`) is not a failure.
///
/// The techniques are those of [`registry`]: every technique crate of the workspace, and any
/// other crate linked into the binary that registers one (`ssm_core::register_technique!`). A
/// binary with a technique of its own calls that crate's `link()`, then this:
///
/// ```no_run
/// fn main() -> std::process::ExitCode {
///     // my_technique::link(); (keeps the crate, and with it its registration, in the binary)
///     ssm_bench::run()
/// }
/// ```
///
/// Call it first thing in `main`, before spawning any thread (a `link()` before it is fine: it
/// starts none): without `XDG_RUNTIME_DIR` it sets `NODEVICE_SELECT=1` for the process (which keeps
/// Mesa's device-selection layer from looking for a Wayland session), and changing the
/// environment is sound only while no other thread exists.
#[must_use]
pub fn run() -> ExitCode {
    quiet_window_system_layers();
    match commands::parse_and_run() {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that stopped reading (`ssm list | head`) is not a failure.
        Err(error)
            if error.chain().any(|e| e.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)) =>
        {
            ExitCode::SUCCESS
        }
        Err(error) => {
            // One line: the error and its causes.
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

/// Without a Wayland session (no `XDG_RUNTIME_DIR`), Mesa's device-selection
/// Vulkan layer still tries to connect to one when wgpu enables the Wayland
/// surface extension, and libwayland prints `error: XDG_RUNTIME_DIR is invalid
/// or not set` on a perfectly good offscreen run. ssm never presents to a
/// window and picks its adapter itself, so the layer is switched off (its own
/// documented switch) for this process.
fn quiet_window_system_layers() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() && std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: called only by `run`, whose contract is to be called first thing in `main`,
        // before any thread exists, so no other thread can read the environment while it changes.
        #[allow(unsafe_code)]
        unsafe {
            std::env::set_var("NODEVICE_SELECT", "1");
        }
    }
}

/// The registry, with every technique crate linked (through the
/// `ssm-techniques` facade: a new technique crate is one line in its manifest).
///
/// # Errors
/// A duplicate technique name.
pub fn registry() -> ssm_core::Result<&'static Registry> {
    ssm_techniques::registry()
}
