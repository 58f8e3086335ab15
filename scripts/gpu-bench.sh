#!/usr/bin/env bash
# The speed presets on whatever adapter wgpu picks, at 1920×1080 unless told otherwise, gathered
# into one Markdown table that names the adapter (issue 13: run it on a machine with a GPU and put
# the table beside the lavapipe results; scripts/results.sh, through SSM_BENCH_RESULTS in gpu-bench-device.sh, writes docs/results-<adapter>.md). Every point's work is counted too (`--count-work`,
# issue 40: one extra, untimed frame per point), so the table and each sweep.csv give times and
# counted work (invocations, texel reads, per pass in passes_work) side by side.
#
#   scripts/gpu-bench.sh [OUT]          # default OUT: gpu-bench; writes OUT/gpu-bench.md
#
# Environment: SSM_BENCH_WIDTH, SSM_BENCH_HEIGHT (1920, 1080), SSM_BENCH_FRAMES (5),
# SSM_BENCH_PRESETS (space-separated preset names; default below), SSM_BENCH_SET (extra
# `--set` assignments, space-separated, e.g. "reference.samples=64" to shorten the ground truth),
# SSM_BIN (a prebuilt `ssm` to run instead of building one with cargo: a machine without a Rust
# toolchain or a network, such as a lent GPU machine; scripts/gpu-bench-pack.sh makes one).
set -euo pipefail
cd "$(dirname "$0")/.."

out="${1:-gpu-bench}"
width="${SSM_BENCH_WIDTH:-1920}"
height="${SSM_BENCH_HEIGHT:-1080}"
frames="${SSM_BENCH_FRAMES:-5}"
# Buades et al.'s Table 4 and SSSM's implementation choices beside PCSS (rows past the screen's
# edges, fragment or shared-row passes, sampled or storage reads; PCSS's workgroup tiles), Atty
# et al.'s map sizes (one- and two-sided), 1–3 lights for every technique, Shen et al.'s Figs. 10
# and 11, Forest et al.'s Fig. 12.
presets="${SSM_BENCH_PRESETS:-sssm-table4 sssm-edges sssm-passes pcss-taps atty-map-size-time lights pvsm-fig10 pvsm-fig11 wedges-fig12}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"

settings=()
for assignment in ${SSM_BENCH_SET:-}; do
    settings+=(--set "$assignment")
done

if [ -n "${SSM_BIN:-}" ]; then
    [ -x "$SSM_BIN" ] || { echo "gpu-bench: SSM_BIN=$SSM_BIN is not an executable" >&2; exit 1; }
    ssm() { "$SSM_BIN" "$@"; }
else
    cargo build --release --locked --bin ssm
    ssm() { cargo run --release --locked --quiet --bin ssm -- "$@"; }
fi
mkdir -p "$out"
table="$out/gpu-bench.md"
first=1
for preset in $presets; do
    echo "== $preset" >&2
    ssm sweep --preset "$preset" --width "$width" --height "$height" --frames "$frames" --count-work \
        "${settings[@]}" --out "$out/$preset"
    # sweep.md: a title naming the adapter, a blank line, the header and its rule, then rows.
    if [ "$first" = 1 ]; then
        { echo "# ssm speed presets"; echo; cat "$out/$preset/sweep.md"; } > "$table"
        first=0
    else
        tail -n +5 "$out/$preset/sweep.md" >> "$table"
    fi
done
echo "wrote $table" >&2
