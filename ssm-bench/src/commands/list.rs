//! `ssm list` (the registered techniques) and `ssm scenes` (the built-in scenes).

use std::io::Write;

use anyhow::{Context, Result};
use ssm_core::GpuContext;
use ssm_scene::BUILTIN_SCENES;

use crate::measure::needs::support_on;
use crate::present::{Format, say};
use crate::registry;

/// `ssm list`: every registered technique, its paper, needs, parameters and debug outputs, and
/// whether this adapter runs it.
pub(super) fn techniques(format: Format) -> Result<()> {
    let registry = registry()?;
    let gpu = GpuContext::new();
    if format == Format::Json {
        let techniques = registry
            .iter()
            .map(|info| {
                let requirements = (info.requirements)(&info.default_params())?;
                Ok(serde_json::json!({
                    "name": info.name,
                    "summary": info.summary,
                    "paper": info.paper,
                    "kind": format!("{:?}", info.kind).to_lowercase(),
                    "needs": requirements.describe(),
                    "runs_here": gpu.as_ref().ok().map(|gpu| support_on(gpu, info)),
                    "params": info.params.iter().map(|spec| serde_json::json!({
                        "name": spec.name,
                        "default": spec.default_value().to_string(),
                        "range": spec.range_text(),
                        "doc": spec.doc,
                    })).collect::<Vec<_>>(),
                    "debug_outputs": info.debug_outputs.iter().map(|o| serde_json::json!({
                        "name": o.name, "doc": o.doc, "overlay": o.overlay,
                    })).collect::<Vec<_>>(),
                    "presets": info.presets.iter().map(|p| p.name).collect::<Vec<_>>(),
                    "paper_configuration": (!info.paper_configuration.settings.is_empty()).then(|| serde_json::json!({
                        "settings": info.paper_configuration.settings,
                        "scenes": info.paper_configuration.scenes,
                        "truth": info.paper_configuration.truth,
                        "averaged_over": info.paper_configuration.averaged_over,
                    })),
                }))
            })
            .collect::<Result<Vec<_>>>()?;
        let adapter = gpu.as_ref().map_or(serde_json::Value::Null, |gpu| serde_json::Value::String(gpu.describe()));
        say!("{}", serde_json::to_string_pretty(&serde_json::json!({ "adapter": adapter, "techniques": techniques }))?);
        return Ok(());
    }
    match &gpu {
        Ok(gpu) => say!("adapter: {}\n", gpu.describe()),
        Err(e) => say!("adapter: none ({e})\n"),
    }
    for info in registry.iter() {
        say!("{}: {}", info.name, info.summary);
        say!("  paper: {}", info.paper);
        let paper = info.paper_configuration;
        if !paper.settings.is_empty() {
            let settings: Vec<String> = paper.settings.iter().map(|s| format!("--set {}.{s}", info.name)).collect();
            let truth: String = paper.truth.iter().map(|s| format!(" --set reference.{s}")).collect();
            say!("  the paper's configuration: {}{truth} (its scenes: {})", settings.join(" "), paper.scenes.join(", "));
        }
        let requirements = (info.requirements)(&info.default_params())?;
        say!("  needs: {}", requirements.describe());
        if let Ok(gpu) = &gpu {
            say!("  runs here: {}", support_on(gpu, info));
        }
        for spec in info.params {
            say!("  --set {}.{}={}  ({}; {})", info.name, spec.name, spec.default_value(), spec.range_text(), spec.doc);
        }
        for output in info.debug_outputs {
            say!("  --debug-output {}  ({})", output.name, output.doc);
        }
        say!("");
    }
    Ok(())
}

/// `ssm list --parameters-of <technique>`: its README's generated parameter table.
pub(super) fn parameters_markdown(name: &str) -> Result<()> {
    let info = registry()?.get(name)?;
    say!("{}", crate::docs::parameters_markdown(info)?.trim_end());
    Ok(())
}

/// `ssm scenes`: the built-in scenes, their triangle counts and parameters.
pub(super) fn scenes(format: Format) -> Result<()> {
    if format == Format::Json {
        let scenes: Vec<serde_json::Value> = BUILTIN_SCENES
            .iter()
            .map(|scene| {
                serde_json::json!({
                    "name": scene.name,
                    "triangles": scene.build().triangle_count(),
                    "summary": scene.summary,
                    "params": scene.params.iter().map(|p| serde_json::json!({
                        "name": p.name, "default": p.default, "min": p.min, "max": p.max, "doc": p.doc,
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        say!("{}", serde_json::to_string_pretty(&scenes)?);
        return Ok(());
    }
    for scene in BUILTIN_SCENES {
        let built = scene.build();
        say!("{:<16} {:>7} triangles  {}", scene.name, built.triangle_count(), scene.summary);
        for param in scene.params {
            say!("{:<26}{}:{}={}  ({} to {}) {}", "", scene.name, param.name, param.default, param.min, param.max, param.doc);
        }
    }
    Ok(())
}
