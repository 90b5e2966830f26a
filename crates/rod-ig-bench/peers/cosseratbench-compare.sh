#!/usr/bin/env bash
# Runs rod-ig beside PyElastica and MuJoCo (mujoco<4: 4.0 rejects the suite's cable XML) on the
# cosseratbench scenarios rod-ig covers (cantilever, catenary and its stiffness variants) and on
# rod-ig's own experiment heavy_elastica (w = 1 ... 1000, level and tilted), through the suite's
# own runner; prints its result lines (error metrics, wall time). docs/cosseratbench.md has the
# table of one run. Takes ~5 minutes on two cores.
#
# Usage: crates/rod-ig-bench/peers/cosseratbench-compare.sh [OUT_DIR]   (default: build/cosseratbench)
# Env:   COSSERATBENCH_VENV  venv to create or reuse (default: build/cosseratbench-venv)
set -euo pipefail
REPO="$(cd "$(dirname "$0")/../../.." && pwd)"
OUT="${1:-$REPO/build/cosseratbench}"
VENV="${COSSERATBENCH_VENV:-$REPO/build/cosseratbench-venv}"
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/python" -m pip install --quiet --disable-pip-version-check \
    "cosseratbench==0.3.*" pyelastica "mujoco<4" maturin
# rod-ig itself, built from this checkout into the venv.
(cd "$REPO/python" && PATH="$VENV/bin:$PATH" VIRTUAL_ENV="$VENV" "$VENV/bin/maturin" develop --release --quiet)
mkdir -p "$OUT"
run() { "$VENV/bin/cosseratbench" run "$@" -s rod-ig -s pyelastica -s mujoco -o "$OUT/results"; }
run cantilever catenary -v youngs_modulus | tee "$OUT/suite.log"
run heavy_elastica -v weight -v tilt_deg | tee "$OUT/heavy_elastica.log"
