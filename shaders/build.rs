//! Writes one module per folder of WGSL files under this crate (`common`, `core`, one per
//! technique), each file a constant embedded with `include_str!`, and `FILES`, every file by its
//! path under `shaders/`: a new technique's folder needs no line here.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// An identifier from a file or folder name: letters and digits kept, the rest `_`.
fn identifier(name: &str, upper: bool) -> String {
    let mut out: String = name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
    if out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, '_');
    }
    if upper { out.to_ascii_uppercase() } else { out.to_ascii_lowercase() }
}

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into()));
    let mut folders: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap_or_else(|e| panic!("{}: {e}", root.display()))
        .filter_map(|entry| entry.ok().map(|entry| entry.path()))
        .filter(|path| path.is_dir() && !matches!(path.file_name().and_then(|n| n.to_str()), Some("src" | "target")))
        .collect();
    folders.sort();
    // A folder added to or removed from this crate (a new technique's, as `ssm new` writes)
    // changes the crate's own listing: watched, so that its module is written on the next build.
    // (Each folder is watched below for the files added to it.)
    println!("cargo::rerun-if-changed={}", root.display());
    let mut code = String::new();
    let mut all = Vec::new();
    for folder in &folders {
        // A file added to or removed from the folder changes its listing.
        println!("cargo::rerun-if-changed={}", folder.display());
        let folder_name = folder.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_owned();
        let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
            .unwrap_or_else(|e| panic!("{}: {e}", folder.display()))
            .filter_map(|entry| entry.ok().map(|entry| entry.path()))
            .filter(|path| path.extension().is_some_and(|e| e == "wgsl"))
            .collect();
        files.sort();
        if files.is_empty() {
            continue;
        }
        let _ = writeln!(code, "/// The WGSL files of `shaders/{folder_name}/`.\npub mod {} {{", identifier(&folder_name, false));
        let mut entries = Vec::new();
        for file in &files {
            let file_name = file.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            let stem = Path::new(file_name).file_stem().and_then(|n| n.to_str()).unwrap_or_default();
            let constant = identifier(stem, true);
            let import = format!("{folder_name}/{file_name}");
            let _ = writeln!(code, "    /// `{import}`.\n    pub const {constant}: &str = include_str!({:?});", file.display());
            entries.push(format!("({import:?}, {constant})"));
            all.push(format!("({import:?}, {}::{constant})", identifier(&folder_name, false)));
        }
        let _ = writeln!(
            code,
            "    /// Every file of the folder, by its path under `shaders/` (how an import names it).\n    pub const FILES: &[(&str, &str)] = &[{}];\n}}\n",
            entries.join(", ")
        );
    }
    let _ = writeln!(
        code,
        "/// Every WGSL file, by its path under `shaders/` (how an import names it).\npub const FILES: &[(&str, &str)] = &[{}];",
        all.join(", ")
    );
    let out = std::env::var("OUT_DIR").unwrap_or_else(|e| panic!("OUT_DIR: {e}"));
    std::fs::write(Path::new(&out).join("shaders.rs"), code).unwrap_or_else(|e| panic!("writing shaders.rs: {e}"));
}
