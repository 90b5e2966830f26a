#!/usr/bin/env python3
"""Generate high-precision reference values for crates/rod-ig-core/tests/elliptic.rs.

Uses mpmath at 80 significant digits. Each case fixes one f64 parameter exactly: either m1
(near the separatrix, m = 1 - m1 computed in high precision; the Rust side receives m1 and
fl(1 - m1)) or m (small m; the Rust side receives m and fl(1 - m)).

Outputs (JSON lines):
  tests/data/elliptic_jacobi.jsonl     u, m, m1, sn, cn, dn, am (continuous), e_am = E(am u|m)
  tests/data/elliptic_integrals.jsonl  phi, m, m1, F, E, D = (F - E)/m, K, Ec (complete)

Usage: python3 scripts/references/gen_elliptic_fixtures.py   (from the repository root; needs mpmath)
"""
import json
import os

import mpmath as mp

mp.mp.dps = 80
HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "..", "crates", "rod-ig-core", "tests", "data")


def params():
    """(m, m1) pairs as f64 plus which one is exact."""
    out = []
    for m1 in [1e-25, 1e-20, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.5]:
        out.append((1.0 - m1, m1, mp.mpf(1) - mp.mpf(m1), "m1"))
    for m in [1e-30, 1e-16, 1e-10, 1e-4, 0.3, 0.7, 0.9]:
        out.append((m, 1.0 - m, mp.mpf(m), "m"))
    out.append((0.0, 1.0, mp.mpf(0), "m"))
    return out


def am_of(u, m, sn, cn, K):
    base = mp.atan2(sn, cn)
    approx = mp.pi * u / (2 * K)
    k = mp.nint((approx - base) / (2 * mp.pi))
    return base + 2 * mp.pi * k


def main():
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "elliptic_jacobi.jsonl"), "w") as f:
        for (mf, m1f, m, exact) in params():
            K = mp.ellipk(m)
            for u in [-31.0, -7.3, -1.1, -0.2, 0.0, 1e-8, 0.37, 1.0, 1.7, 3.3, 9.9, 24.0, 40.0]:
                uu = mp.mpf(u)
                sn = mp.ellipfun("sn", uu, m=m)
                cn = mp.ellipfun("cn", uu, m=m)
                dn = mp.ellipfun("dn", uu, m=m)
                am = am_of(uu, m, sn, cn, K)
                e_am = mp.ellipe(am, m)
                rec = dict(u=u, m=mf, m1=m1f, exact=exact, sn=float(sn), cn=float(cn),
                           dn=float(dn), am=float(am), e_am=float(e_am))
                f.write(json.dumps(rec) + "\n")
    with open(os.path.join(OUT, "elliptic_integrals.jsonl"), "w") as f:
        for (mf, m1f, m, exact) in params():
            K = mp.ellipk(m)
            Ec = mp.ellipe(m)
            for phi in [-7.0, -2.0, -1.5, -0.4, 0.0, 1e-6, 0.3, 1.0, 1.5, 1.5707, 2.9, 4.0, 11.0]:
                p = mp.mpf(phi)
                if m == 1 and abs(p) >= mp.pi / 2:
                    continue
                F = mp.ellipf(p, m)
                E = mp.ellipe(p, m)
                if m == 0:
                    # D(phi|0) = integral of sin^2 = phi/2 - sin(2 phi)/4
                    D = p / 2 - mp.sin(2 * p) / 4
                else:
                    D = (F - E) / m
                rec = dict(phi=phi, m=mf, m1=m1f, exact=exact, F=float(F), E=float(E),
                           D=float(D), K=float(K), Ec=float(Ec))
                f.write(json.dumps(rec) + "\n")


if __name__ == "__main__":
    main()
