#!/usr/bin/env bash
# Applies the project's own patches (patches/<crate>-<version>-*.patch) to the crates.io
# releases of two dependencies of the ROS node, at build time, into
# build/patched/<crate>-<version>, which ros/rod_ig/Cargo.toml's [patch.crates-io] points at
# (the node is a Cargo workspace of its own: the math crate and the CLI never need this). The
# repository holds only the patches (each with its rationale in its header), never a copy of
# the crates' sources.
#
# Every entry point (scripts/run-node.sh, scripts/test-all.sh, .ci/run) runs this before cargo;
# run it once by hand before building the node with a bare cargo command. Idempotent and fast
# when done (a stamp holds the patches' checksums). Needs curl (or the crate in cargo's cache),
# sha256sum, tar, and patch or git.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
OUT="$REPO/build/patched"
mkdir -p "$OUT"
# build/ holds Cargo packages (the patched crates) and rod_ig_msgs' build: not for colcon.
touch "$REPO/build/COLCON_IGNORE"

fetch_crate() { # name version expected_sha -> path of the verified .crate
    local name=$1 version=$2 sha=$3 file
    for file in "${CARGO_HOME:-$HOME/.cargo}"/registry/cache/*/"$name-$version.crate"; do
        if [ -f "$file" ] && echo "$sha  $file" | sha256sum -c --quiet - 2>/dev/null; then
            echo "$file"; return 0
        fi
    done
    file="$OUT/$name-$version.crate"
    if ! { [ -f "$file" ] && echo "$sha  $file" | sha256sum -c --quiet - 2>/dev/null; }; then
        curl -sSfL --retry 3 -o "$file.part" "https://static.crates.io/crates/$name/$name-$version.crate"
        echo "$sha  $file.part" | sha256sum -c --quiet - \
            || { echo "patch-deps: $name-$version.crate does not match Cargo.lock's checksum" >&2; exit 1; }
        mv "$file.part" "$file"
    fi
    echo "$file"
}

apply_patch() { # dir patchfile
    if command -v patch >/dev/null; then
        patch -s -p1 -d "$1" <"$2"
    else
        git -C "$1" apply --unsafe-paths -p1 "$2" 2>/dev/null || (cd "$1" && git apply -p1 "$2")
    fi
}

for spec in "rustdds 0.15.1" "ros2-client 0.12.1"; do
    read -r name version <<<"$spec"
    dir="$OUT/$name-$version"
    patches=("$REPO"/patches/"$name-$version"-*.patch)
    stamp="$dir/.rod-ig-patched"
    want="$(cat "${patches[@]}" | sha256sum | cut -d' ' -f1)"
    if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
        continue
    fi
    # The registry's checksum of the unpatched release (Cargo.lock drops it once the crate is
    # patched, so patches/checksums keeps it).
    sha="$(awk -v k="$name-$version" '$1 == k { print $2 }' "$REPO/patches/checksums")"
    [ -n "$sha" ] || { echo "patch-deps: no checksum for $name-$version in patches/checksums" >&2; exit 1; }
    crate="$(fetch_crate "$name" "$version" "$sha")"
    rm -rf "$dir"
    tar -xzf "$crate" -C "$OUT"
    for p in "${patches[@]}"; do
        apply_patch "$dir" "$p" || { echo "patch-deps: $p does not apply to $name-$version" >&2; exit 1; }
    done
    echo "$want" >"$stamp"
    echo "patch-deps: $name-$version patched (${#patches[@]} patch(es))" >&2
done
