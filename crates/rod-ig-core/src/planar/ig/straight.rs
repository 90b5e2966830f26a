//! Starts for targets near full extension (‖(x, y)‖ → 1), reachable only by nearly straight
//! rods: gently bent ones with little force, and rods under strong tension near the separatrix
//! λ4 = 0, where Υ is so anisotropic that atlas seeds rarely fall in Newton's basin.
//!
//! Small-angle model of the rod equation θ'' = κ' = a4 sin θ − a5 cos θ (docs/math.md §1) about the
//! straight rod: θ'' = T θ − a5 with T = a4, θ(0) = 0, θ'(0) = a3, solved by
//!
//! θ(t) = a3 S(t) − a5 C(t),  S = sinh(kt)/k, C = (cosh(kt) − 1)/k² for T = k² ≥ 0
//! (sin and 1 − cos for T = −k²),
//!
//! two entire functions of T (S = t, C = t²/2 at T = 0), so the model is continuous through
//! the force-free rod. y(1) ≈ ∫θ and θ(1) are linear in (a3, a5): a 2×2 solve per T. The
//! end-shortening 1 − x(1) ≈ ½∫θ² is a quadratic form in (a3, a5) whose coefficients depend on
//! T only; T is chosen so that it matches the target's 1 − x (a scan over a fixed grid of T,
//! whose coefficients are computed once, then regula falsi). Each root gives a start
//! a = (a3, T, a5) that Newton refines. Under tension beyond T = 4 the fit is made in the
//! bounded exponentials e^{k(t−1)}, e^{−kt} (`Basis::fit_exponential`): sinh and cosh would
//! cancel terms of size e^{2k}.

use crate::planar::small_angle;

use crate::{wrap_angle, PlanarParams, PlanarPose};
use std::sync::OnceLock;

/// The T-dependent coefficients of the model: values at t = 1 and integrals over [0, 1]; under
/// tension beyond [`SERIES_BELOW`], k = √T and e^{−k} for the bounded exponential form (see
/// [`Basis::fit`]).
#[derive(Clone, Copy, Debug)]
struct Basis {
    t: f64,
    /// (k, e^{−k}) where the fit uses the bounded exponentials (tension, T > SERIES_BELOW).
    exponential: Option<(f64, f64)>,
    s1: f64,
    c1: f64,
    int_s: f64,
    int_c: f64,
    int_ss: f64,
    int_sc: f64,
    int_cc: f64,
}

/// Beyond this tension the fit works in bounded exponentials ([`Basis::fit_exponential`]): in
/// sinh/cosh it cancels terms of size e^{2k}.
const SERIES_BELOW: f64 = 4.0;

impl Basis {
    /// The coefficients at T = `t` (the straight rod's functions of [`small_angle`]).
    fn at(t: f64) -> Basis {
        if t > SERIES_BELOW {
            // sinh and cosh grow like e^k while the answer is O(1): the fit works in bounded
            // exponentials instead, and these coefficients are not used.
            let k = t.sqrt();
            return Basis {
                t,
                exponential: Some((k, (-k).exp())),
                s1: f64::NAN,
                c1: f64::NAN,
                int_s: f64::NAN,
                int_c: f64::NAN,
                int_ss: f64::NAN,
                int_sc: f64::NAN,
                int_cc: f64::NAN,
            };
        }
        // S = S1, C = S2 = ∫S, ∫C = S3 and the Iij of the small-angle expansion, at t = 1.
        let [s1, s2, s3, i11, i12, i22] = small_angle::straight_functions(t, 1.0);
        Basis {
            t,
            exponential: None,
            s1,
            c1: s2,
            int_s: s2,
            int_c: s3,
            int_ss: i11,
            int_sc: i12,
            int_cc: i22,
        }
    }

    /// (a3, a5) meeting y(1) = y, θ(1) = th, and the model's mismatch ½∫θ² − deficit.
    fn fit(&self, y: f64, th: f64, deficit: f64) -> Option<(f64, f64, f64)> {
        if let Some((k, e)) = self.exponential {
            return Self::fit_exponential(self.t, k, e, y, th, deficit);
        }
        // [∫S  −∫C] [a3]   [y ]
        // [S1  −C1] [a5] = [th]
        let det = -self.int_s * self.c1 + self.int_c * self.s1;
        if !(det.is_finite() && det.abs() > 1e-300) {
            return None;
        }
        let a3 = (-y * self.c1 + self.int_c * th) / det;
        let a5 = (self.int_s * th - self.s1 * y) / det;
        let half =
            0.5 * (a3 * a3 * self.int_ss - 2.0 * a3 * a5 * self.int_sc + a5 * a5 * self.int_cc);
        let g = half - deficit;
        (g.is_finite() && a3.is_finite() && a5.is_finite()).then_some((a3, a5, g))
    }
}

impl Basis {
    /// [`Basis::fit`] under tension T = k² in the bounded form θ = c + P e^{k(t−1)} + Q e^{−kt}
    /// (c = a5/T): the conditions θ(0) = 0, θ(1) = th, ∫θ = y are a well-conditioned 3×3 system
    /// for every k ≥ 2, where the sinh/cosh form cancels terms of size e^{2k} down to O(1)
    /// (spurious roots from rounding were found at k ≈ 18-38 before). Then a3 = θ'(0) and
    /// ½∫θ² = ½[c² + 2c(P + Q)(1 − e)/k + (P² + Q²)(1 − e²)/(2k) + 2PQ e], e = e^{−k}.
    fn fit_exponential(
        t: f64,
        k: f64,
        e: f64,
        y: f64,
        th: f64,
        deficit: f64,
    ) -> Option<(f64, f64, f64)> {
        let w = (1.0 - e) / k; // ∫e^{k(t−1)} = ∫e^{−kt}
                               // Rows: θ(0) = 0, θ(1) = th, ∫θ = y; unknowns (c, P, Q).
        let m = nalgebra::Matrix3::new(1.0, e, 1.0, 1.0, 1.0, e, 1.0, w, w);
        let sol = m.lu().solve(&nalgebra::Vector3::new(0.0, th, y))?;
        let (c, p, q) = (sol[0], sol[1], sol[2]);
        let a3 = k * (p * e - q);
        let a5 = c * t;
        let half = 0.5
            * (c * c
                + 2.0 * c * (p + q) * w
                + (p * p + q * q) * (1.0 - e * e) / (2.0 * k)
                + 2.0 * p * q * e);
        let g = half - deficit;
        (g.is_finite() && a3.is_finite() && a5.is_finite()).then_some((a3, a5, g))
    }
}

/// Smallest |T| of the log-spaced grid on each side of T = 0 (which is a grid point itself).
const T_SMALL: f64 = 1e-3;
/// Most compression: just below the clamped–clamped Euler load 4π² (beyond it the straight
/// rod is unstable, and the 2×2 system turns singular at (2π)²).
const T_COMPRESSION: f64 = -(0.999 * std::f64::consts::TAU) * (0.999 * std::f64::consts::TAU);
/// Most tension: k = 100 (boundary layers of width 0.01; beyond, the strong-tension starts of
/// [`super::fronts`] take over).
const T_TENSION: f64 = 1e4;
/// Grid points per decade of |T|.
const PER_DECADE: f64 = 6.0;

/// The scan grid, most compressed first, with its coefficients (target-independent: once).
fn grid() -> &'static [Basis] {
    static GRID: OnceLock<Vec<Basis>> = OnceLock::new();
    GRID.get_or_init(|| {
        let side = |hi: f64| -> Vec<f64> {
            let n = ((hi / T_SMALL).log10() * PER_DECADE).ceil() as usize;
            (0..=n)
                .map(|i| T_SMALL * (hi / T_SMALL).powf(i as f64 / n as f64))
                .collect()
        };
        let mut ts: Vec<f64> = side(-T_COMPRESSION).into_iter().rev().map(|t| -t).collect();
        ts.push(0.0);
        ts.extend(side(T_TENSION));
        ts.into_iter().map(Basis::at).collect()
    })
}

/// The root's accuracy: far below the model's own error (it drops terms O(θ²) relative to the
/// shortening), so Newton from the start needs no more steps than from the exact model root.
const ROOT_G_TOL: f64 = 1e-9;
/// The root's accuracy in T (relative to 1 + |T|).
const ROOT_T_TOL: f64 = 1e-9;

/// Regula falsi (Illinois) for the mismatch's root between two grid points of opposite sign.
fn root(lo: (f64, f64), hi: (f64, f64), y: f64, th: f64, deficit: f64) -> Option<PlanarParams> {
    let ((mut t0, mut g0), (mut t1, mut g1)) = (lo, hi);
    let mut best = None;
    let mut side = 0;
    for _ in 0..60 {
        let t = (t0 * g1 - t1 * g0) / (g1 - g0);
        let t = if t.is_finite() && t > t0.min(t1) && t < t0.max(t1) {
            t
        } else {
            0.5 * (t0 + t1)
        };
        let (a3, a5, g) = Basis::at(t).fit(y, th, deficit)?;
        best = Some(PlanarParams::new(a3, t, a5));
        if g == 0.0
            || (t1 - t0).abs() <= ROOT_T_TOL * (1.0 + t.abs())
            || g.abs() <= ROOT_G_TOL * deficit
        {
            break;
        }
        if (g < 0.0) == (g0 < 0.0) {
            t0 = t;
            g0 = g;
            if side == -1 {
                g1 *= 0.5;
            }
            side = -1;
        } else {
            t1 = t;
            g1 = g;
            if side == 1 {
                g0 *= 0.5;
            }
            side = 1;
        }
    }
    best.filter(|a| a.iter().all(|v| v.is_finite()))
}

/// The small-angle starts of a target, computed one at a time (each root costs a regula falsi,
/// and most solves need only the first).
pub(crate) struct Roots {
    y: f64,
    th: f64,
    deficit: f64,
    /// Sign-change brackets on the grid, nearest T = 0 last (served by `pop`).
    brackets: Vec<((f64, f64), (f64, f64))>,
}

impl Iterator for Roots {
    type Item = PlanarParams;
    fn next(&mut self) -> Option<PlanarParams> {
        while let Some((lo, hi)) = self.brackets.pop() {
            if let Some(a) = root(lo, hi, self.y, self.th, self.deficit) {
                return Some(a);
            }
        }
        None
    }
}

/// The starts for a target near full extension (distance in (0.9, 1), x > 0, tip angle below
/// 1.2 rad), smallest |a4| first (the gently bent rod before the tensioned or compressed ones);
/// none elsewhere.
pub(crate) fn roots(target: &PlanarPose) -> Roots {
    let r = target.x.hypot(target.y);
    let th = wrap_angle(target.theta);
    let (y, deficit) = (target.y, 1.0 - target.x);
    let mut roots = Roots {
        y,
        th,
        deficit,
        brackets: Vec::new(),
    };
    if !(r > 0.9 && r < 1.0 && target.x > 0.0 && th.abs() < 1.2) {
        return roots;
    }
    // Brackets of the mismatch's sign changes on the grid (cheap: the grid's coefficients are
    // precomputed).
    let mut prev: Option<(f64, f64)> = None;
    for b in grid() {
        let Some((_, _, g)) = b.fit(y, th, deficit) else {
            prev = None;
            continue;
        };
        if let Some((t0, g0)) = prev {
            if (g0 <= 0.0) != (g <= 0.0) {
                roots.brackets.push(((t0, g0), (b.t, g)));
            }
        }
        prev = Some((b.t, g));
    }
    let nearest_zero = |((t0, _), (t1, _)): &((f64, f64), (f64, f64))| {
        if t0 * t1 <= 0.0 {
            0.0
        } else {
            t0.abs().min(t1.abs())
        }
    };
    roots
        .brackets
        .sort_by(|p, q| nearest_zero(q).total_cmp(&nearest_zero(p)));
    roots
}

/// Up to `max` of [`roots`].
#[cfg(test)]
pub(crate) fn starts(target: &PlanarPose, max: usize) -> Vec<PlanarParams> {
    roots(target).take(max).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_tensioned_and_compressed_rods() {
        // Nearly straight rods: strong tension (hypersensitive, near the separatrix) and
        // moderate compression.
        for a in [
            PlanarParams::new(0.21379433849032559, 73.60275354814638, 1.8243287658602725),
            PlanarParams::new(0.1, -5.0, 0.1),
            PlanarParams::new(0.3, -20.0, 1.0),
        ] {
            let b = crate::planar::entry::tip(&a).unwrap();
            let s = starts(&b, 4);
            // One start within ~25 % of a (small-angle model).
            assert!(
                s.iter().any(|g| (g - a).norm() < 0.25 * a.norm()),
                "{a:?}: {s:?}"
            );
        }
    }

    #[test]
    fn series_and_closed_forms_agree_where_they_meet() {
        // At T = −SERIES_BELOW the two evaluations of every coefficient agree to ~1e-13
        // relative (the closed forms' cancellation at k = 2 costs ~1.5 digits of 1e-16).
        for t in [-SERIES_BELOW] {
            let s = Basis::at(t);
            let c = Basis::at(t * (1.0 + f64::EPSILON));
            let pairs = [
                (s.s1, c.s1),
                (s.c1, c.c1),
                (s.int_s, c.int_s),
                (s.int_c, c.int_c),
                (s.int_ss, c.int_ss),
                (s.int_sc, c.int_sc),
                (s.int_cc, c.int_cc),
            ];
            for (i, (u, v)) in pairs.into_iter().enumerate() {
                assert!(
                    (u - v).abs() <= 1e-12 * u.abs(),
                    "T = {t}, coefficient {i}: {u} vs {v}"
                );
            }
        }
        // At T = +SERIES_BELOW the series and the bounded exponential form give the same fit.
        for (y, th, deficit) in [(0.01, 0.02, 1e-4), (-0.3, 0.5, 0.1), (1e-6, -3e-6, 1e-12)] {
            let s = Basis::at(SERIES_BELOW).fit(y, th, deficit).unwrap();
            let e = Basis::at(SERIES_BELOW * (1.0 + f64::EPSILON))
                .fit(y, th, deficit)
                .unwrap();
            let half = |f: (f64, f64, f64)| f.2 + deficit;
            assert!((s.0 - e.0).abs() <= 1e-12 * s.0.abs(), "a3 {s:?} vs {e:?}");
            assert!((s.1 - e.1).abs() <= 1e-12 * s.1.abs(), "a5 {s:?} vs {e:?}");
            assert!(
                (half(s) - half(e)).abs() <= 1e-12 * half(s),
                "½∫θ² {s:?} vs {e:?}"
            );
        }
        // T = 0: S = t, C = t²/2.
        let z = Basis::at(0.0);
        let expected = [1.0, 0.5, 0.5, 1.0 / 6.0, 1.0 / 3.0, 0.125, 0.05];
        let got = [z.s1, z.c1, z.int_s, z.int_c, z.int_ss, z.int_sc, z.int_cc];
        for (e, g) in expected.into_iter().zip(got) {
            assert!((e - g).abs() < 1e-16, "{e} vs {g}");
        }
    }

    #[test]
    fn no_spurious_roots_under_strong_tension() {
        // The sinh/cosh form of the fit cancelled terms of size e^{2k} and produced sign
        // changes from rounding at k ≈ 18-38 (three bogus starts per gently bent target).
        // The shortening of the model grows with T at fixed (y, θ) there: no root.
        for a in [
            PlanarParams::new(-1.07e-4, 2.8e-8, 1.2e-9),
            PlanarParams::new(1e-3, -1.5e-3, -4e-3),
            PlanarParams::new(0.05, 0.3, -0.02),
            PlanarParams::new(0.1, -5.0, 0.1),
        ] {
            let b = crate::planar::entry::tip(&a).unwrap();
            let s = starts(&b, 8);
            assert!(s.iter().all(|g| g[1] < 100.0), "{a:?}: {s:?}");
        }
    }

    #[test]
    fn gently_bent_rods_through_zero_force() {
        // Little or no force, either sign (the force-free rod is inside the scan, not at its
        // edge): the first start is the rod itself to the model's accuracy (it drops terms
        // O(θ) relative to those it keeps: 1.5 % in (a3, a5) at θ ≈ 0.05, the last rod), so
        // |Δa4| is small in absolute terms and (a3, a5) match to a few θ relative.
        for a in [
            PlanarParams::new(-1.07e-4, 2.8e-8, 1.2e-9),
            PlanarParams::new(1e-3, -1.5e-3, -4e-3),
            PlanarParams::new(2e-3, 0.0, 0.0),
            PlanarParams::new(0.0, 0.0, 1e-2),
            PlanarParams::new(0.05, 0.3, -0.02),
        ] {
            let b = crate::planar::entry::tip(&a).unwrap();
            let s = starts(&b, 4);
            let g = s.first().unwrap_or_else(|| panic!("{a:?}: no start"));
            assert!((g[1] - a[1]).abs() < 0.05, "{a:?}: {g:?}");
            let bend = a[0].abs() + a[2].abs();
            assert!(
                (g[0] - a[0]).abs() + (g[2] - a[2]).abs() < (1e-3 + 0.5 * bend) * bend,
                "{a:?}: {g:?}"
            );
        }
    }
}
