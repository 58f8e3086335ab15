//! `ssm merge`: the shards of a sweep (`ssm sweep --shard K/N` outputs) put back together into
//! the outputs the unsharded sweep writes.

use std::path::PathBuf;

use anyhow::{Context, Result};

use crate::present::Format;
use crate::present::sweep::{Cost, ErrorAxis, SweepOutput, WorkUnit, write_sweep};
use crate::{shard, sweep};

/// `ssm merge`'s arguments.
#[derive(clap::Args)]
pub(super) struct MergeArgs {
    /// The shards' output folders (each holds sweep.csv and shard.json), every shard of one sweep once.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// `text`: a line per point on stdout; `json`: the rows and their varied values as one JSON document.
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Output directory: sweep.csv, sweep.md, sweep.png and sweep.svg, as the unsharded sweep writes them.
    #[arg(long)]
    out: PathBuf,
}

/// Merges the shards (checking that they are one sweep's, each once) and writes what the
/// unsharded sweep writes.
pub(super) fn run(args: &MergeArgs) -> Result<()> {
    let merged = shard::merge(&args.shards)?;
    let identity = &merged.identity;
    let error = <ErrorAxis as clap::ValueEnum>::from_str(&identity.error, true)
        .map_err(|e| anyhow::anyhow!("the shards' error axis `{}`: {e}", identity.error))?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    if merged.adapters.len() > 1 {
        eprintln!(
            "note: the shards ran on {} adapters ({}); compare times within one shard's rows only",
            merged.adapters.len(),
            merged.adapters.join("; ")
        );
    }
    let adapter = merged.adapters.join(" + ");
    let along_x = sweep::in_step_with(&identity.varies, &identity.x_axis);
    let output = SweepOutput {
        out: &args.out,
        name: identity.preset.as_deref().unwrap_or("custom"),
        adapter: &adapter,
        size: identity.size,
        frames: identity.frames,
        scene_spec: &identity.scene,
        x_axis: &identity.x_axis,
        along_x: &along_x,
        error,
        cost: <Cost as clap::ValueEnum>::from_str(&identity.cost, true)
            .map_err(|e| anyhow::anyhow!("the shards' cost `{}`: {e}", identity.cost))?,
        work_unit: <WorkUnit as clap::ValueEnum>::from_str(&identity.work_unit, true)
            .map_err(|e| anyhow::anyhow!("the shards' work unit `{}`: {e}", identity.work_unit))?,
        format: args.format,
    };
    eprintln!("merged {} shards of {} runs", args.shards.len(), identity.runs);
    write_sweep(&output, &merged.rows, &merged.varied)
}
