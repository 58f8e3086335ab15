//! The README's steps, in their order, on a clean copy of the checkout, in one target folder, as a
//! user would run them: its set-up command, `ssm new halo`, the build, list,
//! render and test that `ssm new`'s output gives, then every command of its tour:
//! `scripts/readme-steps.sh`, which says step by step what it runs.
//!
//! Ignored by a plain `cargo test`: the copy's release build and the new technique's test build
//! compile every ssm crate twice more (and, from a cold cache, every dependency in the release
//! profile), more than `scripts/test.sh`'s time allows. CI runs it, explicitly, as its own step
//! after the README's test command (`.ci/run`:
//! `cargo test -p ssm-bench --test readme_steps -- --ignored`), so it never goes unrun.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

#[test]
#[ignore = "minutes of release builds: .ci/run runs it with --ignored after the README's test command"]
fn the_readme_steps_pass_in_order_on_a_clean_copy() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/readme-steps.sh");
    let started = Instant::now();
    // One stream, stdout and stderr interleaved as they were written, so a failure reads in order.
    let output = Command::new("bash")
        .arg("-c")
        .arg("\"$0\" 2>&1")
        .arg(&script)
        .output()
        .unwrap_or_else(|e| panic!("running {}: {e}", script.display()));
    let log = String::from_utf8_lossy(&output.stdout);
    // Shown by the test harness on failure (and with --nocapture).
    println!("{log}");
    let failed = log.lines().find(|line| line.starts_with("readme-steps: FAILED")).unwrap_or("(no step named)");
    assert!(
        output.status.success(),
        "scripts/readme-steps.sh exited with {} after {:.0} s: {failed}",
        output.status,
        started.elapsed().as_secs_f64()
    );
}
