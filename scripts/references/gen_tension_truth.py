#!/usr/bin/env python3
"""Reference answers for barely bent planar rods under strong tension (issue 42, item 2).

The planar rod obeys θ'' = a4 sin θ − a5 cos θ (docs/math.md §1). Under tension (a4 > 0) write
R = √(a4² + a5²), φ = atan2(a5, a4) and ψ = θ − φ: ψ'' = R sin ψ, a pendulum about its
*unstable* equilibrium ψ = 0, with ψ(0) = −φ, ψ'(0) = a3. Its first integral
ψ'² = h + 4R sin²(ψ/2), h = a3² − 4R sin²(φ/2), gives it exactly in Jacobi functions:

* h > 0 (rotation): ω = √(h + 4R), m = 4R/ω² (m1 = h/ω², passed exactly), ψ = 2 am(u|m) + π,
  u = ωt/2 + F(ψ0/2 − π/2 | m); x_ψ = (2/ω)[2(u − E(am u))/m − u], y_ψ = (2/ω)[2 dn u/m]
  between the ends (∫ sn² = (u − E)/m, ∫ sn cn = −dn/m);
* h < 0 (libration about ψ = π): m' = 1 + h/(4R) (m1' = −h/(4R)), ψ = π + 2β,
  sin β = √m' sn(v|m'), v = √R t + v0; x_ψ = [v − 2E(am v)]/√R, y_ψ = [2√m' cn v]/√R;
* the pose is (x, y) = Rot(φ)(x_ψ, y_ψ), θ = ψ(t) − ψ(0), the elastic energy ½∫ψ'².

Each is evaluated with mpmath at `--dps` digits (m1 down to 1e-600 needs more digits than that
exponent) and J by central differences at a relative step of 1e-40 (error ~1e-80). Cross-checked
below against an mpmath Taylor integration of the ODE on moderate rods.

Writes JSON lines {"a": [a3, a4, a5], "tip": [x, y, θ], "jacobian": [[...] x3], "energy": E}.
"""
import argparse
import json
import multiprocessing
import random

import mpmath as mp


def _am(u, m, K):
    """Continuous amplitude am(u|m) (am(u + 2K) = am(u) + π)."""
    n = mp.floor((u + K) / (2 * K))
    r = u - 2 * K * n
    return mp.atan2(mp.ellipfun("sn", r, m), mp.ellipfun("cn", r, m)) + mp.pi * n


def pendulum_tip(a3, a4, a5):
    """(x, y, θ, energy) at t = 1 of the rod a = (a3, a4, a5), a4 > 0."""
    a3, a4, a5 = mp.mpf(a3), mp.mpf(a4), mp.mpf(a5)
    R = mp.sqrt(a4 * a4 + a5 * a5)
    phi = mp.atan2(a5, a4)
    psi0 = -phi
    h = a3 * a3 - 4 * R * mp.sin(phi / 2) ** 2
    if h > 0:
        w = mp.sqrt(h + 4 * R)
        m = 4 * R / (w * w)
        K = mp.ellipk(m)
        s = 1 if a3 > 0 else -1
        # The rod turning clockwise (a3 < 0) is the mirror image of ψ → −ψ.
        q0 = s * psi0
        chi0 = q0 / 2 - mp.pi / 2
        u0 = mp.ellipf(chi0, m)
        u1 = u0 + w / 2
        chi1 = _am(u1, m, K)
        e0, e1 = mp.ellipe(chi0, m), mp.ellipe(chi1, m)
        xq = (2 / w) * (2 * ((u1 - e1) - (u0 - e0)) / m - (u1 - u0))
        yq = (2 / w) * 2 * (mp.ellipfun("dn", u1, m) - mp.ellipfun("dn", u0, m)) / m
        q1 = 2 * chi1 + mp.pi
        energy = w * (e1 - e0)
        xp, yp, psi1 = xq, s * yq, s * q1
    else:
        mq = 1 + h / (4 * R)
        rr = mp.sqrt(R)
        K = mp.ellipk(mq)
        q0 = mp.fmod(psi0, 2 * mp.pi)
        if q0 <= 0:
            q0 += 2 * mp.pi
        beta0 = (q0 - mp.pi) / 2
        sn0 = mp.sin(beta0) / mp.sqrt(mq)
        sn0 = max(min(sn0, mp.mpf(1)), mp.mpf(-1))
        cn0 = mp.sqrt(1 - sn0 * sn0) * (1 if a3 >= 0 else -1)
        am0 = mp.atan2(sn0, cn0)
        v0 = mp.ellipf(am0, mq)
        v1 = v0 + rr
        am1 = _am(v1, mq, K)
        xp = ((v1 - 2 * mp.ellipe(am1, mq)) - (v0 - 2 * mp.ellipe(am0, mq))) / rr
        yp = 2 * mp.sqrt(mq) * (mp.ellipfun("cn", v1, mq) - cn0) / rr
        beta1 = mp.asin(mp.sqrt(mq) * mp.ellipfun("sn", v1, mq))
        psi1 = mp.pi + 2 * beta1 - q0 + psi0
        # ½∫ψ'² = ½∫4R m' cn² dv/√R = 2√R(E(am v) − m1' v) between the ends.
        m1q = -h / (4 * R)
        energy = 2 * rr * ((mp.ellipe(am1, mq) - m1q * v1) - (mp.ellipe(am0, mq) - m1q * v0))
    c, sn = mp.cos(phi), mp.sin(phi)
    return (c * xp - sn * yp, sn * xp + c * yp, psi1 - psi0, energy)


def digits_needed(a):
    """Working digits for rod a: mpmath's elliptic functions lose about log10(1/m1) digits as
    m → 1, and a difference quotient at a relative step of 1e-40 on entries as small as
    |a3|·‖J‖ needs 1e-50·|a3| of what is left (the 1e-6 asked of J, with room)."""
    a3, a4, a5 = (abs(float(v)) for v in a)
    r = (a4 * a4 + a5 * a5) ** 0.5
    # The smallest nonzero bending term: in libration (a5²/R > a3²) the start's sn φ differs
    # from ±1 by a3²/(8R), which must be resolved too.
    terms = [v for v in (a3, a5 / r ** 0.5) if v > 0] or [1e-320]
    tiny = max(min(terms), 1e-320)
    lost = max(0.0, -2 * mp.log10(tiny) + mp.log10(4 * r))
    # The energy and 1 − x are O(tiny²) differences of O(1) elliptic terms: as many digits
    # again (without them an energy of 1e-179 came out 1e-6 off, issue 53).
    return int(80 + 2 * lost + max(0.0, -mp.log10(tiny)))


def reference(a):
    """Tip, J (central differences) and energy of rod a, at the digits it needs."""
    with mp.workdps(max(mp.mp.dps, digits_needed(a))):
        return _reference(a)


def _reference(a):
    x, y, th, e = pendulum_tip(*a)
    jac = [[None] * 3 for _ in range(3)]
    for j in range(3):
        step = mp.mpf(10) ** -40 * max(abs(mp.mpf(a[j])), mp.mpf(10) ** -320)
        if j == 0:
            # The a3 column at a3 = 0: a step on the bending's own scale |a5|/√a4 (a step of
            # 1e-360 is below the digits that resolve the base's curvature).
            root = mp.sqrt(abs(mp.mpf(a[1])))
            step = mp.mpf(10) ** -40 * max(abs(mp.mpf(a[0])), abs(mp.mpf(a[2])) / root,
                                           mp.mpf(10) ** -320)
        if j == 2:
            # The a5 column: a step that keeps h's sign where a5 is small (|δ| ≪ |a3|√a4).
            scale = max(abs(mp.mpf(a[2])), abs(mp.mpf(a[0])) * mp.sqrt(a[1]))
            step = mp.mpf(10) ** -40 * max(scale, mp.mpf(10) ** -320)
        up = list(map(mp.mpf, a))
        dn = list(map(mp.mpf, a))
        up[j] += step
        dn[j] -= step
        pu, pd = pendulum_tip(*up), pendulum_tip(*dn)
        for i in range(3):
            jac[i][j] = (pu[i] - pd[i]) / (2 * step)
    return (x, y, th), jac, e


def ode_check(a, dps=40):
    """The same tip by an mpmath Taylor integration of the ODE (moderate rods only)."""
    with mp.workdps(dps):
        a3, a4, a5 = map(mp.mpf, a)
        f = mp.odefun(lambda t, v: [v[1], a4 * mp.sin(v[0]) - a5 * mp.cos(v[0]),
                                    mp.cos(v[0]), mp.sin(v[0]), v[1] ** 2 / 2],
                      0, [0, a3, 0, 0, 0])
        th, _, x, y, e = f(1)
        return x, y, th, e


def samples(n, seed):
    """Barely bent rods under strong tension: |a3|, |a5| log-uniform down to 1e-300 (or zero),
    √a4 from 1 to 700, signs mixed."""
    rng = random.Random(seed)
    out = []
    for i in range(n):
        root_f = 10 ** rng.uniform(0, mp.log10(700))
        a4 = float(root_f) ** 2
        a3 = 10 ** rng.uniform(-300, -1) * rng.choice([-1, 1])
        kind = i % 4
        a5 = 0.0 if kind < 2 else 10 ** rng.uniform(-300, -1) * rng.choice([-1, 1])
        if kind == 1:
            a3 = float(rng.choice([-1, 1]) * 10 ** rng.uniform(-300, -100))
        out.append([a3, a4, a5])
    return out


def samples_near_straight(n, seed):
    """Rods whose largest bending angle θ(1) ≈ a3 sinh(√a4)/√a4 is log-uniform in
    [1e-7, 1e-2] (the small-angle expansion's edge), √a4 from 1 to 700."""
    rng = random.Random(seed)
    out = []
    for _ in range(n):
        root_f = 10 ** rng.uniform(0, float(mp.log10(700)))
        theta = 10 ** rng.uniform(-7, -2)
        a3 = float(theta * root_f / mp.sinh(root_f)) * rng.choice([-1, 1])
        a5 = 0.0 if rng.random() < 0.5 else a3 * root_f * 10 ** rng.uniform(-3, 0) * rng.choice([-1, 1])
        out.append([a3, root_f * root_f, a5])
    return out


def samples_separatrix_limit(n, seed):
    """Issue 53, item 4: a = (c, F, a5) with c log-uniform down to 1e-300 (either sign, or
    exactly 0), √F log-uniform from 1 to 700, a5 = 0 or |a5|/F log-uniform in [1e-300, 1e-8];
    and the two rods the issue found wrong."""
    rng = random.Random(seed)
    out = [[8.850559451519699e-186, 246788.58890306484, 0.0],
           [1.5586680756769043e-199, 490000.0, 0.0]]
    for i in range(n - len(out)):
        root_f = 10 ** rng.uniform(0, float(mp.log10(700)))
        a4 = float(root_f) ** 2
        c = 10 ** rng.uniform(-300, -1) * rng.choice([-1, 1])
        kind = i % 4
        a5 = 0.0
        if kind >= 2:
            a5 = a4 * 10 ** rng.uniform(-300, -8) * rng.choice([-1, 1])
        if kind == 3:
            c = 0.0
        out.append([c, a4, a5])
    return out


def samples_separatrix_limit_edge(n, seed):
    """The separatrix limit's edge: |a3|/√F (and |a5|/F) log-uniform in [1e-9, 1e-7]."""
    rng = random.Random(seed)
    out = []
    for i in range(n):
        rf = 10 ** rng.uniform(0, 2.845)
        c = 10 ** rng.uniform(-9, -7) * rf * rng.choice([-1, 1])
        a5 = 0.0 if i % 2 == 0 else rf * rf * 10 ** rng.uniform(-9, -7) * rng.choice([-1, 1])
        out.append([c, rf * rf, a5])
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=120)
    p.add_argument("--seed", type=int, default=42)
    p.add_argument("--dps", type=int, default=60, help="at least (raised per rod)")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--near-straight", action="store_true",
                   help="rods at the small-angle expansion's edge instead")
    p.add_argument("--separatrix-limit", action="store_true",
                   help="the separatrix limit's rods (issue 53) instead")
    p.add_argument("--separatrix-limit-edge", action="store_true",
                   help="the separatrix limit's edge, rho in [1e-9, 1e-7] (seed 531)")
    p.add_argument("--check", action="store_true", help="cross-check against the ODE and exit")
    p.add_argument("-o", "--output", default="-")
    args = p.parse_args()
    mp.mp.dps = args.dps
    if args.check:
        for a in [[1.0, 1.0, 0.0], [0.5, 100.0, 0.0], [0.5, 100.0, 0.3], [-0.7, 30.0, 2.0],
                  [0.01, 50.0, -3.0], [2.0, 10.0, -0.5]]:
            x, y, th, e = pendulum_tip(*a)
            xo, yo, tho, eo = ode_check(a)
            print(a, mp.nstr(max(abs(x - xo), abs(y - yo), abs(th - tho), abs(e - eo)), 3))
        return
    out = open(args.output, "w") if args.output != "-" else None
    with multiprocessing.Pool(args.jobs) as pool:
        family = samples
        if args.near_straight:
            family = samples_near_straight
        elif args.separatrix_limit:
            family = samples_separatrix_limit
        elif args.separatrix_limit_edge:
            family = samples_separatrix_limit_edge
        rods = family(args.n, args.seed)
        for line in pool.imap(_line, rods):
            print(line, file=out, flush=True) if out else print(line, flush=True)


def _line(a):
    (x, y, th), jac, e = reference(a)
    return json.dumps({
        "a": a,
        "tip": [float(x), float(y), float(th)],
        "jacobian": [[float(v) for v in row] for row in jac],
        "energy": float(e),
    })


if __name__ == "__main__":
    main()
