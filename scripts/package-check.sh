#!/usr/bin/env bash
# Packages every library crate and the ssm tool as crates.io would take them, and builds each
# package from its own files alone (`cargo package` verifies): path dependencies carry versions,
# the WGSL travels inside ssm-shaders, and no file outside a package is needed. The test crates
# (publish = false) are left out. Run by CI after the README's test command.
set -euo pipefail
cd "$(dirname "$0")/.."
# --allow-dirty: what is checked is the packages, not whether the tests left the tree clean.
cargo package --workspace --locked --allow-dirty \
    --exclude ssm-integration-tests --exclude ssm-testing --exclude ssm-plugin-technique
