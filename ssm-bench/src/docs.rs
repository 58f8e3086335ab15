//! Documentation generated from the registry, so that it cannot drift from the code: each
//! technique README's parameter table (between `<!-- parameters -->` and `<!-- /parameters -->`),
//! checked by `ssm-bench/tests/docs.rs` and rewritten with `SSM_BLESS=1`.

use ssm_core::TechniqueInfo;

/// The line that opens a README's generated parameter table.
pub const PARAMETERS_BEGIN: &str = "<!-- parameters -->";
/// The line that closes it.
pub const PARAMETERS_END: &str = "<!-- /parameters -->";

/// The parameter table of `info` in Markdown: one row per `--set` parameter (its default, its type
/// and range, its documentation), then its requirements and debug outputs.
///
/// # Errors
/// The technique's requirements cannot be derived from its defaults.
pub fn parameters_markdown(info: &TechniqueInfo) -> ssm_core::Result<String> {
    let mut text = String::new();
    text.push_str(&format!(
        "Generated from the settings (`ssm list --parameters-of {name}`; in the ssm checkout `cargo test -p ssm-bench\n\
         --test docs` checks it and `SSM_BLESS=1` rewrites it). Set each with `--set {name}.<parameter>=<value>`.\n\n",
        name = info.name
    ));
    text.push_str("| parameter | default | values | what it does |\n|---|---|---|---|\n");
    for spec in info.params {
        let doc = spec.doc.replace('|', "\\|").replace('\n', " ");
        text.push_str(&format!("| `{}` | `{}` | {} | {} |\n", spec.name, spec.default_value(), spec.range_text().replace('|', "\\|"), doc));
    }
    let requirements = (info.requirements)(&info.default_params())?;
    text.push_str(&format!("\nNeeds (at the defaults): {}.\n", requirements.describe()));
    if !info.debug_outputs.is_empty() {
        text.push_str("\nDebug outputs (`--debug-output <name>`):\n\n");
        for output in info.debug_outputs {
            text.push_str(&format!("- `{}`: {}\n", output.name, output.doc.replace('\n', " ")));
        }
    }
    Ok(text)
}

/// `readme` with the text between its parameter markers replaced by `table`; `None` when the
/// markers are missing, repeated or out of order.
#[must_use]
pub fn with_parameters(readme: &str, table: &str) -> Option<String> {
    let begin = readme.find(PARAMETERS_BEGIN)?;
    let end = readme.find(PARAMETERS_END)?;
    if readme.matches(PARAMETERS_BEGIN).count() != 1 || readme.matches(PARAMETERS_END).count() != 1 || end < begin {
        return None;
    }
    let head = &readme[..begin + PARAMETERS_BEGIN.len()];
    let tail = &readme[end..];
    Some(format!("{head}\n{table}{tail}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_replaces_only_what_lies_between_the_markers() {
        let readme = "# t\n\n<!-- parameters -->\nold\n<!-- /parameters -->\nafter\n";
        let updated = with_parameters(readme, "new\n").unwrap_or_default();
        assert_eq!(updated, "# t\n\n<!-- parameters -->\nnew\n<!-- /parameters -->\nafter\n");
        assert_eq!(with_parameters(&updated, "new\n").as_deref(), Some(updated.as_str()), "idempotent");
        assert_eq!(with_parameters("no markers", "x"), None);
        assert_eq!(with_parameters("<!-- /parameters -->\n<!-- parameters -->", "x"), None, "out of order");
        assert_eq!(with_parameters("<!-- parameters -->\n<!-- parameters -->\n<!-- /parameters -->", "x"), None);
    }
}
