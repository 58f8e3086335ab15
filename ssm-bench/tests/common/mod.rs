//! What the CLI tests share: techniques picked from the registry by what
//! they offer, never by name, so that the tests hold for whatever techniques
//! are linked; and, for the browser tests, Chromium and its offline flags.

#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

use ssm_core::{GpuContext, ParamKind, TechniqueInfo, TechniqueKind};

/// The real-time techniques this adapter can run at their defaults, sorted by name.
pub fn runnable() -> Vec<&'static TechniqueInfo> {
    let gpu = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    ssm_bench::registry()
        .unwrap()
        .iter()
        .filter(|i| i.kind == TechniqueKind::Realtime)
        .filter(|i| (i.requirements)(&i.default_params()).and_then(|r| r.check_device(i.name, &gpu)).is_ok())
        .collect()
}

/// Two different runnable techniques, each with an integer parameter and a quality knob.
pub fn two_techniques() -> (&'static TechniqueInfo, &'static TechniqueInfo) {
    let with_knobs: Vec<_> = runnable().into_iter().filter(|i| int_param(i).is_some() && i.trade.is_some()).collect();
    assert!(with_knobs.len() >= 2, "fewer than two techniques with an integer parameter and a quality knob");
    (with_knobs[0], with_knobs[1])
}

/// An integer parameter of `info`: (name, default, min, max).
pub fn int_param(info: &TechniqueInfo) -> Option<(&'static str, i64, i64, i64)> {
    info.params.iter().find_map(|p| match p.kind {
        ParamKind::Int { default, min, max } if min < max => Some((p.name, default, min, max)),
        _ => None,
    })
}

/// The prefix every pass label of `info` starts with (`multi-sm` → `multi_sm`).
pub fn pass_prefix(info: &TechniqueInfo) -> String {
    info.name.replace('-', "_")
}

/// The first `count` values of `info`'s quality knob, as a `--vary` specification.
pub fn knob_vary(info: &TechniqueInfo, count: usize) -> (String, usize) {
    let knob = info.trade.unwrap();
    let (params, values) = knob.split_once('=').unwrap();
    let kept: Vec<&str> = values.split(',').take(count).collect();
    (format!("{}.{params}={}", info.name, kept.join(",")), kept.len())
}

/// Splits one CSV line, honouring quotes.
pub fn split_csv(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

/// The index of `name` in a CSV header line.
pub fn column(header: &str, name: &str) -> usize {
    header.split(',').position(|c| c == name).unwrap_or_else(|| panic!("no column {name} in {header}"))
}

/// Flags for a headless Chromium that reaches nothing outside the machine.
pub const OFFLINE_FLAGS: &[&str] = &[
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
];

/// The Chromium on this machine; the test fails, saying how to install it, when there is none.
pub fn chromium_binary() -> &'static str {
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|b| Command::new(b).arg("--version").output().is_ok_and(|o| o.status.success()))
        .unwrap_or_else(|| panic!("no Chromium found: install it with scripts/install-deps.sh --for-tests (Debian package chromium)"))
}
