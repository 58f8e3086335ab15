//! `ssm view`: the live window (the viewer itself is the library's [`crate::view`]).

use anyhow::{Result, bail};
use ssm_core::TechniqueKind;

use super::{ImageSize, load_scene, params_for, parse_setting};
use crate::present::Format;
use crate::registry;

/// `ssm view`'s arguments.
#[derive(clap::Args)]
pub(super) struct ViewArgs {
    /// A built-in scene name, a scene manifest (.toml) or a model file.
    #[arg(long)]
    scene: String,
    /// Technique names in key order (key 1 is the first), comma-separated; default: every real-time technique, then `reference`.
    #[arg(long, value_delimiter = ',')]
    technique: Vec<String>,
    #[command(flatten)]
    size: ImageSize,
    /// Starting parameter `<technique>.<param>=<value>`; repeatable.
    #[arg(long = "set", value_name = "TECHNIQUE.PARAM=VALUE")]
    settings: Vec<String>,
    /// Start with "count work" on (the W key switches it): the panel shows the selected
    /// technique's counted work per pass, counted once per technique and setting.
    #[arg(long)]
    count_work: bool,
}

/// Resolves the techniques (in key order) and their starting parameters, then opens the window.
pub(super) fn run(args: &ViewArgs) -> Result<()> {
    let registry = registry()?;
    let scene = load_scene(&args.scene, Format::Text)?;
    let settings: Vec<(&str, &str, &str)> = args.settings.iter().map(|s| parse_setting(s)).collect::<Result<_>>()?;
    let names: Vec<&str> = if args.technique.is_empty() {
        let mut names: Vec<&str> = registry.iter().filter(|i| i.kind == TechniqueKind::Realtime).map(|i| i.name).collect();
        names.extend(registry.iter().filter(|i| i.kind == TechniqueKind::GroundTruth).map(|i| i.name));
        names
    } else {
        args.technique.iter().map(String::as_str).collect()
    };
    for (technique, _, _) in &settings {
        if !names.contains(technique) {
            bail!("--set names technique `{technique}`, which is not among those shown ({})", names.join(","));
        }
    }
    let techniques = names
        .iter()
        .map(|name| {
            let info = registry.get(name)?;
            Ok((info, params_for(info, &settings)?))
        })
        .collect::<Result<Vec<_>>>()?;
    crate::view::run(crate::view::ViewOptions {
        scene_name: args.scene.clone(),
        scene,
        techniques,
        width: args.size.width,
        height: args.size.height,
        count_work: args.count_work,
    })
}
