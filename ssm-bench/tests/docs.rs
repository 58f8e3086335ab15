//! The documentation a new user reads is kept short and current (issue #42): the top README and
//! every technique README at most 300 lines, and each technique README's parameter table equal to
//! what the registry generates (`SSM_BLESS=1` rewrites the tables in place).

use std::path::{Path, PathBuf};

use ssm_bench::docs::{parameters_markdown, with_parameters};

/// The most lines a README may have (issue #42: a researcher reads it in five minutes).
const MAX_README_LINES: usize = 300;

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map(Path::to_path_buf).unwrap_or_default()
}

/// Every technique crate's folder under `ssm-techniques/` (the facade `all` is not one).
fn technique_folders() -> Vec<PathBuf> {
    let mut folders: Vec<PathBuf> = std::fs::read_dir(workspace_root().join("ssm-techniques"))
        .map(|entries| entries.filter_map(|entry| entry.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    folders.retain(|path| path.join("Cargo.toml").is_file() && path.file_name().is_some_and(|name| name != "all"));
    folders.sort();
    folders
}

fn line_count(path: &Path) -> usize {
    std::fs::read_to_string(path).map(|text| text.lines().count()).unwrap_or(usize::MAX)
}

#[test]
fn the_readmes_are_at_most_300_lines() {
    let mut readmes = vec![workspace_root().join("README.md")];
    readmes.extend(technique_folders().into_iter().map(|folder| folder.join("README.md")));
    assert!(readmes.len() > 8, "found the technique folders: {readmes:?}");
    let long: Vec<String> = readmes
        .iter()
        .filter(|path| line_count(path) > MAX_README_LINES)
        .map(|path| format!("{} ({} lines)", path.display(), line_count(path)))
        .collect();
    assert!(long.is_empty(), "READMEs over {MAX_README_LINES} lines (lab notes go to docs/notes/): {long:?}");
}

#[test]
fn every_technique_readme_lists_its_parameters_as_the_registry_does() {
    let registry = ssm_bench::registry().unwrap_or_else(|e| panic!("registry: {e}"));
    let bless = std::env::var_os("SSM_BLESS").is_some();
    let mut stale = Vec::new();
    let folders = technique_folders();
    assert!(folders.len() >= 8, "technique folders: {folders:?}");
    for folder in folders {
        let name = folder.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let info = registry.get(&name).unwrap_or_else(|e| panic!("{}: {e}", folder.display()));
        let table = parameters_markdown(info).unwrap_or_else(|e| panic!("{name}: {e}"));
        let path = folder.join("README.md");
        let readme = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let updated = with_parameters(&readme, &table).unwrap_or_else(|| {
            panic!("{}: needs exactly one `<!-- parameters -->` line followed by one `<!-- /parameters -->` line", path.display())
        });
        if updated != readme {
            if bless {
                std::fs::write(&path, updated).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            } else {
                stale.push(path.display().to_string());
            }
        }
    }
    assert!(stale.is_empty(), "parameter tables out of date (rerun with SSM_BLESS=1): {stale:?}");
}

/// The top README's summary table is the one `scripts/results.sh` generated: between its markers,
/// a row for every technique docs/summary.toml describes and the line naming the command, adapter,
/// date and commit. (A technique new to the checkout joins it when summary.toml names it and the
/// script runs again: a test cannot ask for an hour of lavapipe.)
#[test]
fn the_readme_carries_the_generated_summary_table() {
    let readme = std::fs::read_to_string(workspace_root().join("README.md")).unwrap_or_default();
    let summary = readme
        .split_once("<!-- summary -->")
        .and_then(|(_, rest)| rest.split_once("<!-- /summary -->"))
        .map(|(summary, _)| summary)
        .unwrap_or_else(|| panic!("README.md needs `<!-- summary -->` and `<!-- /summary -->` lines"));
    let words: toml::Table = std::fs::read_to_string(workspace_root().join("docs/summary.toml"))
        .unwrap_or_default()
        .parse()
        .unwrap_or_else(|e| panic!("docs/summary.toml: {e}"));
    let names: Vec<String> = words
        .get("technique")
        .and_then(toml::Value::as_array)
        .map(|entries| entries.iter().filter_map(|entry| entry.get("name")?.as_str().map(str::to_owned)).collect())
        .unwrap_or_default();
    assert!(names.len() >= 8, "docs/summary.toml describes the techniques: {names:?}");
    for name in names {
        let link = format!("| [`{name}`](ssm-techniques/{name}/README.md) |");
        assert!(summary.lines().any(|line| line.starts_with(&link)), "no summary row for {name} (run scripts/results.sh):\n{summary}");
    }
    assert!(
        summary.lines().any(|line| line.starts_with("From `scripts/results.sh") && line.contains("commit")),
        "the summary names the command that made it:\n{summary}"
    );
}
