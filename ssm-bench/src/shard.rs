//! Sweeps past one machine: `ssm sweep --shard K/N` runs a deterministic share of a sweep's
//! runs and records what it ran in `shard.json`; `ssm merge DIR...` checks that the shards are
//! the parts of one sweep and puts their rows back in the unsharded order.
//!
//! A run is one (scene point, technique point) pair, numbered scene point first, technique
//! point second, as an unsharded sweep measures them. Shard K of N takes the K-th of N
//! contiguous blocks of that numbering, so neighbouring runs (the same scene point, the same
//! ground truth) stay on one machine as far as the split allows.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use anyhow::{Context, Result, bail};
use serde_json::{Value, json};

use crate::data::Row;
use crate::data::csv::parse_csv;

/// A grid point's varied values, `(qualified parameter, value)`, scene ones first.
pub type Varied = Vec<(String, String)>;

/// The file a shard writes beside its `sweep.csv`.
pub const SHARD_FILE: &str = "shard.json";

/// The format of [`SHARD_FILE`]; a merge refuses others.
pub const SHARD_FORMAT: u64 = 1;

/// Shard `index` (1-based) of `count`, as `--shard K/N` gives it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// Which shard, from 1 to `count`.
    pub index: usize,
    /// How many shards the sweep is split into.
    pub count: usize,
}

impl FromStr for Shard {
    type Err = anyhow::Error;

    fn from_str(text: &str) -> Result<Self> {
        let (index, count) = text.split_once('/').with_context(|| format!("--shard {text}: expected K/N, as 2/3"))?;
        let parse = |s: &str| s.trim().parse::<usize>().with_context(|| format!("--shard {text}: `{s}` is not a whole number"));
        let (index, count) = (parse(index)?, parse(count)?);
        if count == 0 || index == 0 || index > count {
            bail!("--shard {text}: K must be from 1 to N, and N at least 1");
        }
        Ok(Self { index, count })
    }
}

impl Shard {
    /// The runs (0-based, in the unsharded order) of this shard out of `total`: the K-th of N
    /// contiguous blocks whose sizes differ by at most one. Empty when N exceeds `total` for
    /// some shards.
    #[must_use]
    pub fn runs(self, total: usize) -> Range<usize> {
        let start = (self.index - 1) * total / self.count;
        let end = self.index * total / self.count;
        start..end
    }
}

/// What makes two shards parts of the same sweep: everything that decides the runs and how they
/// are measured. Written into each shard's [`SHARD_FILE`] and compared field by field on merge.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepIdentity {
    /// The ssm package version that ran it.
    pub ssm_version: String,
    /// The preset's name, if one was used.
    pub preset: Option<String>,
    /// The scene as given.
    pub scene: String,
    /// Every `--vary` specification, the preset's included, in order.
    pub varies: Vec<String>,
    /// Every `--set` assignment, in order.
    pub settings: Vec<String>,
    /// Image size.
    pub size: (u32, u32),
    /// Frames timed per run.
    pub frames: u32,
    /// The pixels the errors cover (`all` or `receivers`).
    pub pixels: String,
    /// The plot's axes.
    pub x_axis: String,
    /// The plot's y axis, as `--error` names it.
    pub error: String,
    /// Whether every run's work was counted (`--count-work` or `--cost work`).
    pub count_work: bool,
    /// What the Pareto front weighs error against, as `--cost` names it.
    pub cost: String,
    /// The work plot's unit, as `--work-unit` names it.
    pub work_unit: String,
    /// How many runs the whole sweep has.
    pub runs: usize,
}

impl SweepIdentity {
    fn to_json(&self) -> Value {
        json!({
            "ssm_version": self.ssm_version,
            "preset": self.preset,
            "scene": self.scene,
            "varies": self.varies,
            "settings": self.settings,
            "width": self.size.0,
            "height": self.size.1,
            "frames": self.frames,
            "pixels": self.pixels,
            "x_axis": self.x_axis,
            "error": self.error,
            "count_work": self.count_work,
            "cost": self.cost,
            "work_unit": self.work_unit,
            "runs": self.runs,
        })
    }

    fn from_json(value: &Value, file: &Path) -> Result<Self> {
        let text = |key: &str| -> Result<String> {
            value.get(key).and_then(Value::as_str).map(str::to_owned).with_context(|| format!("{}: no text `{key}`", file.display()))
        };
        let number = |key: &str| -> Result<u64> {
            value.get(key).and_then(Value::as_u64).with_context(|| format!("{}: no whole number `{key}`", file.display()))
        };
        let list = |key: &str| -> Result<Vec<String>> {
            value
                .get(key)
                .and_then(Value::as_array)
                .and_then(|items| items.iter().map(|v| v.as_str().map(str::to_owned)).collect::<Option<Vec<_>>>())
                .with_context(|| format!("{}: no list of text `{key}`", file.display()))
        };
        let small =
            |key: &str| -> Result<u32> { u32::try_from(number(key)?).with_context(|| format!("{}: `{key}` too large", file.display())) };
        Ok(Self {
            ssm_version: text("ssm_version")?,
            preset: value.get("preset").and_then(Value::as_str).map(str::to_owned),
            scene: text("scene")?,
            varies: list("varies")?,
            settings: list("settings")?,
            size: (small("width")?, small("height")?),
            frames: small("frames")?,
            pixels: text("pixels")?,
            x_axis: text("x_axis")?,
            error: text("error")?,
            // Shards written before counted work (issue 40) counted none.
            count_work: value.get("count_work").and_then(Value::as_bool).unwrap_or(false),
            cost: value.get("cost").and_then(Value::as_str).unwrap_or("time").to_owned(),
            work_unit: value.get("work_unit").and_then(Value::as_str).unwrap_or("reads-and-invocations").to_owned(),
            runs: usize::try_from(number("runs")?).with_context(|| format!("{}: `runs` too large", file.display()))?,
        })
    }
}

/// One shard's record: the sweep it belongs to, which shard it is, the adapter that ran it, and
/// for each of its rows (in `sweep.csv`'s order) the run's number and varied values.
#[derive(Clone, Debug, PartialEq)]
pub struct ShardRecord {
    /// The sweep.
    pub identity: SweepIdentity,
    /// Which shard.
    pub shard: Shard,
    /// The adapter's name (`sweep.md`'s header).
    pub adapter: String,
    /// Per row of the shard's `sweep.csv`: the run's number in the unsharded order and its
    /// varied values (scene ones first).
    pub rows: Vec<(usize, Varied)>,
}

impl ShardRecord {
    /// Writes `dir/shard.json`.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let mut value = self.identity.to_json();
        value["format"] = json!(SHARD_FORMAT);
        value["shard"] = json!(self.shard.index);
        value["shards"] = json!(self.shard.count);
        value["adapter"] = json!(self.adapter);
        value["rows"] = Value::Array(
            self.rows
                .iter()
                .map(|(run, varied)| json!({ "run": run, "varied": varied.iter().map(|(k, v)| [k, v]).collect::<Vec<_>>() }))
                .collect(),
        );
        let file = dir.join(SHARD_FILE);
        let text = serde_json::to_string_pretty(&value).context("serialising shard.json")?;
        std::fs::write(&file, text).with_context(|| format!("writing {}", file.display()))
    }

    /// Reads `dir/shard.json`.
    ///
    /// # Errors
    /// A missing or malformed file, naming it and what is wrong.
    pub fn read(dir: &Path) -> Result<Self> {
        let file = dir.join(SHARD_FILE);
        let text = std::fs::read_to_string(&file)
            .with_context(|| format!("reading {} (is {} a shard's output?)", file.display(), dir.display()))?;
        let value: Value = serde_json::from_str(&text).with_context(|| format!("{}: not JSON", file.display()))?;
        let format = value.get("format").and_then(Value::as_u64);
        if format != Some(SHARD_FORMAT) {
            bail!("{}: format {format:?}, this ssm reads format {SHARD_FORMAT}", file.display());
        }
        let count = |key: &str| -> Result<usize> {
            value
                .get(key)
                .and_then(Value::as_u64)
                .and_then(|n| usize::try_from(n).ok())
                .with_context(|| format!("{}: no whole number `{key}`", file.display()))
        };
        let shard = Shard { index: count("shard")?, count: count("shards")? };
        if shard.index == 0 || shard.index > shard.count {
            bail!("{}: shard {} of {} is out of range", file.display(), shard.index, shard.count);
        }
        let rows = value
            .get("rows")
            .and_then(Value::as_array)
            .with_context(|| format!("{}: no `rows` list", file.display()))?
            .iter()
            .map(|row| {
                let run = row.get("run").and_then(Value::as_u64).and_then(|n| usize::try_from(n).ok());
                let varied = row.get("varied").and_then(Value::as_array).and_then(|pairs| {
                    pairs
                        .iter()
                        .map(|pair| match pair.as_array().map(Vec::as_slice) {
                            Some([k, v]) => Some((k.as_str()?.to_owned(), v.as_str()?.to_owned())),
                            _ => None,
                        })
                        .collect::<Option<Vec<_>>>()
                });
                run.zip(varied).with_context(|| format!("{}: a row without `run` and `varied` pairs", file.display()))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            identity: SweepIdentity::from_json(&value, &file)?,
            shard,
            adapter: value.get("adapter").and_then(Value::as_str).unwrap_or_default().to_owned(),
            rows,
        })
    }
}

/// The shards of one sweep put back together: the rows in the unsharded order, their varied
/// values, and what the shards agree on.
#[derive(Debug)]
pub struct Merged {
    /// The sweep.
    pub identity: SweepIdentity,
    /// The adapters that ran the shards, each once, in shard order.
    pub adapters: Vec<String>,
    /// The rows, in the unsharded order.
    pub rows: Vec<Row>,
    /// Each row's varied values.
    pub varied: Vec<Varied>,
}

/// Reads the shards in `dirs` (each a `sweep --shard` output folder) and merges them.
///
/// # Errors
/// A folder that is no shard, shards of different sweeps (the first differing field is named),
/// of different ssm versions, a shard missing or given twice, a run missing or recorded twice,
/// or a `sweep.csv` whose rows do not match its `shard.json`.
pub fn merge(dirs: &[PathBuf]) -> Result<Merged> {
    if dirs.is_empty() {
        bail!("ssm merge: give the shards' output folders");
    }
    let mut shards = Vec::new();
    for dir in dirs {
        let record = ShardRecord::read(dir)?;
        let csv_file = dir.join("sweep.csv");
        let text = std::fs::read_to_string(&csv_file).with_context(|| format!("reading {}", csv_file.display()))?;
        let rows = parse_csv(&text).with_context(|| format!("reading {}", csv_file.display()))?;
        if rows.len() != record.rows.len() {
            bail!("{}: {} rows, but its shard.json records {}", csv_file.display(), rows.len(), record.rows.len());
        }
        shards.push((dir.clone(), record, rows));
    }
    let (first_dir, first, _) = &shards[0];
    let identity = first.identity.clone();
    let count = first.shard.count;
    for (dir, record, _) in &shards[1..] {
        if record.identity.ssm_version != identity.ssm_version {
            bail!(
                "{} was run by ssm {} and {} by ssm {}: merge shards of one version",
                first_dir.display(),
                identity.ssm_version,
                dir.display(),
                record.identity.ssm_version
            );
        }
        if record.identity != identity || record.shard.count != count {
            bail!(
                "{} and {} are shards of different sweeps ({})",
                first_dir.display(),
                dir.display(),
                first_difference(&identity, count, record)
            );
        }
    }
    let mut seen = vec![None; count];
    for (dir, record, _) in &shards {
        if let Some(other) = seen[record.shard.index - 1].replace(dir.clone()) {
            bail!("shard {}/{count} given twice: {} and {}", record.shard.index, other.display(), dir.display());
        }
    }
    if let Some(missing) = seen.iter().position(Option::is_none) {
        bail!("shard {}/{count} is missing", missing + 1);
    }
    let mut runs: Vec<Option<(Row, Varied)>> = vec![None; identity.runs];
    for (dir, record, rows) in shards.iter().cloned() {
        let expected = record.shard.runs(identity.runs);
        for ((run, varied), row) in record.rows.into_iter().zip(rows) {
            if !expected.contains(&run) {
                bail!("{}: run {run} is not shard {}/{count}'s ({expected:?})", dir.display(), record.shard.index);
            }
            if runs[run].replace((row, varied)).is_some() {
                bail!("{}: run {run} recorded twice", dir.display());
            }
        }
    }
    if let Some(missing) = runs.iter().position(Option::is_none) {
        bail!("run {missing} of {} is in no shard", identity.runs);
    }
    let mut adapters: Vec<String> = Vec::new();
    shards.sort_by_key(|(_, record, _)| record.shard.index);
    for (_, record, _) in &shards {
        if !adapters.contains(&record.adapter) {
            adapters.push(record.adapter.clone());
        }
    }
    let (rows, varied) = runs.into_iter().flatten().unzip();
    Ok(Merged { identity, adapters, rows, varied })
}

/// The first field in which `record` differs from `identity` (and `count` shards), for the message.
fn first_difference(identity: &SweepIdentity, count: usize, record: &ShardRecord) -> String {
    let other = &record.identity;
    let fields: [(&str, String, String); 14] = [
        ("preset", format!("{:?}", identity.preset), format!("{:?}", other.preset)),
        ("scene", identity.scene.clone(), other.scene.clone()),
        ("varies", identity.varies.join(" "), other.varies.join(" ")),
        ("settings", identity.settings.join(" "), other.settings.join(" ")),
        ("size", format!("{:?}", identity.size), format!("{:?}", other.size)),
        ("frames", identity.frames.to_string(), other.frames.to_string()),
        ("pixels", identity.pixels.clone(), other.pixels.clone()),
        ("x axis", identity.x_axis.clone(), other.x_axis.clone()),
        ("error", identity.error.clone(), other.error.clone()),
        ("count work", identity.count_work.to_string(), other.count_work.to_string()),
        ("cost", identity.cost.clone(), other.cost.clone()),
        ("work unit", identity.work_unit.clone(), other.work_unit.clone()),
        ("runs", identity.runs.to_string(), other.runs.to_string()),
        ("shards", count.to_string(), record.shard.count.to_string()),
    ];
    fields
        .into_iter()
        .find(|(_, a, b)| a != b)
        .map_or_else(|| "no field differs".to_owned(), |(name, a, b)| format!("{name}: {a} against {b}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_split_the_runs_into_contiguous_blocks_that_cover_them_once() {
        for total in [0, 1, 2, 5, 7, 100] {
            for count in 1..=9 {
                let mut covered = Vec::new();
                for index in 1..=count {
                    let runs = Shard { index, count }.runs(total);
                    assert!(
                        runs.len() <= total.div_ceil(count) && runs.len() + 1 >= total / count,
                        "{total} runs, shard {index}/{count}: {runs:?}"
                    );
                    covered.extend(runs);
                }
                assert_eq!(covered, (0..total).collect::<Vec<_>>(), "{total} runs in {count} shards");
            }
        }
        assert_eq!("2/3".parse::<Shard>().unwrap(), Shard { index: 2, count: 3 });
        for bad in ["0/3", "4/3", "1/0", "3", "a/b", "1/-2"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
