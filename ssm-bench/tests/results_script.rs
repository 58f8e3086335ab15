//! `scripts/results.sh --only <parts>` rewrites only its own parts of docs/results.md: the merge in
//! `scripts/results.py` (`part_sections`, `merged_sections`), run with python3 on a small file.

use std::path::Path;
use std::process::Command;

#[test]
fn a_partial_run_replaces_its_own_parts_and_keeps_the_others_in_their_order() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/results.py");
    // A previous file: a report's own `## Counted work` stays inside its part, as do `### ` subsections.
    let check = r####"
import importlib.util, sys
spec = importlib.util.spec_from_file_location("results", sys.argv[1])
results = importlib.util.module_from_spec(spec)
spec.loader.exec_module(results)
previous = "# Results\n\n## summary\n\nold summary\n\n## defaults\n\nold defaults\n### `contact`\nold contact\n## Counted work\nold counts\n\n## trade\n\nold trade\n\n## kinds\n\nold kinds\n"
fresh = results.part_sections("\n".join(["## summary\n\nnew summary\n", "## defaults\n\nnew defaults\n", "### `contact`\nnew contact\n", "## lights\n\nnew lights\n"]))
print("".join(results.merged_sections(previous, fresh)), end="")
"####;
    let output = Command::new("python3")
        // No scripts/__pycache__ left in the checkout by the import of results.py.
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .arg("-c")
        .arg(check)
        .arg(&script)
        .output()
        .expect("python3 runs (scripts/install-deps.sh --for-tests installs it)");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let merged = String::from_utf8(output.stdout).unwrap();
    let expected = "## summary\n\nnew summary\n## defaults\n\nnew defaults\n\n### `contact`\nnew contact\n## trade\n\nold trade\n## kinds\n\nold kinds\n## lights\n\nnew lights\n";
    assert_eq!(merged, expected, "merged:\n{merged}");
}
