//! The tables of counted work (`--count-work`, issue 40) as the reports and `ssm render` print
//! them: a frame's totals per technique ([`frame_table`]) and each pass's counts ([`pass_table`]),
//! what their `-` mean ([`notes`]), how the counts are made ([`HOW_COUNTED`]), and a count as a
//! table cell or in a few characters for labels ([`cell`], [`short`]).

use ssm_core::FrameWork;

use crate::data::work::Totals;

/// A count for a table: the number, or `-` when it was not made.
#[must_use]
pub fn cell(count: Option<u64>) -> String {
    count.map_or_else(|| "-".to_owned(), |n| n.to_string())
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
    use crate::data::work::tests::work;
    use crate::present::sweep::WorkUnit;

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
}
