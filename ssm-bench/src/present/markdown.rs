//! `report.md`: the run's context, the table of errors and times, and the section on the counted work.

use std::fmt::Write as _;

use super::work::{FRAME_HEADER, HOW_COUNTED, PASS_HEADER, frame_table, notes, pass_table};
use super::{ReportContext, TABLE_HEADER, beyond_frame_note, counted, light_suffix, pixels_of, table_cells};
use crate::data::Row;
use crate::data::work::GROUND_TRUTH_NOT_COUNTED;

/// The Markdown table of `rows`.
#[must_use]
pub fn markdown_table(rows: &[Row]) -> String {
    let mut out = format!("| {} |\n|---|---|{}\n", TABLE_HEADER.join(" | "), "---:|".repeat(TABLE_HEADER.len() - 2));
    for r in rows {
        let mut cells = table_cells(r);
        cells[0] = format!("`{}`{}", cells[0], light_suffix(r));
        let _ = writeln!(out, "| {} |", cells.join(" | "));
    }
    out
}

/// `report.md`'s section on the counted work: how it is counted, the frame's totals per
/// technique, each pass's counts, what `-` means, and the ground truth's.
fn markdown_work(context: &ReportContext<'_>, rows: &[Row]) -> String {
    if !context.count_work {
        return String::new();
    }
    let techniques = counted(rows);
    let table = |header: &[&str], cells: Vec<[String; 13]>| {
        let mut out = format!("| {} |\n|---|{}\n", header.join(" | "), "---:|".repeat(header.len() - 1));
        for row in cells {
            let _ = writeln!(out, "| {} |", row.join(" | "));
        }
        out
    };
    let mut out = format!("\n## Counted work\n\n{HOW_COUNTED}\n\nPer frame:\n\n");
    out += &table(&FRAME_HEADER, frame_table(&techniques, pixels_of(rows)));
    out += "\nPer pass:\n\n";
    out += &table(&PASS_HEADER, pass_table(&techniques));
    for note in notes(&techniques) {
        let _ = writeln!(out, "\n{note}");
    }
    let _ = writeln!(out, "\nGround truth (`reference`): {}.", GROUND_TRUTH_NOT_COUNTED);
    out
}

/// `report.md`: the context and the table.
#[must_use]
pub fn markdown_report(context: &ReportContext<'_>, rows: &[Row]) -> String {
    let mut out = format!(
        "# ssm compare: `{}`\n\n{}×{}, median of {} frames after one warm-up, on {}.\nGround truth: `reference` [{}]: {}. Errors are against it, on the same pixels; MAE covers the pixels that either the truth or the technique shadows, MAE penumbra the truth's umbra and penumbra; ± is the ground truth's own error over the same pixels (two errors closer than their two ± are a tie). GPU time is the sum of each technique's timed passes.\n\n",
        context.scene, context.size.0, context.size.1, context.frames, context.adapter, context.reference_params, context.reference_cost
    );
    out += &markdown_table(rows);
    if let Some(note) = beyond_frame_note(rows) {
        let _ = writeln!(out, "\n{note}");
    }
    for (name, why) in context.skipped {
        let _ = writeln!(out, "\nNot run: `{name}`: {why}");
    }
    out += &markdown_work(context, rows);
    out
}
