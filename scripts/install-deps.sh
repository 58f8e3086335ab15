#!/usr/bin/env bash
# Installs what ssm needs beyond a Rust toolchain on a Debian or Ubuntu
# machine: a Vulkan driver. Without a GPU that is Mesa's software rasteriser
# lavapipe (package mesa-vulkan-drivers). Prints the exact command when it
# cannot install (not root and no sudo).
set -euo pipefail

die() { echo "install-deps: $*" >&2; exit 1; }

command -v cargo >/dev/null 2>&1 || die "cargo is missing: install Rust with rustup (https://rustup.rs), then re-run"

# Any Vulkan ICD will do (a GPU driver or lavapipe).
if compgen -G "/usr/share/vulkan/icd.d/*.json" >/dev/null || compgen -G "/etc/vulkan/icd.d/*.json" >/dev/null; then
    exit 0
fi
command -v apt-get >/dev/null 2>&1 || die "no Vulkan driver found and this is not a Debian-like system: install Mesa's Vulkan drivers (lavapipe) or your GPU's driver"
as_root=()
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null 2>&1 || die "no Vulkan driver found; run as root: apt-get update && apt-get install -y mesa-vulkan-drivers"
    as_root=(sudo)
fi
echo "install-deps: installing mesa-vulkan-drivers (software Vulkan)"
"${as_root[@]}" apt-get update -q
DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y -q mesa-vulkan-drivers
