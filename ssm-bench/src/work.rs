//! Counted work (`--count-work`, issue 40) as the tool reports it: one extra, untimed frame of a
//! technique after its timed frames ([`count`], through [`Renderer::count_work`]), its totals per
//! frame with what is unknown kept unknown ([`Totals`]), the `passes_work` column read back
//! ([`parse_passes_column`]), the units a sweep plots work in ([`WorkUnit`]) and the report's
//! tables ([`frame_table`], [`pass_table`], [`notes`]).
//!
//! What is counted and how: invocations and primitives from pipeline statistics (where the
//! adapter has them: [`FrameWork::pipeline_statistics`]), bytes stored to render targets from the
//! attachments' sizes, and texel reads, atomics and storage bytes as the technique's own shaders
//! count them (where it does: [`FrameWork::shader_counts`]; a load or a nearest sample is one
//! texel, a bilinear sample or a gather four). A count that was not made is shown as unknown
//! (`-` in tables, an empty CSV field, `null` in JSON), never as 0.

use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{Context as _, bail};
use ssm_core::{FrameWork, ParamValues, PassWork, Renderer, Result, TechniqueInfo, TechniqueKind};

/// What the report says of the ground truth's work: it traces rays on the CPU and has no GPU pass to count.
pub const GROUND_TRUTH_NOT_COUNTED: &str = "not counted (CPU ray tracing)";

/// Counting frames this process has rendered (see [`counting_frames`]).
static COUNTING_FRAMES: AtomicU64 = AtomicU64::new(0);

/// How many counting frames ([`Renderer::count_work`]) this process has rendered through
/// [`count`]: a run without `--count-work` renders none, which tests check.
#[must_use]
pub fn counting_frames() -> u64 {
    COUNTING_FRAMES.load(Ordering::Relaxed)
}

/// Counts the work of one frame of `info` with `params` (every light) in an extra, untimed frame
/// of a technique built for counting; `None` for the ground truth, which traces rays on the CPU
/// ([`GROUND_TRUTH_NOT_COUNTED`]). Call it after the timed frames: it builds another instance.
///
/// # Errors
/// As [`Renderer::count_work`].
pub fn count(renderer: &mut Renderer, info: &TechniqueInfo, params: &ParamValues) -> Result<Option<FrameWork>> {
    if info.kind == TechniqueKind::GroundTruth {
        return Ok(None);
    }
    COUNTING_FRAMES.fetch_add(1, Ordering::Relaxed);
    renderer.count_work(info, params).map(Some)
}

/// A frame's work summed over its passes; `None` where the count was not made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Totals {
    /// Vertex shader invocations (pipeline statistics).
    pub vertex_invocations: Option<u64>,
    /// Fragment shader invocations (pipeline statistics).
    pub fragment_invocations: Option<u64>,
    /// Compute shader invocations (pipeline statistics).
    pub compute_invocations: Option<u64>,
    /// Primitives into the clipper (pipeline statistics).
    pub primitives: Option<u64>,
    /// Primitives out of the clipper (pipeline statistics).
    pub clipped_primitives: Option<u64>,
    /// Bytes stored to render targets (always known: from the attachments).
    pub target_bytes: u64,
    /// Texel reads (the technique's shaders).
    pub texel_reads: Option<u64>,
    /// Bytes those reads fetched (the technique's shaders): known where every pass that reads
    /// counted its bytes too.
    pub read_bytes: Option<u64>,
    /// Atomic operations (the technique's shaders).
    pub atomics: Option<u64>,
    /// Bytes written to storage (the technique's shaders).
    pub storage_bytes: Option<u64>,
}

impl Totals {
    /// The totals of `work`.
    #[must_use]
    pub fn of(work: &FrameWork) -> Self {
        Self::of_passes(work, &work.passes)
    }

    /// The totals of `passes` (some or all of `work`'s), known as `work`'s are.
    #[must_use]
    pub fn of_passes(work: &FrameWork, passes: &[PassWork]) -> Self {
        let sum = |count: fn(&PassWork) -> u64| passes.iter().map(count).sum::<u64>();
        let statistics = |count: fn(&PassWork) -> u64| work.pipeline_statistics.then(|| sum(count));
        let shaders = |count: fn(&PassWork) -> u64| work.shader_counts.then(|| sum(count));
        Self {
            vertex_invocations: statistics(|p| p.vertex_invocations),
            fragment_invocations: statistics(|p| p.fragment_invocations),
            compute_invocations: statistics(|p| p.compute_invocations),
            primitives: statistics(|p| p.primitives),
            clipped_primitives: statistics(|p| p.clipped_primitives),
            target_bytes: sum(|p| p.target_bytes),
            texel_reads: shaders(|p| p.texel_reads),
            read_bytes: shaders(|p| p.read_bytes).filter(|_| passes.iter().all(|p| p.texel_reads == 0 || p.read_bytes > 0)),
            atomics: shaders(|p| p.atomics),
            storage_bytes: shaders(|p| p.storage_bytes),
        }
    }

    /// Vertex, fragment and compute invocations together.
    #[must_use]
    pub fn invocations(&self) -> Option<u64> {
        Some(self.vertex_invocations? + self.fragment_invocations? + self.compute_invocations?)
    }
}

/// A count for a table: the number, or `-` when it was not made.
#[must_use]
pub fn cell(count: Option<u64>) -> String {
    count.map_or_else(|| "-".to_owned(), |n| n.to_string())
}

/// A count for a CSV field: the number, or empty when it was not made.
#[must_use]
pub fn field(count: Option<u64>) -> String {
    count.map_or_else(String::new, |n| n.to_string())
}

/// A count in a few characters for chart labels: `812`, `12.3 k`, `4.56 M`, `1.2 G`.
#[must_use]
pub fn short(count: f64) -> String {
    match count {
        c if c >= 1e9 => format!("{:.3} G", c / 1e9),
        c if c >= 1e6 => format!("{:.3} M", c / 1e6),
        c if c >= 1e4 => format!("{:.1} k", c / 1e3),
        c => format!("{c:.0}"),
    }
}

/// The passes of a `passes_work` column ([`FrameWork::passes_column`]: `pass:key=value,...;...`),
/// the counts it leaves out (those that are zero) as zero.
///
/// # Errors
/// A pass without `:`, a pair without `=`, an unknown key or a value that is not a whole number.
pub fn parse_passes_column(text: &str) -> anyhow::Result<Vec<PassWork>> {
    text.split(';')
        .filter(|pass| !pass.is_empty())
        .map(|pass| {
            let (name, pairs) = pass.split_once(':').with_context(|| format!("passes_work: `{pass}` is not pass:key=value,..."))?;
            let mut work = PassWork { name: name.to_owned(), ..PassWork::default() };
            for pair in pairs.split(',').filter(|p| !p.is_empty()) {
                let (key, value) = pair.split_once('=').with_context(|| format!("passes_work: `{pair}` is not key=value"))?;
                let value: u64 = value.parse().with_context(|| format!("passes_work: `{value}` is not a whole number"))?;
                let slot = match key {
                    "runs" => &mut work.runs,
                    "vertex_invocations" => &mut work.vertex_invocations,
                    "primitives" => &mut work.primitives,
                    "clipped_primitives" => &mut work.clipped_primitives,
                    "fragment_invocations" => &mut work.fragment_invocations,
                    "compute_invocations" => &mut work.compute_invocations,
                    "target_bytes" => &mut work.target_bytes,
                    "counted_invocations" => &mut work.counted_invocations,
                    "texel_reads" => &mut work.texel_reads,
                    "read_bytes" => &mut work.read_bytes,
                    "atomics" => &mut work.atomics,
                    "storage_bytes" => &mut work.storage_bytes,
                    other => bail!("passes_work: unknown count `{other}`"),
                };
                *slot = value;
            }
            Ok(work)
        })
        .collect()
}

/// The unit a sweep plots counted work in (`--work-unit`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum WorkUnit {
    /// Texel reads plus vertex, fragment and compute invocations: what a frame fetches and shades.
    #[default]
    ReadsAndInvocations,
    /// Texel reads only (as the technique's shaders count them).
    TexelReads,
    /// Vertex, fragment and compute invocations only (pipeline statistics).
    Invocations,
}

impl WorkUnit {
    /// The frame's work in this unit; `None` when a count it needs was not made.
    #[must_use]
    pub fn of(self, work: &FrameWork) -> Option<f64> {
        let totals = Totals::of(work);
        let value = match self {
            Self::ReadsAndInvocations => totals.texel_reads? + totals.invocations()?,
            Self::TexelReads => totals.texel_reads?,
            Self::Invocations => totals.invocations()?,
        };
        Some(value as f64)
    }

    /// The axis label: what is counted, per frame.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::ReadsAndInvocations => "counted work per frame: texel reads + vertex, fragment and compute invocations",
            Self::TexelReads => "counted texel reads per frame",
            Self::Invocations => "counted vertex, fragment and compute invocations per frame",
        }
    }

    /// The unit as `--work-unit` spells it.
    #[must_use]
    pub fn name(self) -> String {
        clap::ValueEnum::to_possible_value(&self).map_or_else(String::new, |v| v.get_name().to_owned())
    }
}

/// What a sweep's Pareto front (the `*` of its lines, `pareto` in JSON) weighs error against (`--cost`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Cost {
    /// Milliseconds per frame.
    #[default]
    Time,
    /// Counted work per frame, in `--work-unit`: every point is counted (as with `--count-work`).
    Work,
}

/// The header of [`frame_table`].
pub const FRAME_HEADER: [&str; 13] = [
    "technique",
    "vertex inv.",
    "fragment inv.",
    "compute inv.",
    "primitives",
    "clipped",
    "texel reads",
    "bytes read",
    "reads / pixel",
    "atomics",
    "target bytes",
    "storage bytes",
    "passes",
];

/// The header of [`pass_table`].
pub const PASS_HEADER: [&str; 13] = [
    "technique",
    "pass",
    "runs",
    "vertex inv.",
    "fragment inv.",
    "compute inv.",
    "primitives",
    "clipped",
    "texel reads",
    "bytes read",
    "atomics",
    "target bytes",
    "storage bytes",
];

/// One row per technique: its frame's totals, `pixels` the image's pixel count (for reads per pixel).
#[must_use]
pub fn frame_table(techniques: &[(&str, &FrameWork)], pixels: u64) -> Vec<[String; 13]> {
    techniques
        .iter()
        .map(|(name, work)| {
            let totals = Totals::of(work);
            [
                (*name).to_owned(),
                cell(totals.vertex_invocations),
                cell(totals.fragment_invocations),
                cell(totals.compute_invocations),
                cell(totals.primitives),
                cell(totals.clipped_primitives),
                cell(totals.texel_reads),
                cell(totals.read_bytes),
                totals.texel_reads.map_or_else(|| "-".to_owned(), |reads| format!("{:.2}", reads as f64 / pixels.max(1) as f64)),
                cell(totals.atomics),
                totals.target_bytes.to_string(),
                cell(totals.storage_bytes),
                work.passes.len().to_string(),
            ]
        })
        .collect()
}

/// One row per pass of each technique, as first recorded.
#[must_use]
pub fn pass_table(techniques: &[(&str, &FrameWork)]) -> Vec<[String; 13]> {
    let mut rows = Vec::new();
    for (name, work) in techniques {
        for pass in &work.passes {
            let totals = Totals::of_passes(work, std::slice::from_ref(pass));
            rows.push([
                (*name).to_owned(),
                pass.name.clone(),
                pass.runs.to_string(),
                cell(totals.vertex_invocations),
                cell(totals.fragment_invocations),
                cell(totals.compute_invocations),
                cell(totals.primitives),
                cell(totals.clipped_primitives),
                cell(totals.texel_reads),
                cell(totals.read_bytes),
                cell(totals.atomics),
                totals.target_bytes.to_string(),
                cell(totals.storage_bytes),
            ]);
        }
    }
    rows
}

/// What the tables' `-` mean for these techniques: no pipeline statistics on the adapter, a
/// technique that does not count in its shaders, passes past the query set's end.
#[must_use]
pub fn notes(techniques: &[(&str, &FrameWork)]) -> Vec<String> {
    let mut notes = Vec::new();
    if techniques.iter().any(|(_, work)| !work.pipeline_statistics) {
        notes.push(
            "This adapter has no pipeline statistics (PIPELINE_STATISTICS_QUERY): invocations and primitives are not counted (-)."
                .to_owned(),
        );
    }
    let silent: Vec<&str> = techniques.iter().filter(|(_, work)| !work.shader_counts).map(|(name, _)| *name).collect();
    if !silent.is_empty() {
        notes.push(format!(
            "{} do{} not count in {} shaders: texel reads, atomics and storage bytes are unknown (-), not zero.",
            silent.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", "),
            if silent.len() == 1 { "es" } else { "" },
            if silent.len() == 1 { "its" } else { "their" }
        ));
    }
    for (name, work) in techniques.iter().filter(|(_, work)| work.uncounted_passes > 0) {
        notes.push(format!("`{name}`: {} passes past the query set's end have no pipeline statistics.", work.uncounted_passes));
    }
    notes
}

/// The sentence that explains the work tables: how the counts are made.
pub const HOW_COUNTED: &str = "One extra, untimed frame per technique after its timed frames (every light): vertex, fragment and compute invocations and primitives into and out of the clipper from pipeline statistics; texel reads, atomics and storage bytes as the technique's shaders count them (a load or a nearest sample is one texel read, a bilinear sample or a gather four); bytes stored to render targets from the attachments' sizes. Fragment invocations may include helper invocations. `-`: not counted.";

#[cfg(test)]
mod tests {
    use super::*;

    fn work(pipeline_statistics: bool, shader_counts: bool) -> FrameWork {
        FrameWork {
            pipeline_statistics,
            shader_counts,
            passes: vec![
                PassWork {
                    name: "x_map".into(),
                    runs: 2,
                    vertex_invocations: 6,
                    primitives: 2,
                    fragment_invocations: 50,
                    target_bytes: 64,
                    ..PassWork::default()
                },
                PassWork {
                    name: "x_filter".into(),
                    runs: 2,
                    compute_invocations: 100,
                    texel_reads: 900,
                    atomics: 3,
                    ..PassWork::default()
                },
            ],
            uncounted_passes: 0,
            diagnostics: Vec::new(),
        }
    }

    #[test]
    fn unknown_counts_stay_unknown() {
        let both = Totals::of(&work(true, true));
        assert_eq!((both.invocations(), both.texel_reads, both.target_bytes), (Some(156), Some(900), 64));
        assert_eq!(WorkUnit::ReadsAndInvocations.of(&work(true, true)), Some(1056.0));
        let no_shaders = work(true, false);
        assert_eq!(Totals::of(&no_shaders).texel_reads, None, "a technique that does not count has unknown reads, not 0");
        assert_eq!(WorkUnit::ReadsAndInvocations.of(&no_shaders), None);
        assert_eq!(WorkUnit::Invocations.of(&no_shaders), Some(156.0));
        let no_statistics = work(false, true);
        assert_eq!((Totals::of(&no_statistics).fragment_invocations, WorkUnit::TexelReads.of(&no_statistics)), (None, Some(900.0)));
        let rows = frame_table(&[("x", &no_shaders)], 100);
        assert_eq!((rows[0][6].as_str(), rows[0][7].as_str(), rows[0][8].as_str(), rows[0][1].as_str()), ("-", "-", "-", "6"));
        assert_eq!(notes(&[("x", &no_shaders)]).len(), 1);
        assert_eq!(notes(&[("x", &no_statistics)]).len(), 1);
    }

    /// The bytes read are known only where every pass that reads counted them: a technique that
    /// counts reads but not (all) their bytes has unknown bytes, not a partial sum.
    #[test]
    fn bytes_read_are_known_only_where_every_reading_pass_counts_them() {
        let mut counted = work(true, true);
        assert_eq!(Totals::of(&counted).read_bytes, None, "reads without bytes");
        counted.passes[1].read_bytes = 3600;
        assert_eq!(Totals::of(&counted).read_bytes, Some(3600), "the map pass reads nothing");
        counted.passes[0].texel_reads = 10;
        assert_eq!(Totals::of(&counted).read_bytes, None, "a reading pass without bytes");
        assert_eq!(Totals::of(&work(true, false)).read_bytes, None);
    }

    #[test]
    fn the_passes_column_reads_back() {
        let work = work(true, true);
        let back = parse_passes_column(&work.passes_column()).unwrap();
        assert_eq!(back, work.passes);
        assert!(parse_passes_column("x_map:runs=1,bogus=2").is_err());
        assert!(parse_passes_column("x_map:runs=many").is_err());
        assert!(parse_passes_column("x_map").is_err());
        assert_eq!(parse_passes_column("").unwrap(), Vec::new());
    }
}
