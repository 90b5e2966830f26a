//! Stability of the 3-D rod (Bretl & McCarthy 2014; rule of docs/math.md §10): the equilibrium
//! is stable iff det J(t, a) > 0 at every t = i/2000 in [0.02, 1]. Straight rods
//! (a2 = a3 = a5 = a6 = 0) have det ≡ 0 and are classified unstable. For planar rods — the
//! planar subset a1 = a2 = a6 = 0, or any rotation of it about the base tangent (a1 = 0 and
//! (a2, a3) ⊥ (a5, a6), to 1e-12 relative) — J is block-diagonal in the rotated frame and both
//! 3×3 blocks (in-plane and out-of-plane) must have det > 0 (docs/math.md §10, trap 3: simultaneous
//! crossings of the two blocks cancel in det).
//!
//! Fast scan: det is evaluated (dense output) on a coarse sub-grid of the rule's grid (every
//! `coarse_stride`-th point, plus every step end); where it is ≤ 0 the rule's grid points since
//! the last positive sample are checked one by one, and the first failing one is refined to
//! the crossing by bisection on the dense output. With `coarse_stride = 1` this is exactly the
//! full-grid rule. With `coarse_stride = 0` (used on the solver's intermediate iterates) only
//! the step ends are tested, without dense output or refinement: a non-positive det at a step
//! end ≥ 0.02 counts as unstable (conservative: it may reject a rod whose det dips below zero
//! only between grid points).

use super::reduced::{self, jac as jac_of, pose as pose_of, ENERGY, NR as NV};
use super::{check_params, options_for, Evaluation3d, SpatialParams, Stiffness};
use crate::conjugate::Stream;
use crate::ode::{DenseStep, Dop853};
use crate::{RodError, StabilityReport};

/// Start of the scanned range (docs/math.md §10, trap 2: atol 1e-16 cannot resolve det below 0.01).
pub const STABILITY_T_MIN: f64 = crate::STABILITY_T_MIN;
/// Number of intervals of the rule's grid on [0, 1].
pub const GRID_N: u32 = 2000;
/// Smallest t entering the normalised margin ([`crate::STABILITY_MARGIN_T_MIN`]).
pub const MARGIN_T_MIN: f64 = crate::STABILITY_MARGIN_T_MIN;
const GRID_START: u32 = 40; // 0.02 · 2000

/// Integration and scan settings of the stability test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StabilityOptions {
    /// Relative tolerance of the integration.
    pub rtol: f64,
    /// Absolute tolerance (docs/math.md §10, trap 1: 1e-16, not 1e-30).
    pub atol: f64,
    /// Coarse sampling stride in grid points (1 = every i/2000; 20 = every 0.01); 0 = step ends
    /// only, no dense output (fast, conservative; module docs).
    pub coarse_stride: u32,
}

impl Default for StabilityOptions {
    /// Reference accuracy: rtol 1e-12, atol 1e-16, coarse stride 20 (every 0.01).
    fn default() -> Self {
        Self {
            rtol: 1e-12,
            atol: 1e-16,
            coarse_stride: 20,
        }
    }
}

impl StabilityOptions {
    /// Solver accuracy: rtol 1e-8, atol 1e-12, coarse stride 40 (every 0.02; identical verdicts
    /// to the full grid on 3000 random rods of the ±5/±30 and ±8/±50 boxes, tests/spatial.rs).
    pub fn production() -> Self {
        Self {
            rtol: 1e-8,
            atol: 1e-12,
            coarse_stride: 40,
        }
    }
    /// The full-grid rule at reference accuracy (stride 1).
    pub fn full_grid() -> Self {
        Self {
            coarse_stride: 1,
            ..Self::default()
        }
    }
}

/// Leading small-t term of det J for c = 1 (docs/math.md §10, fitted):
/// (a2² + a3²) t¹⁴/103680, or (a5² + a6²) t¹⁶/403200 when a2 = a3 = 0.
pub fn det_leading_term(a: &SpatialParams, t: f64) -> f64 {
    let b = a[1] * a[1] + a[2] * a[2];
    if b > 0.0 {
        b * t.powi(14) / 103680.0
    } else {
        (a[4] * a[4] + a[5] * a[5]) * t.powi(16) / 403200.0
    }
}

fn is_straight(a: &SpatialParams) -> bool {
    a[1] == 0.0 && a[2] == 0.0 && a[4] == 0.0 && a[5] == 0.0
}

/// For a planar rod (module docs), the matrix B = diag(Rx(−φ), Rx(−φ)) that maps J(t) to the
/// block-diagonal J of the planar subset, B J Bᵀ; None for a non-planar rod.
fn planar_frame(a: &SpatialParams) -> Option<nalgebra::Matrix6<f64>> {
    let scale = a.amax();
    if !(scale > 0.0) || a[0].abs() > 1e-12 * scale {
        return None;
    }
    let dot = a[1] * a[4] + a[2] * a[5];
    if dot.abs() > 1e-12 * scale * scale {
        return None;
    }
    // The moment lies along Rx(φ) e3 = (0, −sin φ, cos φ); the force in span(e1, Rx(φ) e2).
    let phi = if a[1] != 0.0 || a[2] != 0.0 {
        (-a[1]).atan2(a[2])
    } else {
        a[5].atan2(a[4])
    };
    let (sn, cs) = phi.sin_cos();
    // Rx(−φ) = [[1, 0, 0], [0, cos φ, sin φ], [0, −sin φ, cos φ]]
    let r = nalgebra::Matrix3::new(1.0, 0.0, 0.0, 0.0, cs, sn, 0.0, -sn, cs);
    let mut b = nalgebra::Matrix6::zeros();
    b.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    b.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
    Some(b)
}

fn det3(j: &super::SpatialJacobian, rows: [usize; 3], cols: [usize; 3]) -> f64 {
    let m = nalgebra::Matrix3::from_fn(|r, c| j[(rows[r], cols[c])]);
    m.determinant()
}

/// Determinant of a 6×6 matrix (given as its rows) by Gaussian elimination with partial
/// pivoting, on the stack: each row operation runs over a contiguous array.
#[inline(always)] // into both builds of the scan (crate::simd)
fn det6(mut m: [[f64; 6]; 6]) -> f64 {
    let mut det = 1.0;
    for k in 0..6 {
        // Pivot: the largest entry of column k at or below the diagonal.
        let mut p = k;
        let mut best = m[k][k].abs();
        for (r, row) in m.iter().enumerate().skip(k + 1) {
            let v = row[k].abs();
            if v > best {
                best = v;
                p = r;
            }
        }
        if best == 0.0 || !best.is_finite() {
            return if best == 0.0 { 0.0 } else { f64::NAN };
        }
        if p != k {
            m.swap(k, p);
            det = -det;
        }
        let pivot_row = m[k];
        let piv = pivot_row[k];
        det *= piv;
        for row in m.iter_mut().skip(k + 1) {
            let f = row[k] / piv;
            // All six columns: a fixed-length loop vectorises; the columns ≤ k are not read
            // again.
            for (v, pv) in row.iter_mut().zip(pivot_row) {
                *v -= f * pv;
            }
        }
    }
    det
}

/// (sign function g, full det): g > 0 ⇔ the sample passes the rule.
#[inline(always)] // into both builds of the scan (crate::simd)
fn sample(planar: Option<&nalgebra::Matrix6<f64>>, s: &[f64]) -> (f64, f64) {
    if let Some(b) = planar {
        let j = b * jac_of(s) * b.transpose();
        let din = det3(&j, [2, 3, 4], [2, 3, 4]);
        let dout = det3(&j, [0, 1, 5], [0, 1, 5]);
        (din.min(dout), din * dout)
    } else {
        let m: [[f64; 6]; 6] =
            std::array::from_fn(|r| std::array::from_fn(|c| reduced::jac_entry(s, r, c)));
        let d = det6(m);
        (d, d)
    }
}

/// The 3-D rod's side of the scan: its grid rule (coarse samples, the rule's grid points
/// checked one by one after a non-positive one) and g on the dense output; the crossings and
/// the margin are the crate's one [`Stream`].
struct Scan {
    a: SpatialParams,
    planar: Option<nalgebra::Matrix6<f64>>,
    stride: u32,
    next_coarse: u32,
    /// Last t where the rule held.
    last_pos: f64,
    stream: Stream,
    nonfinite: bool,
}

/// Width to which a crossing is located on the dense output.
const ROOT_TOL: f64 = 1e-10;

impl Scan {
    fn new(a: &SpatialParams, opts: &StabilityOptions) -> Self {
        Self {
            a: *a,
            planar: planar_frame(a),
            stride: opts.coarse_stride.clamp(1, GRID_N),
            next_coarse: GRID_START,
            last_pos: STABILITY_T_MIN - 0.5 / GRID_N as f64,
            stream: Stream::new(),
            nonfinite: false,
        }
    }

    fn grid_t(i: u32) -> f64 {
        i as f64 / GRID_N as f64
    }

    fn failed(&self) -> bool {
        self.stream.first().is_some()
    }

    /// g = det J/D0 for the margin: where the rule fails, its negative magnitude (for a
    /// planar rod both blocks can fail while their product stays positive); NaN where D0 ≤ 0.
    #[inline]
    fn normalised(&self, t: f64, sign: f64, det: f64) -> f64 {
        let lead = det_leading_term(&self.a, t);
        if !(lead > 0.0) {
            f64::NAN
        } else if sign > 0.0 {
            det / lead
        } else {
            -(det / lead).abs()
        }
    }

    /// Checks grid points in (last_pos, t_bad] one by one; the first failing one is located
    /// on the dense output ([`Stream::sample_on`]).
    fn refine(&mut self, d: &DenseStep<NV>, t_bad: f64) {
        let lo_i = ((self.last_pos * GRID_N as f64).floor() as u32 + 1).max(GRID_START);
        let planar = self.planar;
        let sign_at = |t: f64| sample(planar.as_ref(), &d.eval(t)).0;
        let since = self.last_pos.max(STABILITY_T_MIN.min(t_bad));
        let mut i = lo_i;
        while i <= GRID_N {
            let t = Self::grid_t(i);
            if t > t_bad + 1e-15 {
                break;
            }
            let (g, det) = sample(self.planar.as_ref(), &d.eval(t));
            if !g.is_finite() {
                self.nonfinite = true;
                return;
            }
            let normalised = self.normalised(t, g, det);
            let _ = self
                .stream
                .sample_on(&sign_at, since, (t, g, normalised), ROOT_TOL);
            if self.failed() {
                return;
            }
            i += 1;
        }
        // The excursion lies between grid points: the rule still holds.
        self.last_pos = t_bad;
    }

    /// Processes the accepted step (t0, t1] with its dense output.
    #[inline(always)] // into both builds of the scan (crate::simd)
    fn step(&mut self, d: &DenseStep<NV>, t1: f64, y1: &[f64; NV]) {
        if self.failed() || self.nonfinite || t1 < STABILITY_T_MIN {
            return;
        }
        // Coarse grid points inside the step, then the step end.
        loop {
            if self.next_coarse > GRID_N {
                break;
            }
            let t = Self::grid_t(self.next_coarse);
            if t > t1 {
                break;
            }
            self.next_coarse = if self.next_coarse == GRID_N {
                GRID_N + 1
            } else {
                (self.next_coarse + self.stride).min(GRID_N)
            };
            let s = if t == t1 { *y1 } else { d.eval(t) };
            if !self.check(d, t, &s) {
                return;
            }
        }
        if self.last_pos < t1 {
            self.check(d, t1, y1);
        }
    }

    /// Step-end-only variant (no dense output): a non-positive sample is a failure, placed
    /// between the last passing sample and it by interpolation.
    #[inline]
    fn step_end_only(&mut self, t1: f64, y1: &[f64; NV]) {
        if self.failed() || self.nonfinite || t1 < STABILITY_T_MIN {
            return;
        }
        let (g, det) = sample(self.planar.as_ref(), y1);
        if !g.is_finite() {
            self.nonfinite = true;
            return;
        }
        let normalised = self.normalised(t1, g, det);
        let _ = self.stream.sample(t1, g, normalised);
        if g > 0.0 {
            self.last_pos = t1;
        }
    }

    /// Returns false when the scan is over (failure or non-finite).
    #[inline(always)] // into both builds of the scan (crate::simd)
    fn check(&mut self, d: &DenseStep<NV>, t: f64, s: &[f64; NV]) -> bool {
        let (g, det) = sample(self.planar.as_ref(), s);
        if !g.is_finite() {
            self.nonfinite = true;
            return false;
        }
        if g > 0.0 {
            let normalised = self.normalised(t, g, det);
            let _ = self.stream.sample(t, g, normalised);
            self.last_pos = t;
            true
        } else {
            self.refine(d, t);
            !self.failed() && !self.nonfinite
        }
    }

    fn report(&self) -> StabilityReport {
        self.stream.exact_report()
    }
}

/// Integrates rod + variational equations once with dense output, scanning det J on the way.
/// With `early_exit`, stops as soon as the verdict is "unstable" (final state then None).
fn run(
    a: &SpatialParams,
    k: &Stiffness,
    opts: &StabilityOptions,
    early_exit: bool,
) -> Result<(Option<[f64; NV]>, StabilityReport), RodError> {
    check_params(a, k)?;
    if !(opts.rtol.is_finite() && opts.rtol > 0.0 && opts.atol.is_finite() && opts.atol >= 0.0) {
        return Err(RodError::OutOfDomain("invalid stability tolerances".into()));
    }
    let ci = [1.0 / k.c1, 1.0 / k.c2, 1.0 / k.c3];
    let ap = reduced::params(a);
    let straight = is_straight(a);
    if straight && early_exit {
        return Ok((None, crate::conjugate::undecided()));
    }
    let options = options_for(a, opts.rtol, opts.atol);
    let dense = !straight && opts.coarse_stride != 0;
    let mut scan = Scan::new(a, opts);
    let integration = Integration {
        ci,
        a: ap,
        options,
        dense,
        straight,
        early_exit,
    };
    let y = crate::simd::pick_build!(scan_avx2, scan_baseline, &integration, &mut scan)?;
    let Some(y) = y else {
        return Ok((None, scan.report()));
    };
    if y.iter().any(|v| !v.is_finite()) {
        return Err(RodError::Overflow("non-finite rod state".into()));
    }
    let report = if straight {
        crate::conjugate::undecided()
    } else {
        scan.report()
    };
    Ok((Some(y), report))
}

/// What [`run`] integrates: the rod's stiffness inverses and parameters, and how.
struct Integration {
    ci: [f64; 3],
    a: [f64; 6],
    options: crate::ode::OdeOptions,
    dense: bool,
    straight: bool,
    early_exit: bool,
}

/// [`integrate_scanning`] as the crate is built.
fn scan_baseline(
    integration: &Integration,
    scan: &mut Scan,
) -> Result<Option<[f64; NV]>, RodError> {
    let mut f = |_: f64, s: &[f64; NV], ds: &mut [f64; NV]| {
        reduced::rhs::<NV, true>(&integration.ci, &integration.a, s, ds)
    };
    integrate_scanning(&mut f, integration, scan)
}

/// [`integrate_scanning`] compiled for AVX2 ([`crate::simd`]); the closure is written here so
/// that it inherits the feature.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn scan_avx2(integration: &Integration, scan: &mut Scan) -> Result<Option<[f64; NV]>, RodError> {
    let mut f = |_: f64, s: &[f64; NV], ds: &mut [f64; NV]| {
        reduced::rhs::<NV, true>(&integration.ci, &integration.a, s, ds)
    };
    integrate_scanning(&mut f, integration, scan)
}

/// The integration of [`run`] with the scan of each accepted step: the final state, or None
/// when the scan stopped early on an unstable verdict. Inlined into both builds.
#[inline(always)]
fn integrate_scanning<F>(
    f: &mut F,
    integration: &Integration,
    scan: &mut Scan,
) -> Result<Option<[f64; NV]>, RodError>
where
    F: FnMut(f64, &[f64; NV], &mut [f64; NV]),
{
    let (dense, straight, early_exit) = (
        integration.dense,
        integration.straight,
        integration.early_exit,
    );
    let mut st = Dop853::new(
        f,
        0.0,
        reduced::initial::<NV>(),
        1.0,
        &integration.options,
        dense,
    )?;
    while !st.finished() {
        st.step(f)?;
        if !straight {
            let t1 = st.t();
            let y1 = *st.y();
            match st.dense() {
                Some(d) => scan.step(d, t1, &y1),
                None => scan.step_end_only(t1, &y1),
            }
            if scan.nonfinite {
                return Err(RodError::Overflow("non-finite Jacobian".into()));
            }
            if early_exit && scan.failed() {
                return Ok(None);
            }
        }
    }
    Ok(Some(*st.y()))
}

/// Stability verdict by the docs/math.md §10 rule, fast scan at reference accuracy
/// ([`StabilityOptions::default`]: rtol 1e-12, atol 1e-16, coarse stride 0.01 with refinement).
/// The margin is min over scanned t ≥ 0.05 of det J(t) / leading term ([`det_leading_term`];
/// a weak margin, docs/math.md §10), ≤ 0 when unstable.
pub fn stability(a: &SpatialParams, k: &Stiffness) -> Result<StabilityReport, RodError> {
    stability_with(a, k, &StabilityOptions::default())
}

/// Stability verdict with explicit options; stops integrating at the first failure.
pub fn stability_with(
    a: &SpatialParams,
    k: &Stiffness,
    opts: &StabilityOptions,
) -> Result<StabilityReport, RodError> {
    Ok(run(a, k, opts, true)?.1)
}

/// The docs/math.md §10 rule checked at every t = i/2000 in [0.02, 1] (reference; slower).
pub fn stability_full_grid(a: &SpatialParams, k: &Stiffness) -> Result<StabilityReport, RodError> {
    stability_with(a, k, &StabilityOptions::full_grid())
}

/// One integration with the stability scan stopping at the first failure: `Some(evaluation)`
/// when stable, `None` (with the report) when unstable.
pub(crate) fn evaluate_if_stable(
    a: &SpatialParams,
    k: &Stiffness,
    opts: &StabilityOptions,
) -> Result<(Option<Evaluation3d>, StabilityReport), RodError> {
    let (y, stability) = run(a, k, opts, true)?;
    Ok((
        y.map(|y| Evaluation3d {
            tip: pose_of(&y),
            jacobian: jac_of(&y),
            energy: y[ENERGY],
            stability,
            full_accuracy: true,
        }),
        stability,
    ))
}

pub(super) fn evaluate_impl(
    a: &SpatialParams,
    k: &Stiffness,
    opts: &StabilityOptions,
) -> Result<Evaluation3d, RodError> {
    let (y, stability) = run(a, k, opts, false)?;
    let y = y.ok_or_else(|| RodError::Integration("no final state".into()))?;
    Ok(Evaluation3d {
        tip: pose_of(&y),
        jacobian: jac_of(&y),
        energy: y[ENERGY],
        stability,
        full_accuracy: true,
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn det6_matches_nalgebra() {
        let mut x = 0.3f64;
        for _ in 0..200 {
            let m: [[f64; 6]; 6] = std::array::from_fn(|_| {
                std::array::from_fn(|_| {
                    x = (x * 3.7 + 0.13).fract();
                    x - 0.5
                })
            });
            let n = nalgebra::Matrix6::from_fn(|r, c| m[r][c]);
            let (a, b) = (super::det6(m), n.determinant());
            assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "{a} {b}");
        }
        assert_eq!(super::det6([[0.0; 6]; 6]), 0.0);
    }

    /// The AVX2 builds of the integration and of the scan (crate::simd) give the same bits as
    /// the baseline build: the state after forward + J and the whole evaluation (state,
    /// verdict, margin, conjugate point) on 400 rods of the bench's box (|a1..3| ≤ 5,
    /// |a4..6| ≤ 30), a third of them scaled by 1e-6..1, with and without an anisotropic
    /// stiffness.
    #[test]
    fn avx2_build_is_bit_identical() {
        use super::super::{options_for, reduced, SpatialParams};
        use super::{Integration, Scan, StabilityOptions, NV};
        if !crate::simd::has_avx2() {
            eprintln!("this CPU has no AVX2: only the baseline build runs here");
            return;
        }
        let bits = |y: &[f64]| y.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        let mut rng = crate::rng::SplitMix64::new(23);
        let mut unstable = 0;
        for i in 0..400 {
            let scale = if i % 3 == 0 {
                10f64.powf(rng.range(-6.0, 0.0))
            } else {
                1.0
            };
            let a: [f64; 6] = std::array::from_fn(|j| {
                let h = if j < 3 { 5.0 } else { 30.0 };
                scale * rng.range(-h, h)
            });
            let ci = if i % 2 == 0 {
                [1.0; 3]
            } else {
                [0.7, 1.0, 1.3]
            };
            let p = SpatialParams::from(a);
            let opts = options_for(&p, 1e-8, 1e-10);
            let base = reduced::integrate_baseline::<NV, true>(&ci, &a, 1.0, &opts).expect("base");
            // SAFETY: this CPU has AVX2 (checked above).
            let avx = unsafe { reduced::integrate_avx2::<NV, true>(&ci, &a, 1.0, &opts) };
            assert_eq!(bits(&base), bits(&avx.expect("avx2")), "{a:?}");
            let so = StabilityOptions::production();
            let integration = Integration {
                ci,
                a,
                options: options_for(&p, so.rtol, so.atol),
                dense: true,
                straight: false,
                early_exit: false,
            };
            let (mut s1, mut s2) = (Scan::new(&p, &so), Scan::new(&p, &so));
            let y1 = super::scan_baseline(&integration, &mut s1)
                .expect("base")
                .expect("state");
            // SAFETY: as above.
            let y2 = unsafe { super::scan_avx2(&integration, &mut s2) }
                .expect("avx2")
                .expect("state");
            assert_eq!(bits(&y1), bits(&y2), "{a:?}");
            let (r1, r2) = (s1.report(), s2.report());
            assert_eq!(r1.stable, r2.stable, "{a:?}");
            assert_eq!(r1.margin.to_bits(), r2.margin.to_bits(), "{a:?}");
            assert_eq!(
                r1.first_conjugate_t.map(f64::to_bits),
                r2.first_conjugate_t.map(f64::to_bits)
            );
            unstable += usize::from(!r1.stable);
        }
        // Both verdicts occur in the sample (the box is ≈ 70 % stable).
        eprintln!("{unstable} unstable of 400");
        assert!((50..350).contains(&unstable), "{unstable} unstable of 400");
    }
}
