//! Replays, on stable, what the fuzz targets (`fuzz/`, nightly) start from and
//! what they found: the seeds (`fuzz/seeds/<target>/` and this crate's loader
//! corpus `tests/corpus/<format>/`) and every input that ever crashed, hung or
//! ran out of memory (`fuzz/regressions/<target>/`). Each goes through
//! `ssm_scene::fuzzing::load`, the function the fuzz targets call, so it is
//! loaded exactly as `ssm render --scene FILE` loads it. None may panic (not
//! even inside a loader, where a panic would be caught and turned into an
//! error), and each must finish within [`TIME_LIMIT`].

// Test helpers unwrap too: a failure should stop the test where it happens.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use ssm_scene::fuzzing::{Target, load};

/// Far above what any of these files takes (milliseconds); a hang is caught well before CI's limit.
const TIME_LIMIT: Duration = Duration::from_secs(10);

/// What `load_model` says when a parser panicked: it must never be seen.
const CAUGHT_PANIC: &str = "the parser failed on malformed data";

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The files of a folder, sorted; none if it does not exist.
fn files(folder: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .map(|entries| entries.map(|e| e.unwrap().path()).filter(|p| p.is_file() && !p.ends_with("README.md")).collect())
        .unwrap_or_default();
    files.sort();
    files
}

/// Loads `file` as `target` on a thread of its own; the outcome, or why it is a bug.
fn replay(target: Target, file: &Path) -> Result<Result<(), String>, String> {
    let data = std::fs::read(file).unwrap();
    let (send, receive) = mpsc::channel();
    let started = Instant::now();
    std::thread::spawn(move || {
        let _ = send.send(load(target, &data));
    });
    match receive.recv_timeout(TIME_LIMIT) {
        Ok(Err(message)) if message.contains(CAUGHT_PANIC) => Err(format!("a loader panicked: {message}")),
        Ok(outcome) => Ok(outcome),
        Err(mpsc::RecvTimeoutError::Timeout) => Err(format!("still running after {:?}", started.elapsed())),
        Err(mpsc::RecvTimeoutError::Disconnected) => Err("panicked".into()),
    }
}

/// The seed and regression folders of a target.
fn folders(target: Target) -> [(PathBuf, bool); 3] {
    [
        // (folder, whether every file in it must load)
        (repo().join("fuzz/seeds").join(target.name()), true),
        // The loader corpus has a folder per format, named as the targets are (none for manifests).
        (repo().join("ssm-scene/tests/corpus").join(target.name()), false),
        (repo().join("fuzz/regressions").join(target.name()), false),
    ]
}

#[test]
fn seeds_and_regressions_neither_panic_nor_hang() {
    let mut bugs = Vec::new();
    for target in Target::ALL {
        let mut replayed = 0;
        for (folder, must_load) in folders(target) {
            for file in files(&folder) {
                replayed += 1;
                match replay(target, &file) {
                    Ok(Ok(())) => {}
                    Ok(Err(message)) if must_load => bugs.push(format!("{}: a seed must load: {message}", file.display())),
                    Ok(Err(_)) => {}
                    Err(bug) => bugs.push(format!("{} ({}): {bug}", file.display(), target.name())),
                }
            }
        }
        assert!(replayed > 0, "no seeds for the {} target", target.name());
    }
    assert!(bugs.is_empty(), "{}", bugs.join("\n"));
}
