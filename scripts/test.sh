#!/usr/bin/env bash
# Every check CI runs, in order: dependencies (Vulkan driver, Chromium), test
# models, formatting, lints, then every test of the workspace (GPU tests run
# on lavapipe when there is no GPU). Ground-truth images are cached in a
# throw-away folder so that every run traces afresh.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-deps.sh --for-tests
scripts/fetch-models.sh
# Mesa's loader looks for a Wayland socket; headless runs have none.
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
export SSM_CACHE_DIR="${SSM_CACHE_DIR:-$(mktemp -d)}"

cargo fmt --all --check
cargo clippy --workspace --all-targets --locked -- -D warnings
# --all-targets also runs the criterion benches once each, in their test mode.
cargo test --workspace --all-targets --locked
# The documentation's examples (--all-targets leaves them out): ssm-scene's opening example.
cargo test --workspace --doc --locked
# The API documentation builds without a warning (broken links, private items
# linked from public docs); missing_docs is already a lint of every crate.
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked
