//! Writes `link_all()` from this crate's own manifest: one call to `link()`
//! for every dependency but ssm-core, so that adding a technique is one line
//! in `Cargo.toml`.

use std::fmt::Write as _;

fn main() {
    println!("cargo::rerun-if-changed=Cargo.toml");
    let manifest_dir = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into());
    let manifest = std::fs::read_to_string(format!("{manifest_dir}/Cargo.toml")).unwrap_or_else(|e| panic!("reading Cargo.toml: {e}"));
    let parsed: toml::Table = manifest.parse().unwrap_or_else(|e| panic!("parsing Cargo.toml: {e}"));
    let dependencies = parsed.get("dependencies").and_then(toml::Value::as_table).cloned().unwrap_or_default();
    let crates: Vec<String> = dependencies.keys().filter(|name| *name != "ssm-core").map(|name| name.replace('-', "_")).collect();
    let mut code = String::from(
        "/// Links every technique crate (and the ground truth in ssm-core), so that\n/// their registrations are present; returns their names, sorted.\n#[must_use]\npub fn link_all() -> Vec<&'static str> {\n    let mut names = vec![ssm_core::reference::link()",
    );
    for name in &crates {
        let _ = write!(code, ", {name}::link()");
    }
    code.push_str("];\n    names.sort_unstable();\n    names\n}\n\n/// The crates linked, as Cargo names them (`ssm_atty`, ...).\npub const CRATES: &[&str] = &[");
    for name in &crates {
        let _ = write!(code, "{name:?}, ");
    }
    code.push_str("];\n");
    let out = std::env::var("OUT_DIR").unwrap_or_else(|e| panic!("OUT_DIR: {e}"));
    std::fs::write(format!("{out}/link_all.rs"), code).unwrap_or_else(|e| panic!("writing link_all.rs: {e}"));
}
