//! What theory says of a closed-form rod's conjugate points (Sachkov 2008): the span free of
//! them, the verdicts that need no scan, and where det J may dip (inflections, wavelength).

use super::*;

impl<T: Real> Closed<T> {
    /// A t_free such that a theorem rules out any conjugate point on (0, t_free), so that det J
    /// cannot vanish there whatever the rounding of a scan: infinite where there is none at
    /// all, 0 where nothing is known. Sachkov, "Conjugate points in Euler's elastic problem"
    /// (J. Dyn. Control Syst. 14, 2008; arXiv:0705.1003): non-inflectional elasticae (case II
    /// and its small-force limit, κ ∝ dn > 0) and circles have no conjugate point, and on an
    /// inflectional one (case I, κ ∝ cn Γ) the first conjugate point lies after its first
    /// inflection point (Γ = K(2j + 1), t > 0).
    ///
    /// The case must be sure (λ4 far above its rounding, [`THEOREM_MAX_SPREAD`]); the separatrix
    /// (case III, λ4 = 0 as computed) is left to the scan, since a λ4 rounded to zero may hide
    /// an inflectional rod. In case I the inflection is taken [`THEOREM_PHASE_MARGIN`] early for
    /// the rounding of φ and K. A rod starting exactly at an inflection point (a3 = 0) gets the
    /// next one: the conjugate time is continuous in the phase, and for a base just past an
    /// inflection the bound is that next one (checked on the 320-bit references).
    #[inline]
    pub(crate) fn conjugate_free_until(&self) -> f64 {
        let (a3, sign_sure) = (self.a3.re(), self.case_is_sure());
        match self.case {
            Case::II | Case::SmallForce if sign_sure => f64::INFINITY,
            Case::Circle => f64::INFINITY,
            Case::I if sign_sure => {
                let (k, phi, r, margin) = self.phase_and_margin();
                let (below, above) = self.inflections_around_base();
                // a3 = 0: φ is an inflection, rounded to either side of it.
                let next = if a3 == 0.0 && phi - below > margin {
                    above + 2.0 * k
                } else {
                    above
                };
                let t = (next - phi - margin) / r;
                if t.is_finite() {
                    t.max(0.0)
                } else {
                    0.0
                }
            }
            _ => 0.0,
        }
    }

    /// A t_conj such that a theorem places a conjugate point on (0, t_conj]: on an
    /// inflectional rod (case I) the first conjugate point lies between its first and third
    /// inflection points (Sachkov 2008, as [`Self::conjugate_free_until`]). Infinite where
    /// nothing is known. The third inflection after the base is taken [`THEOREM_PHASE_MARGIN`]
    /// late for the rounding of φ and K, and one inflection later where the base lies within
    /// that margin before an inflection (φ rounded to the wrong side of it would miscount by
    /// one; a base exactly at an inflection, a3 = 0, counts the next one as first, the later
    /// of the two counts).
    pub(crate) fn conjugate_by(&self) -> f64 {
        if self.case != Case::I || !self.case_is_sure() {
            return f64::INFINITY;
        }
        let (k, phi, r, margin) = self.phase_and_margin();
        let (_, above) = self.inflections_around_base();
        let later = if above - phi <= margin { 6.0 } else { 4.0 };
        let t = (above + later * k + margin - phi) / r;
        if t.is_finite() {
            t
        } else {
            f64::INFINITY
        }
    }

    /// True when a theorem places a conjugate point on (0, 1] ([`Self::conjugate_by`]): the
    /// rod is unstable.
    pub(crate) fn conjugate_certain(&self) -> bool {
        self.conjugate_by() <= 1.0
    }

    /// The verdict a theorem gives, where one does: stable where no conjugate point can lie
    /// on (0, 1] ([`Self::conjugate_free`]), unstable where one must
    /// ([`Self::conjugate_certain`]).
    pub(crate) fn theorem_verdict(&self) -> Option<crate::StabilityVerdict> {
        if self.conjugate_free() {
            Some(crate::StabilityVerdict::Stable)
        } else if self.conjugate_certain() {
            Some(crate::StabilityVerdict::Unstable)
        } else {
            None
        }
    }

    /// K, φ, r (f64 values) and the margin [`THEOREM_PHASE_MARGIN`]·(|φ| + r + K) by which a
    /// bound on Γ is taken early for their rounding.
    pub(super) fn phase_and_margin(&self) -> (f64, f64, f64, f64) {
        let (k, phi, r) = (self.landen.k().re(), self.phi.re(), self.r.re());
        (k, phi, r, THEOREM_PHASE_MARGIN * (phi.abs() + r + k))
    }

    /// True when λ4's sign, and so the case, is sure: its terms' squares of normal size
    /// (relative rounding) and λ4 far above its rounding ([`THEOREM_MAX_SPREAD`]).
    pub(super) fn case_is_sure(&self) -> bool {
        let (a3, a4, a5) = (self.a3.re(), self.a4.re(), self.a5.re());
        let terms = a5 * a5 + a3 * a3 * (a3 * a3 * 0.25 + a4).abs();
        self.lambda4_spread < THEOREM_MAX_SPREAD && terms >= THEOREM_MIN_TERMS
    }

    /// True when no conjugate point can lie on (0, 1] ([`Self::conjugate_free_until`]).
    pub(crate) fn conjugate_free(&self) -> bool {
        self.conjugate_free_until() > 1.0
    }

    /// A t before which no conjugate point was ever seen: as [`Self::conjugate_free_until`],
    /// but in case I the measured bound Γ-span ≥ 2K whatever the phase (the theorem's first
    /// inflection can come arbitrarily soon after the base). Measured against the DOP853
    /// reference on 40 values of m × 200 phases (the smallest span 2K·(1 + ~0.2/K), tending to
    /// 2K as m → 1 with the base just before an inflection; exactly 4K below m ≈ 0.8) and on
    /// the 320-bit references (≥ 2K·1.0008). Not a theorem: it only tells the scan which signs
    /// of g within their error bound are rounding ([`super::stability`]), never a verdict.
    pub(crate) fn conjugate_span_bound(&self) -> f64 {
        let proven = self.conjugate_free_until();
        if self.case != Case::I || !self.case_is_sure() {
            return proven;
        }
        let (k, _, r, margin) = self.phase_and_margin();
        let t = (2.0 * k - margin) / r;
        if t.is_finite() {
            proven.max(t)
        } else {
            proven
        }
    }

    /// The t ∈ (0, 1) where Γ = K(2j + 1) (cases I and II; at most [`MAX_DIP_TIMES`], from the base): the
    /// inflection points (κ ∝ cn) or the straightest points between loops (κ ∝ dn), where
    /// they are needed: where a scan of this `spacing` in t samples Γ more coarsely than 1.
    /// Near the separatrix g has narrow dips there (width ~1 in Γ, the loops' scale, where the
    /// grid's quarter period is K/2): on 5 reference rods whose scanned margin was 12–74 %
    /// above the reference's, the dense minimum sat within 0.03 K of such a point.
    pub(crate) fn dip_times(&self, spacing: f64) -> DipTimes {
        let mut out = DipTimes::default();
        let (k, phi, r) = (self.landen.k().re(), self.phi.re(), self.r.re());
        if !matches!(self.case, Case::I | Case::II) || r * spacing <= 1.0 {
            return out;
        }
        let (_, mut gamma) = self.inflections_around_base();
        while out.len < MAX_DIP_TIMES {
            let t = (gamma - phi) / r;
            // NaN ends the loop too.
            if t.partial_cmp(&1.0) != Some(std::cmp::Ordering::Less) {
                break;
            }
            out.times[out.len] = t;
            out.len += 1;
            gamma += 2.0 * k;
        }
        out
    }

    /// Γ of the last point Γ = K(2j + 1) (case I: an inflection, cn Γ = 0) at or below the
    /// base's φ, and of the next one above it.
    pub(super) fn inflections_around_base(&self) -> (f64, f64) {
        let (k, phi) = (self.landen.k().re(), self.phi.re());
        let below = k * (2.0 * ((phi - k) / (2.0 * k)).floor() + 1.0);
        (below, below + 2.0 * k)
    }

    /// A length in t over which the shape (and det J) changes appreciably: the half-period
    /// 2K/r of cn in Γ = r t + φ (I), the period 2K/r of dn (II), π/√F (III), π/|a3|
    /// (circle); 1 for the straight rod.
    pub fn wavelength(&self) -> f64 {
        let l = match self.case {
            Case::I | Case::II => 2.0 * self.landen.k().re() / self.r.re(),
            Case::III => std::f64::consts::PI / self.r.re(),
            Case::Circle | Case::SmallForce => std::f64::consts::PI / self.a3.re().abs(),
            Case::Straight => 1.0,
        };
        if l.is_finite() && l > 0.0 {
            l
        } else {
            1.0
        }
    }
}
