//! What a measurement needs: what the renderer must build for a set of techniques and for the
//! outputs every command reads ([`requirements_of`], [`output_requirements`]), whether an adapter
//! runs a technique ([`support_on`]), and which debug outputs to read ([`debug_outputs_for`],
//! [`check_debug_outputs`]).

use ssm_core::{GpuContext, ParamValues, Requirements, TechniqueInfo};

/// The shared inputs every output of `ssm render` needs: the G-buffer, for
/// the shaded image and the world positions.
#[must_use]
pub fn output_requirements() -> Requirements {
    Requirements { gbuffer: true, ..Requirements::NONE }
}

/// What the renderer must build for `techniques` (the union of what each needs, the framework's
/// own-surface share included: `TechniqueInfo::needs`) and for the
/// outputs every command reads ([`output_requirements`]).
///
/// # Errors
/// A technique whose parameters its requirements reject.
pub fn requirements_of<'a>(techniques: impl IntoIterator<Item = (&'a TechniqueInfo, &'a ParamValues)>) -> ssm_core::Result<Requirements> {
    let mut needs = output_requirements();
    for (info, params) in techniques {
        needs = needs.union(info.needs(params)?);
    }
    Ok(needs)
}

/// The debug outputs to ask of `info`: those named in `asked` (`all`: every one it declares),
/// plus its overlays when `overlays` (the HTML report draws them).
#[must_use]
pub fn debug_outputs_for(info: &TechniqueInfo, asked: &[String], overlays: bool) -> Vec<&'static str> {
    let all = asked.iter().any(|a| a == DEBUG_OUTPUT_ALL);
    info.debug_outputs.iter().filter(|o| all || asked.iter().any(|a| a == o.name) || (overlays && o.overlay)).map(|o| o.name).collect()
}

/// `--debug-output all`: every debug output of every technique run.
pub const DEBUG_OUTPUT_ALL: &str = "all";

/// Checks that every name in `asked` is a debug output of at least one of `infos` (or `all`).
///
/// # Errors
/// A name none of them offers; the message lists what each offers.
pub fn check_debug_outputs(asked: &[String], infos: &[&TechniqueInfo]) -> anyhow::Result<()> {
    for name in asked.iter().filter(|a| *a != DEBUG_OUTPUT_ALL) {
        if !infos.iter().any(|info| info.debug_outputs.iter().any(|o| o.name == name)) {
            let offered: Vec<String> = infos
                .iter()
                .map(|info| {
                    let names: Vec<&str> = info.debug_outputs.iter().map(|o| o.name).collect();
                    format!("{}: {}", info.name, if names.is_empty() { "none".to_owned() } else { names.join(", ") })
                })
                .collect();
            anyhow::bail!("--debug-output {name}: no technique run offers it ({}; `ssm list` describes them)", offered.join("; "));
        }
    }
    Ok(())
}

/// Whether `gpu` can run `info` at its default parameters, as a short phrase.
#[must_use]
pub fn support_on(gpu: &GpuContext, info: &TechniqueInfo) -> String {
    match (info.requirements)(&info.default_params()).and_then(|r| r.check_device(info.name, gpu)) {
        Ok(()) => "yes".into(),
        Err(e) => format!("no: {e}"),
    }
}
