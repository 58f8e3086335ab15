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
    // `rust/<Struct>`: a uniform's WGSL declaration, written by its Rust struct's derive
    // (`UniformStruct::WGSL`) and listed among its technique's importable files.
    let generated: Vec<(&str, &str)> = ssm_integration_tests::registry()
        .iter()
        .flat_map(|info| info.uniforms.iter().flat_map(|check| check.imports.iter().copied()))
        .filter(|(path, _)| path.starts_with("rust/"))
        .collect();
    let lookup = |import: &str| {
        std::fs::read_to_string(root.join(import))
            .ok()
            .or_else(|| generated.iter().find(|(path, _)| *path == import).map(|(_, text)| (*text).to_owned()))
    };
    // A file another imports is validated inside each importer's composed module (naga validates
    // every function of a module, used or not), so it may call what its importers define (sssm's
    // blur cores call the `*_source` of their fragment or compute entry file).
    let imported: Vec<PathBuf> = files
        .iter()
        .flat_map(|file| {
            let source = std::fs::read_to_string(file).unwrap();
            source
                .lines()
                .filter_map(|line| line.trim().strip_prefix(ssm_core::shader::IMPORT_PREFIX.trim_end()).map(|path| root.join(path.trim())))
                .collect::<Vec<_>>()
        })
        .collect();
    let mut validated = 0;
    let mut failures = Vec::new();
    for file in files.iter().filter(|file| !imported.contains(file)) {
        validated += 1;
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
        // The capabilities of the optional features a shader may use when the device has them
        // (ssm_core::OPTIONAL_FEATURES): the forced early depth test of wedges' counting build.
        let capabilities = naga::valid::Capabilities::default() | naga::valid::Capabilities::EARLY_DEPTH_TEST;
        let mut validator = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities);
        if let Err(e) = validator.validate(&module) {
            failures.push(format!("{}:\n{}", file.display(), e.emit_to_string(&composed)));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(validated >= 9, "validated only {validated} of {files:?}");
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

/// A WGSL struct's size and its members' names and byte offsets.
type WgslLayout = (u32, Vec<(String, u32)>);

/// The size and field offsets of a WGSL struct, from naga's reflection of `source` (imports resolved).
fn wgsl_layout(source: &str, imports: &[(&str, &str)], name: &str) -> Result<WgslLayout, String> {
    let lookup = |path: &str| COMMON_SHADERS.iter().chain(imports).find(|(p, _)| *p == path).map(|(_, text)| (*text).to_owned());
    let composed = compose_with(source, &lookup)?;
    let module = naga::front::wgsl::parse_str(&composed).map_err(|e| e.emit_to_string(&composed))?;
    module
        .types
        .iter()
        .find_map(|(_, ty)| match &ty.inner {
            naga::TypeInner::Struct { members, span } if ty.name.as_deref() == Some(name) => {
                Some((*span, members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect()))
            }
            _ => None,
        })
        .ok_or_else(|| format!("no struct `{name}` in the WGSL"))
}

/// Differences between a Rust uniform and the WGSL struct that reads it: size, and the offset of
/// every WGSL member (Rust fields named `_pad...`/`pad...` are padding and need no WGSL twin).
fn layout_mismatches(rust: &ssm_core::RustLayout, (size, members): &WgslLayout) -> Vec<String> {
    let mut out = Vec::new();
    if rust.size != *size as usize {
        out.push(format!("{} is {} bytes, the WGSL struct {size}", rust.name, rust.size));
    }
    for (name, offset) in members {
        match rust.fields.iter().find(|(field, _)| field == name) {
            Some((_, rust_offset)) if *rust_offset == *offset as usize => {}
            Some((_, rust_offset)) => out.push(format!("{}.{name} is at byte {rust_offset}, in WGSL at {offset}", rust.name)),
            None if name.starts_with("_pad") || name.starts_with("pad") => {}
            None => out.push(format!("{} has no field `{name}` (WGSL offset {offset})", rust.name)),
        }
    }
    for (field, _) in rust.fields {
        let padding = field.starts_with("_pad") || field.starts_with("pad");
        if !padding && !members.iter().any(|(name, _)| name == field) {
            out.push(format!("{}.{field} has no WGSL member", rust.name));
        }
    }
    out
}

/// Every registered technique's uniforms, and the framework's own, match the WGSL structs the
/// shaders read them as: a field added, moved or resized on one side only fails here, without a GPU.
#[test]
fn every_uniform_matches_its_wgsl_struct() {
    use ssm_core::UniformStruct;
    let core_shader = |file: &str| std::fs::read_to_string(shaders_dir().join(file)).unwrap();
    let mut checks: Vec<(String, ssm_core::RustLayout, Result<WgslLayout, String>)> = vec![
        (
            "core/light_frame".into(),
            ssm_core::LightFrameUniform::LAYOUT,
            wgsl_layout(&core_shader("core/light_depth.wgsl"), &[], "LightFrame"),
        ),
        ("core/camera".into(), ssm_core::CameraUniform::LAYOUT, wgsl_layout(&core_shader("common/camera.wgsl"), &[], "Camera")),
        (
            "core/light_depth".into(),
            ssm_core::DepthBiasUniform::LAYOUT,
            wgsl_layout(&core_shader("core/light_depth.wgsl"), &[], "DepthBias"),
        ),
    ];
    let registry = ssm_integration_tests::registry();
    for info in registry.iter() {
        for check in info.uniforms {
            checks.push((info.name.to_owned(), check.rust, wgsl_layout(check.wgsl_source, check.imports, check.wgsl_struct)));
        }
    }
    let techniques_checked = registry.iter().filter(|i| !i.uniforms.is_empty()).count();
    assert!(techniques_checked >= 5, "only {techniques_checked} techniques declare their uniforms");
    let mut failures = Vec::new();
    for (owner, rust, wgsl) in &checks {
        match wgsl {
            Ok(layout) => failures.extend(layout_mismatches(rust, layout).into_iter().map(|m| format!("{owner}: {m}"))),
            Err(e) => failures.push(format!("{owner}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The comparison itself fails on a moved field, a resized struct and a missing member.
#[test]
fn a_mismatched_layout_is_reported() {
    let wgsl = (16, vec![("a".to_owned(), 0), ("b".to_owned(), 4), ("_pad0".to_owned(), 8), ("_pad1".to_owned(), 12)]);
    let good = ssm_core::RustLayout { name: "Good", size: 16, fields: &[("a", 0), ("b", 4), ("_pad0", 8), ("_pad1", 12)] };
    assert!(layout_mismatches(&good, &wgsl).is_empty());
    let moved = ssm_core::RustLayout { name: "Moved", size: 16, fields: &[("b", 0), ("a", 4), ("_pad", 8)] };
    assert_eq!(layout_mismatches(&moved, &wgsl).len(), 2);
    let short = ssm_core::RustLayout { name: "Short", size: 12, fields: &[("a", 0), ("b", 4), ("c", 8)] };
    assert_eq!(layout_mismatches(&short, &wgsl).len(), 2, "{:?}", layout_mismatches(&short, &wgsl));
}
