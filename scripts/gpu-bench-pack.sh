#!/usr/bin/env bash
# Packs what scripts/gpu-bench-device.sh needs on a lent GPU machine that has no Rust toolchain
# and no network (issue 13, item 7), into .gpu-bench/ (ignored by git):
#
#   .gpu-bench/ssm      the release `ssm`, stripped of its debug information (about 20 MB: the
#                       device tool carries at most 64 MiB with the working tree)
#   .gpu-bench/debs/    Debian's Vulkan loader and GL dispatch libraries (the device tool's
#                       list: libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2,
#                       which the NVIDIA driver's Vulkan library loads), unpacked there only
#                       where the machine lacks them; the driver itself is the machine's
#
# Then prints the device tool's `run` call. Run on x86-64 Debian or Ubuntu (the machine's
# processor is x86-64); needs apt-get for the loader.
#
#   scripts/gpu-bench-pack.sh
set -euo pipefail
cd "$(dirname "$0")/.."

case "$(uname -m)" in
    x86_64) ;;
    *) echo "gpu-bench-pack: the GPU machine is x86-64 and this machine is $(uname -m): pack on an x86-64 machine" >&2; exit 1 ;;
esac
command -v strip >/dev/null || { echo "gpu-bench-pack: 'strip' is missing (binutils)" >&2; exit 1; }
command -v apt-get >/dev/null || { echo "gpu-bench-pack: apt-get is missing: download Debian's libvulkan1 .deb into .gpu-bench/debs yourself" >&2; exit 1; }

pack=.gpu-bench
rm -rf "$pack"
mkdir -p "$pack/debs"
cargo build --release --locked --bin ssm
strip -o "$pack/ssm" target/release/ssm
# The loader for the machine's architecture, whatever this machine's apt is set up for.
lists=$(mktemp -d)
trap 'rm -rf "$lists"' EXIT
mkdir -p "$lists/partial"
apt_options=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists")
apt-get "${apt_options[@]}" update -q >/dev/null
(cd "$pack/debs" && apt-get "${apt_options[@]}" download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 >/dev/null)
du -sh "$pack"
cat <<'EOF'
gpu-bench-pack: ready. On the lent machine (the device tool's run), with carry [".gpu-bench"]:
  scripts/gpu-bench-device.sh
(SSM_BENCH_PRESETS, SSM_BENCH_WIDTH, SSM_BENCH_HEIGHT, SSM_BENCH_FRAMES and SSM_BENCH_SET
choose less; SSM_BENCH_LIMIT_S, default 480, stops it in time to hand back what it has.)
EOF
