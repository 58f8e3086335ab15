#!/usr/bin/env bash
# Packages every library crate and the ssm tool as crates.io would take them, and builds each
# package from its own files alone (`cargo package` verifies): path dependencies carry versions,
# the WGSL travels inside ssm-shaders, and no file outside a package is needed. The test crates
# (publish = false) are left out. Run by CI after the README's test command.
set -euo pipefail
cd "$(dirname "$0")/.."
# cargo verifies each package against the others through a local registry, and takes a
# registry's crate of a given name and version as never changing: it unpacks it once (under
# $CARGO_HOME/registry/src/-<hash>/) and compiles it once. On a machine that packaged an older
# state of a crate with the same version, verification would build against those stale sources and
# artifacts. Forget both first: this workspace's unpacked packages, and the fingerprints of its
# crates (path and registry alike, so the next build recompiles the ssm crates, not their deps).
rm -rf "${CARGO_HOME:-$HOME/.cargo}"/registry/src/-*/ssm-*
rm -rf "${CARGO_TARGET_DIR:-target}"/debug/.fingerprint/ssm-*
# --allow-dirty: what is checked is the packages, not whether the tests left the tree clean.
cargo package --workspace --locked --allow-dirty \
    --exclude ssm-integration-tests --exclude ssm-testing --exclude ssm-plugin-technique
