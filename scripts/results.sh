#!/usr/bin/env bash
# Regenerates every results table and figure of the docs and of each technique's README, from
# scratch, with the `ssm` commands that produce them (issue #42):
#   docs/results.md and docs/results/*.svg        every technique on three scenes (times and counted
#                                                 work side by side, per-pass charts, the ground
#                                                 truth's cost), the trade plot, several lights, one scene per kind (docs/choosing.md)
#   ssm-techniques/<t>/results.md (+ results/)    each technique's paper presets and examples
#   README.md, between <!-- summary --> markers   the summary table (words from docs/summary.toml)
#   docs/choosing.md, between <!-- rankings:... --> markers   the rankings of each kind of scene
# On an adapter other than lavapipe (a lent GPU: scripts/gpu-bench-pack.sh) everything goes to one
# file, docs/results-<adapter>.md, beside the lavapipe one.
#
#   scripts/results.sh [--width 320 --height 240 | --paper-sizes] [--frames 5] [--only summary,trade,lights,kinds,pvsm,...]
#   scripts/results.sh --splice-summary   (runs nothing: rewrites README.md's summary block and docs/choosing.md's
#                                          rankings from docs/results/summary.md and docs/results.md;
#                                          python3 scripts/results.py --rankings-from docs/results.md does it without a build)
#   python3 scripts/results.py --check-rankings   (what ssm-bench/tests/rankings.rs runs)
#
# Needs python3 (3.11+, for tomllib). Takes hours on lavapipe at the defaults; --only runs a part.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v python3 >/dev/null || { echo "scripts/results.sh: needs python3" >&2; exit 1; }
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
# SSM_BIN (a prebuilt `ssm`, as on a lent GPU machine): no build; the examples run only if built.
if [ -z "${SSM_BIN:-}" ]; then
    cargo build --release --locked --bin ssm
    cargo build --release --locked -p ssm-atty -p ssm-wedges -p ssm-bench --examples
fi
exec python3 scripts/results.py "$@"
