//! `ssm new`: a technique from anywhere. Its refusals write nothing; in a checkout it writes the
//! technique's two folders and the facade's one line and changes nothing else; `--standalone`
//! writes a crate that builds against this checkout and whose binary lists and renders the new
//! technique beside the built-in ones (which compiles the templates' Rust and WGSL).

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

/// The checkout this test belongs to.
fn checkout() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_owned()
}

/// `ssm new <args>` run in `dir`.
fn ssm_new(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ssm")).arg("new").args(args).current_dir(dir).output().expect("the ssm binary runs")
}

/// A fresh folder under the system's temporary folder (outside every checkout).
fn temp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ssm-new-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A fake checkout: the workspace's Cargo.toml, the facade's, and empty technique and shader folders.
fn fake_checkout(test: &str) -> PathBuf {
    let root = temp_dir(test);
    std::fs::create_dir_all(root.join("ssm-techniques/all")).unwrap();
    std::fs::create_dir_all(root.join("shaders")).unwrap();
    std::fs::copy(checkout().join("Cargo.toml"), root.join("Cargo.toml")).unwrap();
    std::fs::copy(checkout().join("ssm-techniques/all/Cargo.toml"), root.join("ssm-techniques/all/Cargo.toml")).unwrap();
    root
}

/// Every file and folder under `root`, by relative path, with its bytes (`None` for a folder).
fn snapshot(root: &Path) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Option<Vec<u8>>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let relative = path.strip_prefix(root).unwrap().to_owned();
            if path.is_dir() {
                out.insert(relative, None);
                walk(root, &path, out);
            } else {
                out.insert(relative, Some(std::fs::read(&path).unwrap()));
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(root, root, &mut out);
    out
}

/// A refusal: exit status 1, one line on stderr starting `error:` that says `needle`, nothing on stdout.
fn assert_refused(output: &Output, needle: &str) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(
        lines[0].starts_with("error: ") && lines[0].contains("nothing written") && lines[0].contains(needle),
        "expected `{needle}`: {stderr}"
    );
    assert!(output.stdout.is_empty(), "{}", String::from_utf8_lossy(&output.stdout));
}

#[test]
fn refusals_write_nothing() {
    let root = fake_checkout("refusals");
    // Something already there under each name: a technique folder, a shader folder, a facade line.
    std::fs::create_dir_all(root.join("ssm-techniques/has-folder/src")).unwrap();
    std::fs::write(root.join("ssm-techniques/has-folder/src/lib.rs"), "// someone's work\n").unwrap();
    std::fs::create_dir_all(root.join("shaders/has-shaders")).unwrap();
    let facade = root.join("ssm-techniques/all/Cargo.toml");
    let text = std::fs::read_to_string(&facade).unwrap();
    let with_line =
        text.replacen("[dependencies]\n", "[dependencies]\nssm-has-line = { path = \"../has-line\", version = \"0.1.0\" }\n", 1);
    std::fs::write(&facade, with_line).unwrap();
    let before = snapshot(&root);
    let cases: &[(&str, &str)] = &[
        // Taken.
        ("pcss", "`pcss` is taken: a registered technique has it"),
        ("reference", "`reference` is taken: a registered technique has it"),
        ("has-folder", "ssm-techniques/has-folder exists"),
        ("has-shaders", "shaders/has-shaders exists"),
        ("has-line", "already has a `ssm-has-line` dependency"),
        ("all", "a folder of the workspace's own"),
        ("common", "a folder of the workspace's own"),
        ("scene", "has a package `ssm-scene`"),
        ("framework", "has a package `ssm-framework`"),
        // Not a crate name's tail.
        ("My-pcf", "starts with `M`, not a lowercase ASCII letter"),
        ("2d", "starts with `2`"),
        ("my_pcf", "`_` is not a lowercase ASCII letter, a digit or '-'"),
        ("my pcf", "` ` is not a lowercase ASCII letter"),
        ("pcf-", "it ends with '-'"),
        ("", "it is empty"),
        ("fn", "`fn` is a Rust keyword"),
    ];
    for (name, needle) in cases {
        assert_refused(&ssm_new(&root.join("shaders"), &[name]), needle);
    }
    assert!(before == snapshot(&root), "a refusal changed the checkout");

    // Outside a checkout, without --standalone.
    let outside = temp_dir("outside");
    assert_refused(&ssm_new(&outside, &["fine-name"]), "is not inside an ssm checkout");
    assert!(snapshot(&outside).is_empty());

    // --standalone into a folder that holds something, or is a file.
    std::fs::write(outside.join("notes.txt"), "mine\n").unwrap();
    assert_refused(&ssm_new(&outside, &["fine-name", "--standalone", "."]), "it exists and is not empty");
    assert_refused(&ssm_new(&outside, &["fine-name", "--standalone", "notes.txt"]), "it exists and is not a folder");
    // A registered name is refused standalone too: the binary would register it twice.
    assert_refused(&ssm_new(&outside, &["hard", "--standalone", "new-folder"]), "`hard` is taken");
    let files: Vec<PathBuf> = snapshot(&outside).into_keys().collect();
    assert_eq!(files, [PathBuf::from("notes.txt")]);
    std::fs::remove_dir_all(&root).unwrap();
    std::fs::remove_dir_all(&outside).unwrap();
}

#[test]
fn in_a_checkout_it_writes_two_folders_and_one_facade_line() {
    let root = fake_checkout("in-tree");
    let facade = root.join("ssm-techniques/all/Cargo.toml");
    let facade_before = std::fs::read_to_string(&facade).unwrap();
    let before = snapshot(&root);
    // From a folder inside the checkout: it walks up to the workspace's root.
    let output = ssm_new(&root.join("ssm-techniques"), &["my-pcf"]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{}{stdout}", String::from_utf8_lossy(&output.stderr));

    let after = snapshot(&root);
    let added: Vec<&PathBuf> = after.keys().filter(|path| !before.contains_key(*path)).collect();
    let expected = [
        "shaders/my-pcf",
        "shaders/my-pcf/my-pcf.wgsl",
        "ssm-techniques/my-pcf",
        "ssm-techniques/my-pcf/Cargo.toml",
        "ssm-techniques/my-pcf/README.md",
        "ssm-techniques/my-pcf/src",
        "ssm-techniques/my-pcf/src/lib.rs",
        "ssm-techniques/my-pcf/tests",
        "ssm-techniques/my-pcf/tests/my-pcf.rs",
    ];
    let expected: Vec<PathBuf> = expected.iter().map(PathBuf::from).collect();
    assert_eq!(added, expected.iter().collect::<Vec<_>>());
    let changed: Vec<&PathBuf> = before.keys().filter(|path| before[*path] != after[*path]).collect();
    assert_eq!(changed, [&PathBuf::from("ssm-techniques/all/Cargo.toml")], "only the facade changes");

    // The facade: exactly one line more, the technique's, among the technique lines in name order.
    let facade_after = std::fs::read_to_string(&facade).unwrap();
    let line = "ssm-my-pcf = { path = \"../my-pcf\", version = \"0.1.0\" }";
    let mut without: Vec<&str> = facade_after.lines().collect();
    let at = without.iter().position(|l| *l == line).unwrap_or_else(|| panic!("no `{line}` in:\n{facade_after}"));
    without.remove(at);
    assert_eq!(without, facade_before.lines().collect::<Vec<_>>());
    let previous = facade_after.lines().nth(at - 1).unwrap();
    let next = facade_after.lines().nth(at + 1).unwrap();
    assert!(previous.starts_with("ssm-multi-sm ") && next.starts_with("ssm-pcss "), "between `{previous}` and `{next}`");
    let parsed: toml::Table = facade_after.parse().unwrap();
    assert!(parsed["dependencies"].get("ssm-my-pcf").is_some());

    // The files: every placeholder filled, the in-tree shader constant, the workspace's dependencies.
    for path in expected.iter().map(|p| root.join(p)).filter(|p| p.is_file()) {
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(!text.contains("{{"), "{}: a placeholder is left", path.display());
    }
    let lib = std::fs::read_to_string(root.join("ssm-techniques/my-pcf/src/lib.rs")).unwrap();
    assert!(lib.contains("const SHADER: &str = ssm_shaders::my_pcf::MY_PCF;"), "{lib}");
    assert!(lib.contains("pub const NAME: &str = \"my-pcf\";") && lib.contains("\"my_pcf_filter\""));
    let manifest: toml::Table = std::fs::read_to_string(root.join("ssm-techniques/my-pcf/Cargo.toml")).unwrap().parse().unwrap();
    assert_eq!(manifest["package"]["name"].as_str(), Some("ssm-my-pcf"));
    for dependency in ["ssm-core", "ssm-shaders", "wgpu", "bytemuck"] {
        assert_eq!(manifest["dependencies"][dependency]["workspace"].as_bool(), Some(true), "{dependency}");
    }
    assert!(stdout.contains("cargo test -p ssm-my-pcf"), "{stdout}");

    // Again: now taken, and nothing changes.
    let again = snapshot(&root);
    assert_refused(&ssm_new(&root, &["my-pcf"]), "is taken");
    assert!(again == snapshot(&root));
    std::fs::remove_dir_all(&root).unwrap();
}

/// The standalone crate end to end: written outside every checkout, built with this workspace's
/// target folder (so that only the ssm crates, as path dependencies of another workspace, and the
/// new crate compile; the registry's crates are reused), and its binary lists and renders the new
/// technique beside the built-in ones; its own test passes.
#[test]
fn a_standalone_crate_builds_lists_and_renders() {
    let parent = temp_dir("standalone");
    let dir = parent.join("probe");
    let output = ssm_new(&parent, &["probe", "--standalone", "probe"]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{}{stdout}", String::from_utf8_lossy(&output.stderr));
    assert!(stdout.contains(&format!("ssm checkout at {} (the checkout this ssm was built from", checkout().display())), "{stdout}");
    for file in ["Cargo.toml", "Cargo.lock", "src/lib.rs", "src/main.rs", "shaders/probe.wgsl", "README.md", "tests/probe.rs"] {
        let text = std::fs::read_to_string(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(!text.contains("{{"), "{file}: a placeholder is left");
    }
    let manifest: toml::Table = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap().parse().unwrap();
    let core = &manifest["dependencies"]["ssm-core"];
    assert_eq!(core["package"].as_str(), Some("ssm-framework"));
    assert_eq!(core["path"].as_str(), Some(checkout().join("ssm-core").to_str().unwrap()));
    assert!(core["version"].is_str() && manifest.contains_key("workspace"));

    // `CARGO_TARGET_TMPDIR` is `<target>/tmp`: the workspace's target folder is its parent.
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().unwrap();
    let started = Instant::now();
    let build = Command::new(env!("CARGO")).arg("build").current_dir(&dir).env("CARGO_TARGET_DIR", target).output().unwrap();
    let stderr = String::from_utf8_lossy(&build.stderr);
    let compiled: Vec<&str> = stderr.lines().filter_map(|l| l.trim().strip_prefix("Compiling ")).collect();
    println!("cargo build of the standalone crate: {:.1} s, compiled {}", started.elapsed().as_secs_f64(), compiled.join(", "));
    assert!(build.status.success(), "{stderr}");

    let binary = target.join("debug").join(format!("ssm-probe{}", std::env::consts::EXE_SUFFIX));
    let list = Command::new(&binary).arg("list").output().unwrap();
    let listed = String::from_utf8_lossy(&list.stdout);
    assert!(list.status.success(), "{}", String::from_utf8_lossy(&list.stderr));
    for technique in ["probe", "hard", "pcss", "reference"] {
        assert!(listed.lines().any(|l| l.starts_with(&format!("{technique}: "))), "{technique} missing from:\n{listed}");
    }
    // The README's parameter table is the one the registry generates for the built crate (what the
    // checkout's docs test demands of every technique README).
    let table = Command::new(&binary).args(["list", "--parameters-of", "probe"]).output().unwrap();
    assert!(table.status.success(), "{}", String::from_utf8_lossy(&table.stderr));
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let table = String::from_utf8_lossy(&table.stdout);
    assert_eq!(
        ssm_bench::docs::with_parameters(&readme, &table).as_deref(),
        Some(readme.as_str()),
        "README.md's parameter table differs from `ssm list --parameters-of probe` (regenerate ssm-bench/src/commands/new/parameters.md.tmpl):\n{table}"
    );
    let out = parent.join("render");
    let render = Command::new(&binary)
        .args(["render", "--scene", "parallel-square", "--technique", "probe,pcss", "--width", "48", "--height", "36", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(render.status.success(), "{}", String::from_utf8_lossy(&render.stderr));
    let visibility = image::open(out.join("probe/visibility.png")).unwrap().into_luma16();
    assert_eq!(visibility.dimensions(), (48, 36));
    assert!(
        visibility.pixels().any(|p| p.0[0] == 0) && visibility.pixels().any(|p| p.0[0] == u16::MAX),
        "the square's umbra and the lit receiver are both there"
    );
    assert!(out.join("pcss/visibility.png").is_file());

    // The crate's own test (the parallel-square checks the template writes) passes as written.
    let test = Command::new(env!("CARGO")).arg("test").current_dir(&dir).env("CARGO_TARGET_DIR", target).output().unwrap();
    let test_stdout = String::from_utf8_lossy(&test.stdout);
    assert!(test.status.success(), "{}{test_stdout}", String::from_utf8_lossy(&test.stderr));
    assert!(test_stdout.contains("test result: ok. 3 passed"), "{test_stdout}");
    std::fs::remove_dir_all(&parent).unwrap();
}
