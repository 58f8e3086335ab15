//! `ssm new <name>`: a new technique, ready to build, to replace with a paper's method.
//!
//! In an ssm checkout it writes `ssm-techniques/<name>/` (the crate: manifest, source, README,
//! test) and `shaders/<name>/<name>.wgsl`, and adds the technique's one line to the facade
//! (`ssm-techniques/all/Cargo.toml`), the only file it changes. With `--standalone DIR` it writes a
//! crate of its own in DIR instead, with its WGSL inside it, depending on the checkout's crates by
//! path and version, and a `main.rs` that is the `ssm` tool with the technique linked.
//!
//! The files come from templates embedded in the binary (`new/*.tmpl`). Every check runs before
//! anything is written, and a write that fails removes what was written before it.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::present::say;
use crate::registry;

/// `ssm new`'s arguments.
#[derive(clap::Args)]
pub(super) struct NewArgs {
    /// The technique's name (`ssm render --technique <name>`): lowercase ASCII letters, digits and
    /// '-', starting with a letter, not ending with '-'. Its crate is `ssm-<name>`.
    name: String,
    /// Make a crate of its own in DIR (a new or empty folder) instead of adding one to the
    /// checkout: its binary is the `ssm` tool with the technique linked. It depends on the
    /// checkout containing the current directory, else on the one this `ssm` was built from.
    #[arg(long, value_name = "DIR")]
    standalone: Option<PathBuf>,
}

/// Why `ssm new` refuses (nothing is written then).
#[derive(Debug, thiserror::Error)]
pub(crate) enum NewError {
    /// The name cannot name a technique crate.
    #[error(
        "`{name}` is not a valid technique name: {problem} (a name is lowercase ASCII letters, digits and '-', starting with a letter and not ending with '-'; its crate is `ssm-<name>`)"
    )]
    InvalidName {
        /// The name given.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// Something already has the name.
    #[error("`{name}` is taken: {by}")]
    NameTaken {
        /// The name given.
        name: String,
        /// What has it.
        by: String,
    },
    /// Neither the current directory nor any folder above it is an ssm checkout.
    #[error(
        "{} is not inside an ssm checkout (no Cargo.toml with [workspace] beside ssm-techniques/all/ there or above): run `ssm new` inside one, or pass --standalone DIR",
        dir.display()
    )]
    NotInCheckout {
        /// The current directory.
        dir: PathBuf,
    },
    /// `--standalone` found no checkout to depend on.
    #[error(
        "no ssm checkout to depend on: neither {} nor any folder above it is one, and the checkout this ssm was built from ({}) is gone; run it inside a checkout",
        dir.display(),
        built_from.display()
    )]
    NoCheckout {
        /// The current directory.
        dir: PathBuf,
        /// Where this binary was built from.
        built_from: PathBuf,
    },
    /// The `--standalone` folder holds something already.
    #[error("--standalone {}: {problem}; it must be a new or empty folder", dir.display())]
    StandaloneDirTaken {
        /// The folder given.
        dir: PathBuf,
        /// What is there.
        problem: String,
    },
}

/// The crate names [`check_name`] derives from a technique's name.
#[derive(Clone, Debug, PartialEq, Eq)]
struct TechniqueName {
    /// As given: `my-pcf`.
    name: String,
    /// As a Rust and WGSL identifier, the labels' prefix: `my_pcf`.
    ident: String,
    /// As the shader constant `ssm-shaders` makes from the file's name: `MY_PCF`.
    upper: String,
    /// As a Rust type's name: `MyPcf`.
    camel: String,
    /// The crate: `ssm-my-pcf`.
    crate_name: String,
}

/// Rust's keywords (strict and reserved, 2024 edition): a technique named after one would make
/// `ssm_shaders::<keyword>`, which does not compile.
const RUST_KEYWORDS: &[&str] = &[
    "abstract", "as", "async", "await", "become", "box", "break", "const", "continue", "crate", "do", "dyn", "else", "enum", "extern",
    "false", "final", "fn", "for", "gen", "if", "impl", "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv",
    "pub", "ref", "return", "self", "static", "struct", "super", "trait", "true", "try", "type", "typeof", "unsafe", "unsized", "use",
    "virtual", "where", "while", "yield",
];

/// Folders of the checkout that are not techniques' (`ssm-shaders`' build script makes no module
/// of `src` and `target`, `common` and `core` hold the shared WGSL, `all` is the facade).
const RESERVED_FOLDERS: &[&str] = &["all", "common", "core", "src", "target"];

/// Checks `name` as a crate name's tail and derives the other spellings.
fn check_name(name: &str) -> std::result::Result<TechniqueName, NewError> {
    let invalid = |problem: String| NewError::InvalidName { name: name.to_owned(), problem };
    let Some(first) = name.chars().next() else {
        return Err(invalid("it is empty".into()));
    };
    if !first.is_ascii_lowercase() {
        return Err(invalid(format!("it starts with `{first}`, not a lowercase ASCII letter")));
    }
    if let Some(bad) = name.chars().find(|c| !(c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '-')) {
        return Err(invalid(format!("`{bad}` is not a lowercase ASCII letter, a digit or '-'")));
    }
    if name.ends_with('-') {
        return Err(invalid("it ends with '-'".into()));
    }
    let ident = name.replace('-', "_");
    if RUST_KEYWORDS.contains(&ident.as_str()) {
        return Err(invalid(format!("`{ident}` is a Rust keyword, so `ssm_shaders::{ident}` would not compile")));
    }
    let camel = name
        .split('-')
        .filter(|part| !part.is_empty())
        .map(|part| {
            let mut chars = part.chars();
            chars.next().map(|c| c.to_ascii_uppercase()).into_iter().chain(chars).collect::<String>()
        })
        .collect();
    Ok(TechniqueName { name: name.to_owned(), upper: ident.to_ascii_uppercase(), ident, camel, crate_name: format!("ssm-{name}") })
}

/// An ssm checkout: the folder whose Cargo.toml has `[workspace]`, beside `ssm-techniques/all/`.
struct Checkout {
    root: PathBuf,
    /// Its Cargo.toml.
    manifest: toml::Table,
}

impl Checkout {
    /// The checkout at `dir`, if `dir` is one.
    fn at(dir: &Path) -> Option<Self> {
        if !dir.join("ssm-techniques/all/Cargo.toml").is_file() {
            return None;
        }
        let manifest: toml::Table = std::fs::read_to_string(dir.join("Cargo.toml")).ok()?.parse().ok()?;
        manifest.contains_key("workspace").then(|| Self { root: dir.to_owned(), manifest })
    }

    /// The checkout containing `dir`: `dir` or the nearest folder above it that is one.
    fn containing(dir: &Path) -> Option<Self> {
        dir.ancestors().find_map(Self::at)
    }

    fn facade(&self) -> PathBuf {
        self.root.join("ssm-techniques/all/Cargo.toml")
    }

    fn workspace(&self) -> Option<&toml::Table> {
        self.manifest.get("workspace").and_then(toml::Value::as_table)
    }

    /// `[workspace.package]`'s `key`, a string.
    fn package_field(&self, key: &str) -> Option<&str> {
        self.workspace()?.get("package")?.get(key)?.as_str()
    }

    /// The version of the workspace's crates.
    fn version(&self) -> &str {
        self.package_field("version").unwrap_or("0.1.0")
    }

    /// `[workspace.dependencies]`'s entry for `key`.
    fn dependency(&self, key: &str) -> Option<&toml::Value> {
        self.workspace()?.get("dependencies")?.get(key)
    }

    /// The names of the checkout's packages: its members' and its workspace dependencies'.
    fn package_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        if let Some(dependencies) = self.workspace().and_then(|w| w.get("dependencies")).and_then(toml::Value::as_table) {
            for (key, spec) in dependencies {
                names.push(key.clone());
                names.extend(spec.get("package").and_then(toml::Value::as_str).map(str::to_owned));
            }
        }
        let members = self.workspace().and_then(|w| w.get("members")).and_then(toml::Value::as_array).cloned().unwrap_or_default();
        for member in members.iter().filter_map(toml::Value::as_str) {
            let folders: Vec<PathBuf> = match member.strip_suffix("/*") {
                Some(parent) => std::fs::read_dir(self.root.join(parent)).into_iter().flatten().flatten().map(|e| e.path()).collect(),
                None => vec![self.root.join(member)],
            };
            for folder in folders {
                let name = std::fs::read_to_string(folder.join("Cargo.toml"))
                    .ok()
                    .and_then(|text| text.parse::<toml::Table>().ok())
                    .and_then(|manifest| manifest.get("package")?.get("name")?.as_str().map(str::to_owned));
                names.extend(name);
            }
        }
        names
    }
}

/// Refuses a name some registered technique or package of `checkout` has.
fn check_free(name: &TechniqueName, checkout: &Checkout) -> Result<()> {
    let taken = |by: String| NewError::NameTaken { name: name.name.clone(), by };
    if registry()?.iter().any(|info| info.name == name.name) {
        return Err(taken("a registered technique has it (`ssm list`)".into()).into());
    }
    if checkout.package_names().contains(&name.crate_name) {
        return Err(taken(format!("the checkout at {} has a package `{}`", checkout.root.display(), name.crate_name)).into());
    }
    Ok(())
}

/// A file to write: its path and text.
struct Planned {
    path: PathBuf,
    text: String,
}

/// Writes `files`; if one fails, removes `undo` (what did not exist before: folders, files) and
/// reports the failure.
fn write_all(files: &[Planned], undo: &[PathBuf]) -> Result<()> {
    let result = files.iter().try_for_each(|file| -> Result<()> {
        if let Some(parent) = file.path.parent() {
            std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
        }
        std::fs::write(&file.path, &file.text).with_context(|| format!("writing {}", file.path.display()))
    });
    if result.is_err() {
        for path in undo {
            let _ = if path.is_dir() { std::fs::remove_dir_all(path) } else { std::fs::remove_file(path) };
        }
    }
    result.context("what it had written is removed")
}

/// `{{key}}` in `template` replaced by each value.
fn fill(template: &str, values: &[(&str, &str)]) -> String {
    values.iter().fold(template.to_owned(), |text, (key, value)| text.replace(&format!("{{{{{key}}}}}"), value))
}

/// The templates, embedded so that an installed `ssm` has them.
mod templates {
    pub(super) const CARGO_TOML: &str = include_str!("new/Cargo.toml.tmpl");
    pub(super) const STANDALONE_CARGO_TOML: &str = include_str!("new/standalone-Cargo.toml.tmpl");
    pub(super) const LIB_RS: &str = include_str!("new/lib.rs.tmpl");
    pub(super) const MAIN_RS: &str = include_str!("new/main.rs.tmpl");
    pub(super) const SHADER: &str = include_str!("new/technique.wgsl.tmpl");
    pub(super) const README: &str = include_str!("new/README.md.tmpl");
    /// The README's parameter table as `ssm list --parameters-of` prints it for the template's
    /// settings (`{{name}}` for the technique's name): the checkout's docs test compares every
    /// technique README's table with the registry's, so a new crate starts with the right one
    /// (the standalone test checks this file against the built crate's own output).
    pub(super) const PARAMETERS: &str = include_str!("new/parameters.md.tmpl");

    /// The README template with its parameter table in place.
    pub(super) fn readme() -> String {
        README.replace("{{parameters}}", PARAMETERS)
    }
    pub(super) const TEST: &str = include_str!("new/test.rs.tmpl");
}

/// The one-line description in the crate's manifest.
const DESCRIPTION: &str = "A soft-shadow technique for ssm (started from `ssm new`'s percentage-closer filter).";

/// Where the technique's files go and how they refer to each other: in the checkout or standalone.
struct Layout<'a> {
    /// `shaders/<name>/<name>.wgsl` or `shaders/<name>.wgsl`, relative to the crate's readers.
    shader_path: String,
    /// The Rust expression of the WGSL's text.
    shader_source: String,
    /// How the README runs the tool.
    ssm: &'a str,
    /// The crate's folder as the README names it (relative to where the tool runs).
    crate_dir: String,
    /// How the README runs the test.
    test_command: String,
    /// What the README says of the tests the checkout runs over every technique.
    tree_tests: &'a str,
}

/// The values every template reads.
fn values<'a>(name: &'a TechniqueName, layout: &'a Layout<'a>, crate_ident: &'a str) -> Vec<(&'a str, &'a str)> {
    vec![
        ("name", &name.name),
        ("ident", &name.ident),
        ("Camel", &name.camel),
        ("crate", &name.crate_name),
        ("crate_ident", crate_ident),
        ("description", DESCRIPTION),
        ("shader_path", &layout.shader_path),
        ("shader_source", &layout.shader_source),
        ("ssm", layout.ssm),
        ("crate_dir", &layout.crate_dir),
        ("test_command", &layout.test_command),
        ("tree_tests", layout.tree_tests),
    ]
}

/// Runs `ssm new`.
pub(super) fn run(args: &NewArgs) -> Result<()> {
    let refused = || format!("ssm new {}: nothing written", args.name);
    let cwd = std::env::current_dir().context("reading the current directory")?;
    let name = check_name(&args.name).with_context(refused)?;
    match &args.standalone {
        None => {
            let checkout = Checkout::containing(&cwd).ok_or(NewError::NotInCheckout { dir: cwd.clone() }).with_context(refused)?;
            let plan = plan_in_tree(&name, &checkout).with_context(refused)?;
            write_in_tree(&name, &checkout, &plan)
        }
        Some(dir) => {
            let dir = cwd.join(dir);
            let (checkout, which) = standalone_checkout(&cwd).with_context(refused)?;
            let files = plan_standalone(&name, &checkout, &dir).with_context(refused)?;
            write_standalone(&name, &checkout, which, &dir, &files)
        }
    }
}

/// What `ssm new` writes in a checkout: the files, and the facade's new text.
struct InTreePlan {
    files: Vec<Planned>,
    facade: String,
    facade_line: String,
}

/// Checks that `name` is free in `checkout` and plans its files and the facade's line.
fn plan_in_tree(name: &TechniqueName, checkout: &Checkout) -> Result<InTreePlan> {
    let taken = |by: String| NewError::NameTaken { name: name.name.clone(), by };
    if RESERVED_FOLDERS.contains(&name.name.as_str()) {
        return Err(taken(format!("`{}` is a folder of the workspace's own, not a technique's", name.name)).into());
    }
    check_free(name, checkout)?;
    let technique_dir = checkout.root.join("ssm-techniques").join(&name.name);
    let shader_dir = checkout.root.join("shaders").join(&name.name);
    for dir in [&technique_dir, &shader_dir] {
        if dir.symlink_metadata().is_ok() {
            return Err(taken(format!("{} exists", dir.display())).into());
        }
    }
    let facade_path = checkout.facade();
    let facade_text = std::fs::read_to_string(&facade_path).with_context(|| format!("reading {}", facade_path.display()))?;
    let facade_manifest: toml::Table = facade_text.parse().with_context(|| format!("parsing {}", facade_path.display()))?;
    if facade_manifest.get("dependencies").and_then(|d| d.get(&name.crate_name)).is_some() {
        return Err(taken(format!("{} already has a `{}` dependency", facade_path.display(), name.crate_name)).into());
    }
    let facade_line = format!("{} = {{ path = \"../{}\", version = \"{}\" }}", name.crate_name, name.name, checkout.version());
    let facade = with_dependency_line(&facade_text, &name.crate_name, &facade_line)
        .with_context(|| format!("{} has no [dependencies] table to add the line to", facade_path.display()))?;

    let layout = Layout {
        shader_path: format!("shaders/{0}/{0}.wgsl", name.name),
        shader_source: format!("ssm_shaders::{}::{}", name.ident, name.upper),
        ssm: "ssm",
        crate_dir: format!("ssm-techniques/{}/", name.name),
        test_command: format!("cargo test -p {}", name.crate_name),
        tree_tests: "Beside these, the workspace's cross-crate tests take every registered technique, this one included: the extremes matrix (`tests/extremes.rs`: within 0.1 mean absolute error of the ground truth on every extreme scene, unless `limits` declares a looser bound with the paper's reason), several lights (`tests/multi_light.rs`), the uniform layouts and the WGSL's validation.",
    };
    let crate_ident = name.crate_name.replace('-', "_");
    let values = values(name, &layout, &crate_ident);
    let files = vec![
        Planned { path: technique_dir.join("Cargo.toml"), text: fill(templates::CARGO_TOML, &values) },
        Planned { path: technique_dir.join("README.md"), text: fill(&templates::readme(), &values) },
        Planned { path: technique_dir.join("src/lib.rs"), text: fill(templates::LIB_RS, &values) },
        Planned { path: technique_dir.join("tests").join(format!("{}.rs", name.name)), text: fill(templates::TEST, &values) },
        Planned { path: shader_dir.join(format!("{}.wgsl", name.name)), text: fill(templates::SHADER, &values) },
    ];
    Ok(InTreePlan { files, facade, facade_line })
}

/// `manifest` with `line` (the dependency `key`) added to its `[dependencies]` table: among the
/// technique lines (`ssm-x = { path = "../x", ... }`) in name order, else at the table's end.
/// `None` without a `[dependencies]` table.
fn with_dependency_line(manifest: &str, key: &str, line: &str) -> Option<String> {
    let lines: Vec<&str> = manifest.lines().collect();
    let start = lines.iter().position(|l| l.trim() == "[dependencies]")? + 1;
    let end = lines[start..].iter().position(|l| l.trim_start().starts_with('[')).map_or(lines.len(), |offset| start + offset);
    // A technique's line: its key, before the first `=`, and a path beside the facade.
    let techniques: Vec<(usize, &str)> = (start..end)
        .filter(|i| lines[*i].contains("path = \"../"))
        .filter_map(|i| lines[i].split('=').next().map(|k| (i, k.trim())))
        .collect();
    let at = match techniques.iter().find(|(_, other)| *other > key) {
        Some((i, _)) => *i,
        None => match techniques.last() {
            Some((i, _)) => i + 1,
            // After the table's last line that is not blank.
            None => (start..end).rev().find(|i| !lines[*i].trim().is_empty()).map_or(start, |i| i + 1),
        },
    };
    let mut out: Vec<&str> = lines[..at].to_vec();
    out.push(line);
    out.extend(&lines[at..]);
    let mut text = out.join("\n");
    if manifest.ends_with('\n') {
        text.push('\n');
    }
    Some(text)
}

fn write_in_tree(name: &TechniqueName, checkout: &Checkout, plan: &InTreePlan) -> Result<()> {
    let technique_dir = checkout.root.join("ssm-techniques").join(&name.name);
    let shader_dir = checkout.root.join("shaders").join(&name.name);
    let undo = [technique_dir.clone(), shader_dir.clone()];
    let facade = Planned { path: checkout.facade(), text: plan.facade.clone() };
    write_all(&plan.files, &undo)?;
    write_all(std::slice::from_ref(&facade), &undo)?;
    let formatted = format_rust(&plan.files, checkout.package_field("edition").unwrap_or("2024"));
    let relative = |path: &Path| path.strip_prefix(&checkout.root).unwrap_or(path).display().to_string();
    say!("technique `{}` added to the ssm checkout at {}:", name.name, checkout.root.display());
    for file in &plan.files {
        say!("  {}", relative(&file.path));
    }
    say!("  {}: + {}", relative(&facade.path), plan.facade_line);
    say!("{formatted}");
    say!(
        "It is a percentage-closer filter over a shadow map, which builds, runs and passes its test as it is. Next, in {}:",
        checkout.root.display()
    );
    say!("  cargo build --release --bin ssm        (Cargo.lock gains the crate: commit it with the two folders)");
    say!("  target/release/ssm render --scene parallel-square --technique {} --width 160 --height 120 --out out/{}", name.name, name.name);
    say!("  cargo test -p {}", name.crate_name);
    say!(
        "then replace the filter with your paper's method in {} and {}, and the README's sections with its description.",
        relative(&technique_dir.join("src/lib.rs")),
        relative(&shader_dir.join(format!("{}.wgsl", name.name)))
    );
    Ok(())
}

/// Runs rustfmt over the Rust files among `files` (it reads the `rustfmt.toml` above them), so
/// that they pass `cargo fmt --check` whatever the name's length; says what happened, as a line.
/// Without rustfmt the files are left as the templates wrote them.
fn format_rust(files: &[Planned], edition: &str) -> String {
    let rust: Vec<&Path> = files.iter().map(|f| f.path.as_path()).filter(|p| p.extension().is_some_and(|e| e == "rs")).collect();
    match std::process::Command::new("rustfmt").arg("--edition").arg(edition).args(&rust).output() {
        Ok(output) if output.status.success() => "Formatted with rustfmt.".into(),
        Ok(output) => {
            format!("note: rustfmt failed ({}); run `cargo fmt` before committing", String::from_utf8_lossy(&output.stderr).trim())
        }
        Err(e) => format!("note: rustfmt did not run ({e}); run `cargo fmt` before committing"),
    }
}

/// Which checkout a standalone crate depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CheckoutSource {
    /// The one containing the current directory.
    CurrentDirectory,
    /// The one this binary was built from.
    BuiltFrom,
}

/// The checkout containing `cwd`, else the one this binary was built from.
fn standalone_checkout(cwd: &Path) -> Result<(Checkout, CheckoutSource)> {
    if let Some(checkout) = Checkout::containing(cwd) {
        return Ok((checkout, CheckoutSource::CurrentDirectory));
    }
    let built_from = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap_or(Path::new(env!("CARGO_MANIFEST_DIR")));
    match Checkout::at(built_from) {
        Some(checkout) => Ok((checkout, CheckoutSource::BuiltFrom)),
        None => Err(NewError::NoCheckout { dir: cwd.to_owned(), built_from: built_from.to_owned() }.into()),
    }
}

/// A TOML value as it is written in a manifest (a quoted string, an inline table).
fn toml_value(value: &toml::Value) -> String {
    value.to_string()
}

/// The `[workspace.<key>]` tables of `checkout` written as the top-level `[<as_key>]` tables of
/// another manifest (its lints, its profiles).
fn tables_as(checkout: &Checkout, key: &str, as_key: &str) -> String {
    let value = match key {
        "profile" => checkout.manifest.get("profile"),
        _ => checkout.workspace().and_then(|w| w.get(key)),
    };
    let Some(value) = value else { return String::new() };
    let mut table = toml::Table::new();
    table.insert(as_key.to_owned(), value.clone());
    toml::to_string(&table).unwrap_or_default()
}

/// Checks `name` and `dir` and plans the standalone crate's files.
fn plan_standalone(name: &TechniqueName, checkout: &Checkout, dir: &Path) -> Result<Vec<Planned>> {
    check_free(name, checkout)?;
    if dir.symlink_metadata().is_ok() {
        let taken = |problem: &str| NewError::StandaloneDirTaken { dir: dir.to_owned(), problem: problem.to_owned() };
        if !dir.is_dir() {
            return Err(taken("it exists and is not a folder").into());
        }
        if std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?.next().is_some() {
            return Err(taken("it exists and is not empty").into());
        }
    }
    let layout = Layout {
        shader_path: format!("shaders/{}.wgsl", name.name),
        shader_source: format!("include_str!(\"../shaders/{}.wgsl\")", name.name),
        ssm: "cargo run --release --",
        crate_dir: String::new(),
        test_command: "cargo test".into(),
        tree_tests: "The checkout's cross-crate tests (the extremes matrix, several lights) run over the techniques its own tool links, not over this crate: run them on it by adding it to a checkout (`ssm new` there, then copy this crate's src/, shaders/ and tests/ in).",
    };
    let crate_ident = name.crate_name.replace('-', "_");
    let path_of = |relative: &str| toml_value(&toml::Value::String(checkout.root.join(relative).display().to_string()));
    let dependency = |key: &str| checkout.dependency(key).map_or_else(|| "\"*\"".to_owned(), toml_value);
    let manifest_values: Vec<(&str, String)> = vec![
        ("checkout_comment", checkout.root.display().to_string()),
        ("checkout_path_core", path_of("ssm-core")),
        ("checkout_path_bench", path_of("ssm-bench")),
        ("checkout_path_testing", path_of("tests/ssm-testing")),
        ("checkout_path_scene", path_of("ssm-scene")),
        ("ssm_version", checkout.version().to_owned()),
        ("edition", checkout.package_field("edition").unwrap_or("2024").to_owned()),
        ("rust_version", checkout.package_field("rust-version").unwrap_or("1.87").to_owned()),
        ("license", checkout.package_field("license").unwrap_or("MIT OR Apache-2.0").to_owned()),
        ("wgpu", dependency("wgpu")),
        ("bytemuck", dependency("bytemuck")),
        ("glam", dependency("glam")),
        ("lints", tables_as(checkout, "lints", "lints")),
        ("profiles", tables_as(checkout, "profile", "profile")),
    ];
    let mut values = values(name, &layout, &crate_ident);
    values.extend(manifest_values.iter().map(|(k, v)| (*k, v.as_str())));
    let mut files = vec![
        Planned { path: dir.join("Cargo.toml"), text: fill(templates::STANDALONE_CARGO_TOML, &values) },
        Planned { path: dir.join(".gitignore"), text: "/target\n".into() },
        Planned { path: dir.join("README.md"), text: fill(&templates::readme(), &values) },
        Planned { path: dir.join("src/lib.rs"), text: fill(templates::LIB_RS, &values) },
        Planned { path: dir.join("src/main.rs"), text: fill(templates::MAIN_RS, &values) },
        Planned { path: dir.join("shaders").join(format!("{}.wgsl", name.name)), text: fill(templates::SHADER, &values) },
        Planned { path: dir.join("tests").join(format!("{}.rs", name.name)), text: fill(templates::TEST, &values) },
    ];
    // The checkout's formatting and lint settings.
    for file in ["rustfmt.toml", "clippy.toml"] {
        if let Ok(text) = std::fs::read_to_string(checkout.root.join(file)) {
            files.push(Planned { path: dir.join(file), text });
        }
    }
    // The checkout's lock: the same releases of every dependency, so that a build with the
    // checkout's target folder reuses what it compiled (cargo drops the entries it does not use).
    if let Ok(lock) = std::fs::read_to_string(checkout.root.join("Cargo.lock")) {
        files.push(Planned { path: dir.join("Cargo.lock"), text: lock });
    }
    Ok(files)
}

fn write_standalone(name: &TechniqueName, checkout: &Checkout, which: CheckoutSource, dir: &Path, files: &[Planned]) -> Result<()> {
    // Undo: the folder itself when it is new, else what is written at its top.
    let undo: Vec<PathBuf> = if dir.exists() {
        let mut tops: Vec<PathBuf> =
            files.iter().filter_map(|f| f.path.strip_prefix(dir).ok()?.components().next().map(|c| dir.join(c))).collect();
        tops.dedup();
        tops
    } else {
        vec![dir.to_owned()]
    };
    write_all(files, &undo)?;
    let formatted = format_rust(files, checkout.package_field("edition").unwrap_or("2024"));
    say!("technique `{}` written as the crate {} in {}:", name.name, name.crate_name, dir.display());
    for file in files {
        say!("  {}", file.path.strip_prefix(dir).unwrap_or(&file.path).display());
    }
    let whose = match which {
        CheckoutSource::CurrentDirectory => "the checkout containing the current directory",
        CheckoutSource::BuiltFrom => "the checkout this ssm was built from; run `ssm new` inside another to use that one",
    };
    say!("{formatted}");
    say!("It depends on the ssm checkout at {} ({whose}), by path.", checkout.root.display());
    say!("Next, in {} (the checkout's target folder reuses the dependencies it has compiled):", dir.display());
    say!(
        "  CARGO_TARGET_DIR={} cargo run --release -- compare --scene parallel-square --technique {},pcss --width 160 --height 120 --out /tmp/{}-compare",
        checkout.root.join("target").display(),
        name.name,
        name.name
    );
    say!("  cargo test");
    say!("then replace the filter with your paper's method in src/lib.rs and shaders/{}.wgsl, and the README's sections.", name.name);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_checked_and_spelled() {
        let name = check_name("my-pcf2").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            (name.ident.as_str(), name.upper.as_str(), name.camel.as_str(), name.crate_name.as_str()),
            ("my_pcf2", "MY_PCF2", "MyPcf2", "ssm-my-pcf2")
        );
        for (bad, problem) in [
            ("", "empty"),
            ("2d", "starts with `2`"),
            ("-x", "starts with `-`"),
            ("My", "starts with `M`"),
            ("my_pcf", "`_` is not"),
            ("mY", "`Y` is not"),
            ("pcf-", "ends with '-'"),
            ("type", "Rust keyword"),
        ] {
            let message = check_name(bad).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(message.contains(problem), "{bad:?}: {message}");
        }
    }

    #[test]
    fn the_dependency_line_goes_in_name_order_among_the_techniques() {
        let manifest = "[package]\nname = \"x\"\n\n[dependencies]\nssm-core.workspace = true\n# Techniques.\nssm-atty = { path = \"../atty\" }\nssm-pcss = { path = \"../pcss\" }\n\n[build-dependencies]\ntoml.workspace = true\n";
        let line = "ssm-hard = { path = \"../hard\" }";
        let out = with_dependency_line(manifest, "ssm-hard", line).unwrap_or_default();
        assert_eq!(out, manifest.replace("ssm-pcss = ", &format!("{line}\nssm-pcss = ")));
        let last = with_dependency_line(manifest, "ssm-zz", "ssm-zz = { path = \"../zz\" }").unwrap_or_default();
        assert!(last.contains("ssm-pcss = { path = \"../pcss\" }\nssm-zz = { path = \"../zz\" }\n\n[build-dependencies]"), "{last}");
        let none = with_dependency_line("[dependencies]\nssm-core.workspace = true\n\n[lints]\n", "ssm-a", "ssm-a = { path = \"../a\" }");
        assert_eq!(none.as_deref(), Some("[dependencies]\nssm-core.workspace = true\nssm-a = { path = \"../a\" }\n\n[lints]\n"));
        assert!(with_dependency_line("[package]\n", "ssm-a", "x").is_none());
    }

    /// Every placeholder of every template is filled, in both layouts.
    #[test]
    fn templates_leave_no_placeholder() {
        let name = check_name("probe").unwrap_or_else(|e| panic!("{e}"));
        let layout = Layout {
            shader_path: String::new(),
            shader_source: String::new(),
            ssm: "",
            crate_dir: String::new(),
            test_command: String::new(),
            tree_tests: "",
        };
        let values = values(&name, &layout, "ssm_probe");
        let readme = templates::readme();
        for template in [templates::CARGO_TOML, templates::LIB_RS, templates::MAIN_RS, templates::SHADER, readme.as_str(), templates::TEST]
        {
            let text = fill(template, &values);
            assert!(!text.contains("{{"), "{}", text.lines().find(|l| l.contains("{{")).unwrap_or_default());
        }
    }
}
