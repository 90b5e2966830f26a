//! Taylor-series integration of the planar rod: the better-conditioned formulation where the
//! closed form loses accuracy (nearly straight, gently bent, tiny and strong-axial-force rods).
//!
//! The planar Kirchhoff equations (paper eq. 2.9 with the planar kinematics; docs/math.md §1) are
//! polynomial once the base force is written in the world frame, μ4 = a4 cos θ + a5 sin θ,
//! μ5 = a5 cos θ − a4 sin θ:
//!
//! ```text
//! κ' = −(a5 c − a4 s),  θ' = κ,  c' = −s κ,  s' = c κ,  x' = c,  y' = s,  E' = κ²/2
//! ```
//!
//! with c = cos θ, s = sin θ, κ = μ3 and E the elastic energy ½∫κ². The Taylor coefficients of
//! every series then follow from Cauchy products alone (no cancellation, no transcendental
//! function inside a step), so each coefficient is accurate to a few ulps *relative to itself*:
//! the entries of J(t, a) = ∂q/∂a that are O(|a|²) for a nearly straight rod are computed to full
//! relative accuracy, which the closed form (built from O(1) elliptic quantities) cannot do.
//! Evaluated in [`Dual3`] the same recurrences give J exactly (forward-mode differentiation).
//!
//! Step and order control (error estimate, not tuned thresholds): from t0 the order grows until
//! the last two terms of every series — value and each derivative — at the step h are below
//! `Measured::TAIL_TOL` times that series' largest term; for an entire function this is the standard
//! a-posteriori truncation estimate (Jorba & Zou 2005, §3.2). A gently bent rod is covered by one
//! step from 0 to 1; otherwise h shrinks until the estimate holds at [`MAX_ORDER`]. The scale of
//! every series is kept up to date term by term, so each order's test reads two terms only.

use crate::dd::{Dd, DualDd};
use crate::scalar::Dual3;
use crate::RodError;

use crate::{PlanarJacobian, PlanarParams, PlanarPose};

/// Highest Taylor order per step. The terms decay like (h/R)ᵏ with R the radius of convergence
/// (≳ 3 for gently bent rods: one step to t = 1 in ≲ 32 terms); where R is smaller, shorter
/// steps at this order cost less than more terms (work per step grows like the order squared).
pub(crate) const MAX_ORDER: usize = 32;
const LEN: usize = MAX_ORDER + 1;
/// Lowest order at which convergence is tested: the series of an odd or even function has
/// alternate zero coefficients, so two vanishing terms mean nothing before a few terms.
const MIN_ORDER: usize = 6;
/// Shrink factor of a rejected step (the tail scales like hᴺ: one or two shrinks suffice).
const STEP_SHRINK: f64 = 0.7;
/// Steps smaller than this fraction of the rod mean the rod is beyond what f64 resolves.
const MIN_STEP: f64 = 1e-9;

/// What the recurrences need of a scalar: ring operations, exact division by the small
/// integers k + 1, and the magnitudes used for error control (the value and, for a dual number,
/// each derivative). Implemented by f64, [`Dual3`] (J in the same pass) and [`DualDd`]
/// (ill-conditioned rods).
pub(crate) trait Measured:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Neg<Output = Self>
    + std::ops::AddAssign
{
    /// Number of measured parts (1 for f64, 4 for a dual number).
    const PARTS: usize;
    /// Truncation tolerance relative to each series' own scale: one unit roundoff of the type,
    /// so the truncation error stays below the rounding error of the sum.
    const TAIL_TOL: f64 = f64::EPSILON / 2.0;
    /// A constant.
    fn constant(v: f64) -> Self;
    /// |part i|.
    fn part(self, i: usize) -> f64;
    /// self / n for a small positive integer n (exact to the type's precision).
    fn div_n(self, n: f64) -> Self;
    /// self · h for an f64 step.
    fn mul_f(self, h: f64) -> Self;
    /// The product of the values only, derivatives dropped: the energy series, whose
    /// derivatives nothing reads (a third of the Cauchy products' work in dual numbers).
    #[inline]
    fn mul_values(self, o: Self) -> Self {
        self * o
    }
}

impl Measured for f64 {
    const PARTS: usize = 1;
    #[inline]
    fn constant(v: f64) -> Self {
        v
    }
    #[inline]
    fn part(self, _: usize) -> f64 {
        self.abs()
    }
    #[inline]
    fn div_n(self, n: f64) -> Self {
        self / n
    }
    #[inline]
    fn mul_f(self, h: f64) -> Self {
        self * h
    }
}

impl Measured for Dual3 {
    const PARTS: usize = 4;
    #[inline]
    fn constant(v: f64) -> Self {
        Dual3::constant(v)
    }
    #[inline]
    fn part(self, i: usize) -> f64 {
        if i == 0 {
            self.v.abs()
        } else {
            self.g[i - 1].abs()
        }
    }
    #[inline]
    fn div_n(self, n: f64) -> Self {
        self * (1.0 / n)
    }
    #[inline]
    fn mul_f(self, h: f64) -> Self {
        self * h
    }
    #[inline]
    fn mul_values(self, o: Self) -> Self {
        Dual3::constant(self.v * o.v)
    }
}

/// Truncation per step of [`CoarseDual3`]'s series: each series (value and every derivative)
/// to 1e-10 of its own scale.
pub(crate) const COARSE_TAIL_TOL: f64 = 1e-10;

/// Truncation per step of the tight double-double series, near the 1e-32 rounding of the
/// type: the cross-check of the closed form beyond √‖F‖ = 27, where rounding and truncation
/// grow like 1/m1 per loop past the straight equilibrium (with 1e-22 the series disagreed with
/// the closed form on 59 of 1,300 reference rods, with this on 12, for ≈ 1.7× the steps).
const TIGHT_TAIL_TOL: f64 = 1e-30;

/// Where a series scalar truncates each step, instead of at its own unit roundoff.
pub(crate) trait TailTolerance: Copy + std::fmt::Debug + Default + PartialEq {
    /// Truncation relative to each series' own scale ([`Measured::TAIL_TOL`]).
    const TOL: f64;
}

/// [`COARSE_TAIL_TOL`]: longer steps (about 1.4× at order 32) for the short series of the
/// stability scan, whose g is taken to 1e-3 (see `stability::ShortSeries`); its entries carry
/// a correspondingly larger error bound there.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Coarse;
impl TailTolerance for Coarse {
    const TOL: f64 = COARSE_TAIL_TOL;
}

/// 1e-22 per step for the double-double series: the rods that need double-double amplify
/// local errors by up to e^{√F} ≲ 1e12 over the rest of the rod (√F ≲ 28 along the straight
/// part before and after the loop, measured on the strong-force oracle block), which leaves
/// ≤ 1e-10 at the tip; a smaller tolerance costs ≈ 2.4× the steps per 12 decades.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct DdStandard;
impl TailTolerance for DdStandard {
    const TOL: f64 = 1e-22;
}

/// [`TIGHT_TAIL_TOL`]: the double-double series as the closed form's cross-check.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct DdTight;
impl TailTolerance for DdTight {
    const TOL: f64 = TIGHT_TAIL_TOL;
}

/// A series scalar `T` truncated at `K`'s tolerance: the same arithmetic, another step length.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Truncated<T, K>(pub(crate) T, std::marker::PhantomData<K>);

impl<T, K> Truncated<T, K> {
    /// `t` truncated at `K`'s tolerance.
    #[inline]
    pub(crate) const fn new(t: T) -> Self {
        Self(t, std::marker::PhantomData)
    }
}

/// [`Dual3`] truncated at [`COARSE_TAIL_TOL`]: the stability scan's short series.
pub(crate) type CoarseDual3 = Truncated<Dual3, Coarse>;

impl<T: std::ops::Add<Output = T>, K> std::ops::Add for Truncated<T, K> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::new(self.0 + o.0)
    }
}

impl<T: std::ops::Sub<Output = T>, K> std::ops::Sub for Truncated<T, K> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::new(self.0 - o.0)
    }
}

impl<T: std::ops::Mul<Output = T>, K> std::ops::Mul for Truncated<T, K> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Self::new(self.0 * o.0)
    }
}

impl<T: std::ops::Neg<Output = T>, K> std::ops::Neg for Truncated<T, K> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self::new(-self.0)
    }
}

impl<T: std::ops::AddAssign, K> std::ops::AddAssign for Truncated<T, K> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        self.0 += o.0;
    }
}

impl<T: Measured, K: TailTolerance> Measured for Truncated<T, K> {
    const PARTS: usize = T::PARTS;
    const TAIL_TOL: f64 = K::TOL;
    #[inline]
    fn constant(v: f64) -> Self {
        Self::new(T::constant(v))
    }
    #[inline]
    fn part(self, i: usize) -> f64 {
        self.0.part(i)
    }
    #[inline]
    fn div_n(self, n: f64) -> Self {
        Self::new(self.0.div_n(n))
    }
    #[inline]
    fn mul_f(self, h: f64) -> Self {
        Self::new(self.0.mul_f(h))
    }
    #[inline]
    fn mul_values(self, o: Self) -> Self {
        Self::new(self.0.mul_values(o.0))
    }
}

/// The double-double dual number ([`DualDd`]) as a series scalar: J of ill-conditioned rods
/// (strong axial force: rounding made while the rod loops grows like e^{√F (1 − t)} while it
/// then sits near the unstable straight equilibrium) in the same pass as the tip. Used through
/// [`Truncated`] with [`DdStandard`] or [`DdTight`].
impl Measured for DualDd {
    const PARTS: usize = 4;
    const TAIL_TOL: f64 = crate::dd::DD_EPSILON;
    #[inline]
    fn constant(v: f64) -> Self {
        DualDd::constant(Dd::from_f64(v))
    }
    #[inline]
    fn part(self, i: usize) -> f64 {
        if i == 0 {
            self.v.hi.abs()
        } else {
            self.g[i - 1].hi.abs()
        }
    }
    #[inline]
    fn div_n(self, n: f64) -> Self {
        Self::new(
            self.v.div_small_int(n),
            [
                self.g[0].div_small_int(n),
                self.g[1].div_small_int(n),
                self.g[2].div_small_int(n),
            ],
        )
    }
    #[inline]
    fn mul_f(self, h: f64) -> Self {
        self * h
    }
    #[inline]
    fn mul_values(self, o: Self) -> Self {
        DualDd::constant(self.v * o.v)
    }
}

/// Value and gradient of a dual-number series scalar, rounded to f64.
pub(crate) trait Gradient: Measured {
    /// The value.
    fn value(self) -> f64;
    /// ∂/∂(a3, a4, a5).
    fn gradient(self) -> [f64; 3];
}

impl Gradient for Dual3 {
    fn value(self) -> f64 {
        self.v
    }
    fn gradient(self) -> [f64; 3] {
        self.g
    }
}

impl Gradient for DualDd {
    fn value(self) -> f64 {
        self.v.to_f64()
    }
    fn gradient(self) -> [f64; 3] {
        self.to_f64().1
    }
}

impl<T: Gradient, K: TailTolerance> Gradient for Truncated<T, K> {
    fn value(self) -> f64 {
        self.0.value()
    }
    fn gradient(self) -> [f64; 3] {
        self.0.gradient()
    }
}

/// Indices of the series kept per step.
const K: usize = 0; // κ
const TH: usize = 1;
const C: usize = 2;
const S: usize = 3;
const X: usize = 4;
const Y: usize = 5;
const E: usize = 6;
const SERIES: usize = 7;

/// One Taylor step: the polynomials of every series about `t0`, valid on [t0, t0 + h].
#[derive(Clone, Debug)]
pub(crate) struct Segment<T> {
    /// Start of the step.
    pub t0: f64,
    /// Step length.
    pub h: f64,
    /// Highest coefficient index used.
    order: usize,
    coef: [[T; LEN]; SERIES],
}

impl<T: Measured> Segment<T> {
    fn empty() -> Self {
        Self {
            t0: 0.0,
            h: 0.0,
            order: 0,
            coef: [[T::constant(0.0); LEN]; SERIES],
        }
    }

    #[inline]
    fn horner(&self, series: usize, dt: f64) -> T {
        let c = &self.coef[series];
        let mut v = c[self.order];
        for k in (0..self.order).rev() {
            v = v.mul_f(dt) + c[k];
        }
        v
    }

    /// (x, y, θ) at t ∈ [t0, t0 + h].
    #[inline]
    pub fn pose(&self, t: f64) -> [T; 3] {
        let dt = t - self.t0;
        [self.horner(X, dt), self.horner(Y, dt), self.horner(TH, dt)]
    }

    /// Curvature κ(t) = μ3(t).
    #[inline]
    pub fn curvature(&self, t: f64) -> T {
        self.horner(K, t - self.t0)
    }

    fn state_at_end(&self) -> [T; SERIES] {
        let mut s = [T::constant(0.0); SERIES];
        for (i, v) in s.iter_mut().enumerate() {
            *v = self.horner(i, self.h);
        }
        s
    }
}

/// The rod on [0, 1] as a chain of Taylor steps.
#[derive(Clone, Debug)]
pub(crate) struct TaylorRod<T> {
    /// The first step (a near-relaxed rod is one step), boxed: a segment of dual numbers is
    /// 7 KB, and moving it by value through the constructors and results cost more than the
    /// allocation (memmove was 7 % of a forward evaluation).
    first: Option<Box<Segment<T>>>,
    /// Later steps (multi-step rods only).
    rest: Vec<Segment<T>>,
    /// The state at `t_end`.
    end: [T; SERIES],
    /// Where the integration has reached.
    t_end: f64,
    /// The base force (the right-hand side's parameters), kept for [`Self::extend_to`].
    a4: T,
    a5: T,
    /// Whether every step's polynomials are kept.
    dense: bool,
}

impl<T: Measured> TaylorRod<T> {
    /// Integrates from the base (θ = x = y = 0, κ = a3) to t = 1 in at most `max_steps` steps.
    /// `dense` keeps every step's polynomials (for [`Self::pose`] at interior t); otherwise
    /// only the end state is kept.
    pub fn new(a3: T, a4: T, a5: T, max_steps: usize, dense: bool) -> Result<Self, RodError> {
        Self::new_to(a3, a4, a5, 1.0, max_steps, dense)
    }

    /// [`Self::new`] on [0, `t_end`] only (t_end ≤ 1): the first part of a rod, e.g. where the
    /// closed form cannot resolve det J(t) at small t. `tip` and `energy` are then at t_end.
    pub fn new_to(
        a3: T,
        a4: T,
        a5: T,
        t_end: f64,
        max_steps: usize,
        dense: bool,
    ) -> Result<Self, RodError> {
        let zero = T::constant(0.0);
        let mut end = [zero; SERIES];
        end[K] = a3;
        end[C] = T::constant(1.0);
        let mut rod = Self {
            first: None,
            rest: Vec::new(),
            end,
            t_end: 0.0,
            a4,
            a5,
            dense,
        };
        rod.extend_to(t_end, max_steps)?;
        Ok(rod)
    }

    /// Where the integration has reached (the t of [`Self::tip`]).
    pub fn t_end(&self) -> f64 {
        self.t_end
    }

    /// Number of steps kept (dense rods; 0 otherwise).
    pub fn steps(&self) -> usize {
        self.first.as_ref().map_or(0, |_| 1 + self.rest.len())
    }

    /// Continues the integration from [`Self::t_end`] to `t_end` in at most `max_steps` steps
    /// (the steps already taken are kept, not redone); returns the number of steps taken.
    pub fn extend_to(&mut self, t_end: f64, max_steps: usize) -> Result<usize, RodError> {
        let mut t0 = self.t_end;
        if t0 >= t_end {
            return Ok(0);
        }
        // Without dense output one segment is reused by every step, filled in place.
        let mut scratch: Option<Box<Segment<T>>> = None;
        for steps in 1..=max_steps {
            if crate::deadline::charge(crate::deadline::units::TAYLOR_STEP) {
                return Err(RodError::Deadline { t: t0 });
            }
            let mut seg = match scratch.take() {
                Some(s) => s,
                None => Box::new(Segment::empty()),
            };
            step(&mut seg, &self.end, self.a4, self.a5, t0, t_end - t0)?;
            let state = seg.state_at_end();
            if !state
                .iter()
                .all(|v| (0..T::PARTS).all(|i| v.part(i).is_finite()))
            {
                return Err(overflow());
            }
            self.end = state;
            t0 = if seg.h >= t_end - t0 {
                t_end
            } else {
                t0 + seg.h
            };
            self.t_end = t0;
            if !self.dense {
                scratch = Some(seg);
            } else if self.first.is_none() {
                self.first = Some(seg);
            } else {
                self.rest.push(*seg);
            }
            if t0 >= t_end {
                return Ok(steps);
            }
        }
        Err(RodError::Integration(format!(
            "Taylor series: step budget of {max_steps} steps exhausted at t = {t0}"
        )))
    }

    /// (x, y, θ) at t = 1.
    pub fn tip(&self) -> [T; 3] {
        [self.end[X], self.end[Y], self.end[TH]]
    }

    /// Elastic energy ½∫₀¹κ², integrated along (no cancellation). Value only: in dual numbers
    /// its derivatives are not computed (zero).
    pub fn energy(&self) -> T {
        self.end[E]
    }

    fn segment(&self, t: f64) -> Option<&Segment<T>> {
        let first = self.first.as_deref()?;
        if t <= first.t0 + first.h || self.rest.is_empty() {
            return Some(first);
        }
        let i = self
            .rest
            .partition_point(|s| s.t0 + s.h < t)
            .min(self.rest.len() - 1);
        self.rest.get(i)
    }

    /// (x, y, θ) at t ∈ [0, 1] (needs `dense`); None without dense output.
    pub fn pose(&self, t: f64) -> Option<[T; 3]> {
        self.segment(t).map(|s| s.pose(t))
    }

    /// κ(t) (needs `dense`).
    pub fn curvature(&self, t: f64) -> Option<T> {
        self.segment(t).map(|s| s.curvature(t))
    }
}

fn overflow() -> RodError {
    RodError::Overflow(
        "planar rod: J(t, a) or the shape exceeds the range of f64 (force too large)".into(),
    )
}

/// Builds the Taylor coefficients from `state` at t0 into `seg` (in place: no 7 KB moves) and
/// chooses the step (≤ `remaining`).
fn step<T: Measured>(
    seg: &mut Segment<T>,
    state: &[T; SERIES],
    a4: T,
    a5: T,
    t0: f64,
    remaining: f64,
) -> Result<(), RodError> {
    let zero = T::constant(0.0);
    seg.t0 = t0;
    seg.h = remaining;
    seg.order = 0;
    // Only coefficients 0..=order are ever read, and each is written before it is read.
    for (i, v) in state.iter().enumerate() {
        seg.coef[i][0] = *v;
    }
    // Running scale (largest |term| so far) of every series and measured part at h =
    // `remaining`, so that the order loop's truncation test costs O(1) per order instead of a
    // pass over every term (it was a quarter of a series' cost).
    let mut tails = Tails::<T>::new(remaining);
    tails.add(seg, 0);
    for k in 0..MAX_ORDER {
        let c = &mut seg.coef;
        // Cauchy products (s κ)_k, (c κ)_k, (κ κ)_k (the last for the energy: values only).
        let (mut sk, mut ck, mut kk) = (zero, zero, zero);
        for j in 0..=k {
            let kap = c[K][k - j];
            sk += c[S][j] * kap;
            ck += c[C][j] * kap;
            kk += c[K][j].mul_values(kap);
        }
        let n = (k + 1) as f64;
        c[K][k + 1] = (a4 * c[S][k] - a5 * c[C][k]).div_n(n);
        c[TH][k + 1] = c[K][k].div_n(n);
        c[C][k + 1] = (-sk).div_n(n);
        c[S][k + 1] = ck.div_n(n);
        c[X][k + 1] = c[C][k].div_n(n);
        c[Y][k + 1] = c[S][k].div_n(n);
        c[E][k + 1] = kk.div_n(2.0 * n);
        seg.order = k + 1;
        tails.add(seg, k + 1);
        // Tested at even orders once a few terms exist (two consecutive zero terms of an
        // even/odd series cannot fake convergence then, since the check also needs the scale's
        // terms to have been reached).
        if k + 1 >= MIN_ORDER && (k + 1) % 2 == 0 && tails.converged(seg) {
            return Ok(());
        }
    }
    // Not converged at the full remaining length: shrink h until the tail estimate holds.
    let mut h = remaining;
    while h > MIN_STEP {
        h *= STEP_SHRINK;
        if converged(seg, h) {
            seg.h = h;
            return Ok(());
        }
    }
    if seg.coef.iter().flatten().all(|v| v.part(0).is_finite()) {
        Err(RodError::Integration(format!(
            "Taylor series: step below {MIN_STEP} at t = {t0} (rod too strongly bent for f64)"
        )))
    } else {
        Err(overflow())
    }
}

/// The truncation test of [`converged`] at a fixed h, kept up to date term by term.
struct Tails<T> {
    h: f64,
    /// h^k for the next term k.
    hp: f64,
    /// h^k of the last two terms added (k − 1, k).
    last_hp: [f64; 2],
    /// Largest |term| so far per series and measured part (at most 4 parts).
    scale: [[f64; 4]; SERIES],
    /// A term was not finite.
    overflow: bool,
    _t: std::marker::PhantomData<T>,
}

impl<T: Measured> Tails<T> {
    fn new(h: f64) -> Self {
        Self {
            h,
            hp: 1.0,
            last_hp: [0.0; 2],
            scale: [[0.0; 4]; SERIES],
            overflow: false,
            _t: std::marker::PhantomData,
        }
    }

    /// Takes term `k` (the next one) of every series into the scales.
    #[inline]
    fn add(&mut self, seg: &Segment<T>, k: usize) {
        for (series, scale) in seg.coef.iter().zip(self.scale.iter_mut()) {
            for (part, s) in scale.iter_mut().enumerate().take(T::PARTS) {
                let term = series[k].part(part) * self.hp;
                self.overflow |= !term.is_finite();
                *s = s.max(term);
            }
        }
        self.last_hp = [self.last_hp[1], self.hp];
        self.hp *= self.h;
    }

    /// [`converged`] at this h for a segment whose terms 0..=order were all added: the same
    /// verdict, from the last two terms only.
    fn converged(&self, seg: &Segment<T>) -> bool {
        if self.overflow {
            return false;
        }
        let n = seg.order;
        let [hn1, hn] = self.last_hp;
        seg.coef.iter().zip(&self.scale).all(|(series, scale)| {
            (0..T::PARTS).all(|part| {
                let last = series[n - 1].part(part) * hn1 + series[n].part(part) * hn;
                last <= T::TAIL_TOL * scale[part]
            })
        })
    }
}

/// The a-posteriori truncation test at step h: for every series and every measured part, the
/// last two terms are ≤ TAIL_TOL × the largest term (Jorba & Zou 2005, eq. 3.7 style).
fn converged<T: Measured>(seg: &Segment<T>, h: f64) -> bool {
    let n = seg.order;
    for series in &seg.coef {
        for part in 0..T::PARTS {
            let mut scale = 0.0f64;
            let mut hp = 1.0;
            let mut last = [0.0f64; 2];
            for (k, v) in series.iter().take(n + 1).enumerate() {
                let term = v.part(part) * hp;
                if !term.is_finite() {
                    return false;
                }
                scale = scale.max(term);
                if k + 1 >= n {
                    last[k + 1 - n] = term;
                }
                hp *= h;
            }
            if last[0] + last[1] > T::TAIL_TOL * scale {
                return false;
            }
        }
    }
    true
}

// The formulation (issue 44): the series of a rod as the planar entry points ask it, with its
// step budgets and the domain refusals of the double-double series.

/// Step budget of the f64 Taylor series (bounded time: ≈ 3 µs per step in dual numbers, so
/// ≲ 6 ms; a rod that needs more steps is beyond what the fallback resolves quickly).
pub(crate) const SERIES_MAX_STEPS: usize = 2_000;
/// Step budget of the double-double series (≈ 30–60 µs per step in dual numbers: ≲ 40 ms).
const SERIES_DD_MAX_STEPS: usize = 800;

/// The f64 series of a (dense: keeps every step's polynomials, for poses at t < 1).
pub(crate) fn series_f64(a: &PlanarParams, dense: bool) -> Result<TaylorRod<f64>, RodError> {
    TaylorRod::new(a[0], a[1], a[2], SERIES_MAX_STEPS, dense)
}

/// The series in dual numbers seeded with the identity on a: carries J.
pub(crate) fn series_dual(a: &PlanarParams, dense: bool) -> Result<TaylorRod<Dual3>, RodError> {
    TaylorRod::new(
        Dual3::variable(a[0], 0),
        Dual3::variable(a[1], 1),
        Dual3::variable(a[2], 2),
        SERIES_MAX_STEPS,
        dense,
    )
}

/// The dense series in double-double dual numbers, for rods where the closed form's error
/// estimate fails. Those are the ill-conditioned ones (strong axial force: rounding made while
/// the rod loops grows like e^{√F (1 − t)} while it then sits near the unstable straight
/// equilibrium; an f64 integration, the oracle's included, is off by up to 1e-5 there, see
/// tests/relaxed_oracle.rs), so they are integrated with a 106-bit significand.
pub(crate) fn series_dd<K: TailTolerance>(
    a: &PlanarParams,
    dense: bool,
    max_root_f: f64,
) -> Result<TaylorRod<Truncated<DualDd, K>>, RodError> {
    let root_f = a[1].hypot(a[2]).sqrt();
    if root_f > LN_F64_MAX {
        return Err(overflow_force());
    }
    if root_f > max_root_f {
        return Err(RodError::OutOfDomain(format!(
            "planar rod near its straight equilibrium under a force of {:.3e}: rounding grows \
             like e^(sqrt|F|) and the answer cannot be certified to 1e-9 in bounded time \
             (supported: sqrt|F| <= {max_root_f})",
            root_f * root_f
        )));
    }
    TaylorRod::new(
        Truncated::new(DualDd::variable(a[0], 0)),
        Truncated::new(DualDd::variable(a[1], 1)),
        Truncated::new(DualDd::variable(a[2], 2)),
        SERIES_DD_MAX_STEPS,
        dense,
    )
}

/// The pose and J from a dual-number pose; refused where either is not finite.
pub(crate) fn pose_jac_from<T: Gradient>(
    p: [T; 3],
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    let [x, y, th] = p.map(|v| (v.value(), v.gradient()));
    let pose = PlanarPose::new(x.0, y.0, th.0);
    let j = PlanarJacobian::new(
        x.1[0], x.1[1], x.1[2], y.1[0], y.1[1], y.1[2], th.1[0], th.1[1], th.1[2],
    );
    if !(pose.is_finite() && j.iter().all(|v| v.is_finite())) {
        return Err(crate::planar::closed::overflow());
    }
    Ok((pose, j))
}

/// q(t) and J(t) from the series (dense only when t < 1).
pub(crate) fn series_pose_and_jac(
    a: &PlanarParams,
    t: f64,
) -> Result<(PlanarPose, PlanarJacobian), RodError> {
    if t >= 1.0 {
        return pose_jac_from(series_dual(a, false)?.tip());
    }
    let rod = series_dual(a, true)?;
    pose_jac_from(
        rod.pose(t.max(0.0))
            .ok_or_else(crate::planar::closed::overflow)?,
    )
}

/// ln(f64::MAX): under tension F the rod's J grows like e^{√F t}; beyond this √F it overflows.
pub(crate) const LN_F64_MAX: f64 = 709.7;

/// The refusal of a rod under a tension whose J exceeds f64.
pub(crate) fn overflow_force() -> RodError {
    RodError::Overflow(format!(
        "planar rod: under this force J(t, a) grows like e^(sqrt|F| t) and exceeds f64 \
         (sqrt|F| > {LN_F64_MAX})"
    ))
}

/// ρ = max(|a3|, √‖(a4, a5)‖): the rod's curvature scale (its Taylor terms grow like ρᵏ/k!).
pub(crate) fn curvature_scale(a: &PlanarParams) -> f64 {
    a[0].abs().max(crate::scalar::fast_hypot(a[1], a[2]).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_matches_exact() {
        // a = (1, 0, 0): θ = t, x = sin t, y = 1 − cos t, E = 1/2.
        let r = TaylorRod::new(1.0, 0.0, 0.0, 10, false).unwrap();
        let [x, y, th] = r.tip();
        assert!((x - 1f64.sin()).abs() < 1e-15);
        assert!((y - (1.0 - 1f64.cos())).abs() < 1e-15);
        assert!((th - 1.0).abs() < 1e-15);
        assert!((r.energy() - 0.5).abs() < 1e-15);
    }

    #[test]
    fn straight_rod_jacobian_is_the_linearisation() {
        // a = 0: θ(t) to first order is a3 t − a5 t²/2, y ≈ a3 t²/2 − a5 t³/6, x = 1.
        let r = TaylorRod::new(
            Dual3::variable(0.0, 0),
            Dual3::variable(0.0, 1),
            Dual3::variable(0.0, 2),
            1,
            false,
        )
        .unwrap();
        let [x, y, th] = r.tip();
        assert_eq!(x.v, 1.0);
        assert_eq!(x.g, [0.0; 3]);
        assert!((y.g[0] - 0.5).abs() < 1e-16 && (y.g[2] + 1.0 / 6.0).abs() < 1e-16);
        assert!((th.g[0] - 1.0).abs() < 1e-16 && (th.g[2] + 0.5).abs() < 1e-16);
        assert_eq!(th.g[1], 0.0);
    }
}
