#!/usr/bin/env bash
# Builds the Python package rod_ig as a manylinux2014 abi3 wheel (CPython >= 3.10) and an sdist
# into target/wheels/, with maturin and zig as the linker (so the wheel links against glibc 2.17
# whatever this machine's glibc is). Installs maturin and ziglang into a build venv first.
#
#   ./scripts/build-wheel.sh            # -> target/wheels/rod_ig-<version>-cp310-abi3-manylinux_2_17_x86_64.whl
#   pip install target/wheels/rod_ig-*.whl   # on any Linux x86_64 with CPython >= 3.10, no Rust needed
#
# Environment: ROD_IG_BUILD (build directory, default <repo>/build) holds the build venv.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${ROD_IG_BUILD:-$REPO/build}"
VENV="$BUILD/wheel-build-venv"
OUT="$REPO/target/wheels"
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "maturin>=1.9,<2" ziglang
rm -f "$OUT"/rod_ig-*.whl "$OUT"/rod_ig-*.tar.gz
PATH="$VENV/bin:$PATH" "$VENV/bin/maturin" build --release --manifest-path "$REPO/python/Cargo.toml" \
    --zig --compatibility manylinux2014 --sdist --out "$OUT"
ls -1 "$OUT"/rod_ig-*
