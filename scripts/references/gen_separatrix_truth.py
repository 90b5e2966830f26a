#!/usr/bin/env python3
"""Rigorous high-precision reference for planar rods near the separatrix and under strong force.

Why: rods with tiny bending (|a3|, |a5| down to 1e-14) under strong axial force (|a4| up to 1e4)
linger by the unstable straight equilibrium, where rounding made along the rod grows by up to
e^{√‖F‖} ≈ 1e43: f64 and even double-double integrations are wrong there, and the closed form's
own accuracy has to be measured against something better than either. This script integrates
the planar rod ODE (κ' = a4 sin θ − a5 cos θ, θ' = κ, x' = cos θ, y' = sin θ, E' = κ²/2; the
Taylor recurrences of src/planar/taylor.rs) in arb ball arithmetic (python-flint, 320-bit
midpoints): every number carries a rigorous bound of its rounding error, J = ∂(x, y, θ)/∂a is
carried along as forward-mode derivatives, and each Taylor step (h = 0.3/ω, ω = max(|a3|,
√‖F‖, 1)) is truncated at an order whose last term is below 1e-60 of the series' scale.
det J(t) is read on the grid {i/2000} by Horner evaluation inside the steps.

Writes crates/rod-ig-core/tests/data/separatrix_truth.jsonl, one line per rod:
{"a", "tip": [x, y, theta], "jac": rows x, y, theta × columns a3, a4, a5, "energy",
 "radius" (largest ball radius relative to its value's scale: the rounding bound),
 "stable": true | false | null (null: some det J ball contains 0), "det_min" (min over grid
 t ≥ 0.05 of det J(t)/(t⁹(a3²/8640 + a5²t²/33600)), "first_conjugate" (first grid t with
 det J ≤ 0, or null)}.
Run: python3 scripts/references/gen_separatrix_truth.py [N=600]   (needs python-flint; ≈ 1 s per rod, two
processes); `--extreme [N=160]` writes separatrix_truth_extreme.jsonl instead, issue 23's
tiny-bending sample; `--strong [N=48]` writes separatrix_truth_strong.jsonl, tension beyond the
double-double series' reach (√‖F‖ 100..500) at up to ~925 bits; `--edge [N=16]`
separatrix_truth_edge.jsonl, √‖F‖ 500..700 at up to ~1215 bits; `--verdicts IN OUT` writes only the verdicts of the rods listed in IN.
The samples are seeded: the same files every run.
"""
import json, math, pathlib, random, sys
from multiprocessing import Pool

import flint
from flint import arb

PREC = 320
GRID = 2000


def dmul(u, w):
    return [u[0] * w[0], u[0] * w[1] + u[1] * w[0], u[0] * w[2] + u[2] * w[0],
            u[0] * w[3] + u[3] * w[0]]


def reference(a, prec=PREC):
    flint.ctx.prec = prec
    a3, a4, a5 = a
    Z = arb(0)

    def dual(v, i=None):
        d = [arb(v), Z, Z, Z]
        if i is not None:
            d[i + 1] = arb(1)
        return d

    A4, A5 = arb(a4), arb(a5)
    k, th, c, s, x, y = dual(a3, 0), dual(0), dual(1), dual(0), dual(0), dual(0)
    e = Z
    omega = max(abs(a3), math.sqrt(math.hypot(a4, a5)), 1.0)
    # n equal steps of exact length 1/n: the rod's length is exactly 1 (a float running sum
    # of step lengths is not)
    steps = math.ceil(omega / 0.3)
    grid = [i / GRID for i in range(1, GRID + 1)]
    gi = 0
    dets = []  # (t, det ball)
    for step in range(steps):
        t0 = step / steps
        h = 1.0 / steps
        K, TH, C, S, X, Y, E = [k], [th], [c], [s], [x], [y], [e]
        n = 0
        while True:
            sk, ck, kk = [Z] * 4, [Z] * 4, Z
            for j in range(n + 1):
                sk = [p + q for p, q in zip(sk, dmul(S[j], K[n - j]))]
                ck = [p + q for p, q in zip(ck, dmul(C[j], K[n - j]))]
                kk += K[j][0] * K[n - j][0]
            inv = arb(1) / (n + 1)
            cn, sn = C[n], S[n]
            kn = [A4 * sn[0] - A5 * cn[0], A4 * sn[1] - A5 * cn[1],
                  A4 * sn[2] + sn[0] - A5 * cn[2], A4 * sn[3] - A5 * cn[3] - cn[0]]
            K.append([v * inv for v in kn])
            TH.append([v * inv for v in K[n]])
            C.append([-v * inv for v in sk])
            S.append([v * inv for v in ck])
            X.append([v * inv for v in C[n]])
            Y.append([v * inv for v in S[n]])
            E.append(kk * inv / 2)
            n += 1
            if n >= 12:
                # last two terms at h, relative to the series' scale (≥ 1): below 1e-60
                tail = max(abs(float(P[m][i].mid())) * h ** m
                           for P in (K, C, S, X, Y) for m in (n - 1, n) for i in range(4))
                if tail < 1e-60 or n > 400:
                    break
        hh = arb(1) / steps

        def ev(P, dt):
            acc = list(P[-1])
            for co in reversed(P[:-1]):
                acc = [acc[i] * dt + co[i] for i in range(4)]
            return acc

        def ev1(P, dt):
            acc = P[-1]
            for co in reversed(P[:-1]):
                acc = acc * dt + co
            return acc

        while gi < GRID and gi * steps < (step + 1) * GRID:
            # grid point (gi + 1)/GRID lies in [step/steps, (step + 1)/steps]
            dt = arb(gi + 1) / GRID - arb(step) / steps
            px, py, pt = ev(X, dt), ev(Y, dt), ev(TH, dt)
            m = [px[1:], py[1:], pt[1:]]
            det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                   - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                   + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
            dets.append((grid[gi], det))
            gi += 1
        k, th, c, s, x, y = ev(K, hh), ev(TH, hh), ev(C, hh), ev(S, hh), ev(X, hh), ev(Y, hh)
        e = ev1(E, hh)
    out = [x, y, th]
    radius = 0.0
    for row in out:
        scale = max(abs(float(v.mid())) for v in row[1:]) or 1.0
        radius = max(radius, float(row[0].rad()), max(float(v.rad()) for v in row[1:]) / scale)
    radius = max(radius, float(e.rad()) / max(abs(float(e.mid())), 1e-300))
    stable, first, det_min = True, None, math.inf
    for t, d in dets:
        lead = t ** 9 * (a3 * a3 / 8640 + a5 * a5 * t * t / 33600)
        if d.contains(0):
            stable = None if stable else stable
            if first is None:
                first = t
            break
        if d < 0:
            stable, first = False, t
            if lead > 0:
                det_min = min(det_min, float(d.mid()) / lead) if t >= 0.05 else float(d.mid()) / lead
            break
        if t >= 0.05 and lead > 0:
            det_min = min(det_min, float(d.mid()) / lead)
    return {
        "a": list(a),
        "tip": [float(v[0].mid()) for v in out],
        "jac": [[float(v.mid()) for v in row[1:]] for row in out],
        "energy": float(e.mid()),
        "radius": radius,
        "stable": stable,
        "det_min": det_min if math.isfinite(det_min) else None,
        "first_conjugate": first,
    }


def sample(n):
    r = random.Random(2026)

    def signed(lo, hi):
        v = 10 ** r.uniform(lo, hi)
        return -v if r.random() < 0.5 else v

    out = []
    for i in range(n):
        kind = i % 4
        if kind in (0, 1):  # strong tension, tiny bending: the separatrix
            a = [signed(-14, 0), 10 ** r.uniform(1, 4), signed(-14, 0)]
        elif kind == 2:  # strong force of either sign
            a = [signed(-14, 0), signed(0, 4), signed(-14, 0)]
        else:  # moderate force, tiny to moderate bending
            a = [signed(-14, 0.5), signed(-0.5, 2), signed(-14, 0.5)]
        if i % 10 == 7:
            a[2] = 0.0
        out.append(a)
    return out


def strong_precision(a):
    """Bits for a rod under tension beyond √‖F‖ = 100: rounding made near the straight
    equilibrium grows like e^{√‖F‖} (1.44·√‖F‖ bits), plus 200 bits for the 1e-60 truncation
    and the answer's own digits; 320 at least."""
    return max(PREC, int(1.45 * math.sqrt(math.hypot(a[1], a[2]))) + 200)


def reference_strong(a):
    return reference(a, strong_precision(a))


def sample_strong(n, seed=4005, lo=4.0, hi=5.4):
    """Beyond the double-double series' reach: tension 10^lo..10^hi (√‖F‖ 100..500), moment
    and transverse force 1e-14..1e-3 with some exact zeros (`--strong`; each rod at
    `strong_precision` bits, ~10–40 s). `--edge`: tension 2.5e5..5e5 (√‖F‖ 500..707, up to
    where J ≈ e^{√‖F‖} overflows f64), ~1 minute per rod."""
    r = random.Random(seed)

    def signed(lo, hi):
        v = 10 ** r.uniform(lo, hi)
        return -v if r.random() < 0.5 else v

    def small():
        return 0.0 if r.random() < 0.15 else signed(-14, -3)

    out = []
    while len(out) < n:
        a = [small(), 10 ** r.uniform(lo, hi), small()]
        if a[0] != 0.0 or a[2] != 0.0:
            out.append(a)
    return out


def sample_extreme(n):
    """Issue 23's independent sample: axial force 1e3..1e4 of either sign, moment and transverse
    force 1e-14..1e-6 with some exact zeros, and the rod issue 23 quotes (a 320-bit integration
    calls it stable, det_min 2.73; it came back "unstable, uncertain", margin -2.1e39)."""
    r = random.Random(2311)

    def signed(lo, hi):
        v = 10 ** r.uniform(lo, hi)
        return -v if r.random() < 0.5 else v

    def small():
        return 0.0 if r.random() < 0.15 else signed(-14, -6)

    out = [[0.0, 2473.289745880672, 2.3178627609785778e-14]]
    while len(out) < n:
        a = [small(), signed(3, 4), small()]
        if a[0] != 0.0 or a[2] != 0.0:
            out.append(a)
    return out


def verdicts(path_in, path_out):
    """The reference verdict and det_min only, for the rods listed in path_in (one JSON array
    [a3, a4, a5] per line): tests/data/stability_truth_tiny_bending.jsonl holds the 30 rods of
    a seeded tiny-bending sample that the double-double stability scan called "unstable" with a
    certain verdict (issue 23)."""
    rods = [json.loads(line) for line in open(path_in) if line.strip()]
    with Pool(2) as pool:
        rows = pool.map(reference, rods, chunksize=1)
    with open(path_out, "w") as f:
        for row in rows:
            keep = {k: row[k] for k in ("a", "stable", "det_min", "first_conjugate")}
            f.write(json.dumps(keep) + "\n")


if __name__ == "__main__":
    if "--verdicts" in sys.argv:
        i = sys.argv.index("--verdicts")
        verdicts(sys.argv[i + 1], sys.argv[i + 2])
        sys.exit(0)
    extreme = "--extreme" in sys.argv
    strong = "--strong" in sys.argv
    edge = "--edge" in sys.argv
    args = [v for v in sys.argv[1:] if not v.startswith("--")]
    n = int(args[0]) if args else (160 if extreme else 48 if strong else 16 if edge else 600)
    name = ("separatrix_truth_extreme.jsonl" if extreme else
            "separatrix_truth_strong.jsonl" if strong else
            "separatrix_truth_edge.jsonl" if edge else "separatrix_truth.jsonl")
    path = pathlib.Path(__file__).resolve().parents[2] / "crates/rod-ig-core/tests/data" / name
    with Pool(2) as pool:
        if strong:
            rows = pool.map(reference_strong, sample_strong(n), chunksize=1)
        elif edge:
            rows = pool.map(reference_strong, sample_strong(n, 4006, 5.4, 5.69), chunksize=1)
        else:
            rows = pool.map(reference, (sample_extreme if extreme else sample)(n), chunksize=1)
    with open(path, "w") as f:
        for row in rows:
            f.write(json.dumps(row) + "\n")
    print(f"wrote {len(rows)} rods to {path}")
