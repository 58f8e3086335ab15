#!/usr/bin/env bash
# Runs scripts/gpu-bench.sh on a lent GPU machine with what scripts/gpu-bench-pack.sh packed in
# .gpu-bench/ (a prebuilt `ssm`, the Vulkan loader and GL dispatch libraries), and hands back through $OUT (the device
# tool's folder) the one Markdown table and an archive of every preset's sweep.csv and sweep.md,
# each with the times and the counted work (`--count-work`) side by side.
# Refuses to time a software adapter unless SSM_BENCH_ALLOW_CPU=1 (how it is tested here).
#
#   scripts/gpu-bench-device.sh        # on the lent machine; $OUT must be set
#
# Environment: as scripts/gpu-bench.sh (SSM_BENCH_PRESETS, ...), and SSM_BENCH_LIMIT_S (480): the
# bench is stopped after that many seconds and what it finished is handed back, so that a run
# ends inside the device tool's 10-minute limit on a command; SSM_BENCH_PACK (.gpu-bench): the
# packed folder, relative to the repository's root or absolute; SSM_BENCH_RESULTS: instead of the
# speed presets, run scripts/results.sh (needs python3) with these arguments (e.g. "--only
# summary,trade --width 1920 --height 1080") and hand back docs/results-<adapter>.md and its plots,
# the file a GPU run adds beside the lavapipe docs/results.md.
set -euo pipefail
cd "$(dirname "$0")/.."
# ldconfig lives in /sbin, which a user other than root may not have on PATH.
PATH="$PATH:/sbin:/usr/sbin"

out="${OUT:?gpu-bench-device: OUT is not set (the device tool sets it)}"
pack="${SSM_BENCH_PACK:-.gpu-bench}"
[ -x "$pack/ssm" ] || { echo "gpu-bench-device: $pack/ssm is missing: run scripts/gpu-bench-pack.sh first and carry $pack" >&2; exit 1; }

# The Vulkan loader and the GL dispatch libraries the NVIDIA driver's Vulkan library loads, where
# the machine lacks one (unpacked into /, as the device tool's notes say). (grep reads the whole
# list: `grep -q` would close the pipe on ldconfig, failing the pipeline.)
libraries=$(ldconfig -p)
missing=0
for library in libvulkan.so.1 libGLX.so.0 libEGL.so.1 libGLdispatch.so.0; do
    grep -F "$library" <<<"$libraries" >/dev/null || missing=1
done
if [ "$missing" = 1 ]; then
    debs=("$pack"/debs/*.deb)
    [ -e "${debs[0]}" ] || { echo "gpu-bench-device: this machine lacks the Vulkan loader or GL dispatch libraries and $pack/debs has none to unpack" >&2; exit 1; }
    for deb in "${debs[@]}"; do
        dpkg -x "$deb" /
    done
    ldconfig
fi
# The NVIDIA driver's Vulkan manifest, where the loader's usual folders do not list it.
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$nvidia_icd" ] \
    && ! compgen -G "/usr/share/vulkan/icd.d/nvidia*.json" >/dev/null && ! compgen -G "/etc/vulkan/icd.d/nvidia*.json" >/dev/null; then
    export VK_DRIVER_FILES="$nvidia_icd"
fi
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"

# sed reads the whole listing: `head` would close the pipe on `ssm`, which fails on the write.
adapter=$("$pack/ssm" list | sed -n 1p) || { echo "gpu-bench-device: \`ssm list\` failed: no adapter, or the binary does not run here" >&2; exit 1; }
echo "gpu-bench-device: $adapter" >&2
echo "$adapter" > "$out/adapter.txt"
case "$adapter" in
    *llvmpipe* | *"Vulkan Cpu"* | *SwiftShader*)
        if [ "${SSM_BENCH_ALLOW_CPU:-}" != 1 ]; then
            echo "gpu-bench-device: wgpu found only a software adapter; not timing it (SSM_BENCH_ALLOW_CPU=1 does)" >&2
            exit 1
        fi
        ;;
esac

work=$(mktemp -d)
status=0
if [ -n "${SSM_BENCH_RESULTS:-}" ]; then
    # shellcheck disable=SC2086 # the arguments are meant to split
    SSM_BIN="$(cd "$pack" && pwd)/ssm" timeout -k 20 "${SSM_BENCH_LIMIT_S:-480}" scripts/results.sh --output-root "$work" $SSM_BENCH_RESULTS || status=$?
    (cd "$work" && find . -type f | sort | tar -czf "$out/results.tar.gz" -T -)
    cp "$work"/docs/results*.md "$out"/ 2>/dev/null || true
    [ "$status" = 0 ] || echo "gpu-bench-device: results.sh ended with status $status (124: stopped at SSM_BENCH_LIMIT_S)" >&2
    exit "$status"
fi
# SIGKILL 20 s after the SIGTERM, for an `ssm` stuck in the driver.
SSM_BIN="$(cd "$pack" && pwd)/ssm" timeout -k 20 "${SSM_BENCH_LIMIT_S:-480}" scripts/gpu-bench.sh "$work" || status=$?
# What finished comes back, also after the time limit (status 124).
[ -f "$work/gpu-bench.md" ] && cp "$work/gpu-bench.md" "$out/gpu-bench.md"
(cd "$work" && find . -name 'sweep.csv' -o -name 'sweep.md' | sort | tar -czf "$out/sweeps.tar.gz" -T -)
[ "$status" = 0 ] || echo "gpu-bench-device: gpu-bench.sh ended with status $status (124: stopped at SSM_BENCH_LIMIT_S)" >&2
exit "$status"
