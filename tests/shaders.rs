//! Every WGSL file under `shaders/`, with its imports resolved exactly as at
//! run time, parsed and validated by naga on the CPU: shader errors fail CI
//! without a GPU (rend3's `validate_inherent_shaders` habit).

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use ssm_core::shader::{COMMON_SHADERS, compose_with};

fn wgsl_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            wgsl_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            out.push(path);
        }
    }
}

fn shaders_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders")
}

#[test]
fn every_wgsl_file_parses_and_validates() {
    let root = shaders_dir();
    let mut files = Vec::new();
    wgsl_files(&root, &mut files);
    files.sort();
    assert!(files.len() >= 9, "found only {files:?}");
    let lookup = |import: &str| std::fs::read_to_string(root.join(import)).ok();
    let mut failures = Vec::new();
    for file in &files {
        let source = std::fs::read_to_string(file).unwrap();
        let composed = match compose_with(&source, &lookup) {
            Ok(text) => text,
            Err(e) => {
                failures.push(format!("{}: {e}", file.display()));
                continue;
            }
        };
        let module = match naga::front::wgsl::parse_str(&composed) {
            Ok(module) => module,
            Err(e) => {
                failures.push(format!("{}:\n{}", file.display(), e.emit_to_string(&composed)));
                continue;
            }
        };
        let mut validator = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default());
        if let Err(e) = validator.validate(&module) {
            failures.push(format!("{}:\n{}", file.display(), e.emit_to_string(&composed)));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn embedded_common_shaders_match_the_files() {
    let root = shaders_dir();
    for (path, text) in COMMON_SHADERS {
        let on_disk = std::fs::read_to_string(root.join(path)).unwrap_or_else(|e| panic!("{path}: {e}"));
        assert_eq!(&on_disk, text, "{path}");
    }
    // Every file under common/ is importable at run time.
    let mut files = Vec::new();
    wgsl_files(&root.join("common"), &mut files);
    assert_eq!(files.len(), COMMON_SHADERS.len(), "a file under shaders/common is missing from COMMON_SHADERS");
}

#[test]
fn unknown_imports_and_cycles_are_errors() {
    let lookup = |import: &str| match import {
        "a.wgsl" => Some("// #import b.wgsl\nfn a() {}".to_owned()),
        "b.wgsl" => Some("// #import a.wgsl\nfn b() {}".to_owned()),
        _ => None,
    };
    assert!(compose_with("// #import nope.wgsl", &lookup).unwrap_err().contains("nope.wgsl"));
    assert!(compose_with("// #import a.wgsl", &lookup).unwrap_err().contains("cycle"));
    let diamond = |import: &str| match import {
        "a.wgsl" => Some("// #import c.wgsl\nfn a() {}".to_owned()),
        "b.wgsl" => Some("// #import c.wgsl\nfn b() {}".to_owned()),
        "c.wgsl" => Some("fn c() {}".to_owned()),
        _ => None,
    };
    let composed = compose_with("// #import a.wgsl\n// #import b.wgsl\nfn main() {}", &diamond).unwrap();
    assert_eq!(composed.matches("fn c()").count(), 1, "{composed}");
    assert!(composed.find("fn c()") < composed.find("fn a()"));
}
