//! Counted work (`--count-work`, issue 40) as data: a frame's totals with what is unknown kept
//! unknown ([`Totals`]), a count as a CSV field ([`field`]), the `passes_work` column read back
//! ([`parse_passes_column`]), and what the reports say of the ground truth's work
//! ([`GROUND_TRUTH_NOT_COUNTED`]). A count that was not made is shown as unknown (`-` in tables,
//! an empty CSV field, `null` in JSON), never as 0.

use anyhow::{Context as _, bail};
use ssm_core::{FrameWork, PassWork};

/// What the report says of the ground truth's work: it traces rays on the CPU and has no GPU pass to count.
pub const GROUND_TRUTH_NOT_COUNTED: &str = "not counted (CPU ray tracing)";

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

/// A count for a CSV field: the number, or empty when it was not made.
#[must_use]
pub fn field(count: Option<u64>) -> String {
    count.map_or_else(String::new, |n| n.to_string())
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn work(pipeline_statistics: bool, shader_counts: bool) -> FrameWork {
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
