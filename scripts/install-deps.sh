#!/usr/bin/env bash
# Installs what ssm needs beyond a Rust toolchain on a Debian or Ubuntu
# machine: a C++ compiler (g++: the meshopt crate builds meshoptimizer's C++
# decoders), a Vulkan driver (without a GPU, Mesa's software rasteriser
# lavapipe, package mesa-vulkan-drivers) and, with --for-tests, Chromium for
# the report test and, for the `ssm view` test, a virtual X server (xvfb),
# xdotool (keys and mouse), ImageMagick (screenshots) and the X libraries
# winit opens at run time. Prints the exact command when it cannot install (not root
# and no sudo).
#
#   scripts/install-deps.sh              what `ssm` needs to run
#   scripts/install-deps.sh --for-tests  and what the tests need
set -euo pipefail

die() { echo "install-deps: $*" >&2; exit 1; }

command -v cargo >/dev/null 2>&1 || die "cargo is missing: install Rust with rustup (https://rustup.rs), then re-run"

packages=()
# The cc crate compiles C++ with $CXX, else `c++` (which g++ provides).
if ! command -v "${CXX:-c++}" >/dev/null 2>&1; then
    packages+=(g++)
fi
# Any Vulkan ICD will do (a GPU driver or lavapipe).
if ! compgen -G "/usr/share/vulkan/icd.d/*.json" >/dev/null && ! compgen -G "/etc/vulkan/icd.d/*.json" >/dev/null; then
    packages+=(mesa-vulkan-drivers)
fi
if [ "${1:-}" = "--for-tests" ]; then
    command -v chromium >/dev/null 2>&1 || packages+=(chromium)
    command -v Xvfb >/dev/null 2>&1 || packages+=(xvfb)
    command -v xdotool >/dev/null 2>&1 || packages+=(xdotool)
    command -v import >/dev/null 2>&1 || packages+=(imagemagick)
    # scripts/results.sh assembles its Markdown with Python 3.11 (tomllib); a test runs it.
    command -v python3 >/dev/null 2>&1 || packages+=(python3)
    # winit loads these with dlopen, so nothing at build time asks for them.
    if command -v dpkg >/dev/null 2>&1; then
        for library in libxkbcommon-x11-0 libxcursor1 libxi6 libxrandr2 libx11-xcb1; do
            dpkg -s "$library" >/dev/null 2>&1 || packages+=("$library")
        done
    fi
fi
[ ${#packages[@]} -eq 0 ] && exit 0

command -v apt-get >/dev/null 2>&1 || die "missing ${packages[*]} and this is not a Debian-like system: install a C++ compiler, Mesa's Vulkan drivers (or your GPU's) and Chromium"
as_root=()
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null 2>&1 || die "run as root: apt-get update && apt-get install -y ${packages[*]}"
    as_root=(sudo)
fi
echo "install-deps: installing ${packages[*]}"
"${as_root[@]}" apt-get update -q
DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y -q "${packages[@]}"
