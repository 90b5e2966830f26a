//! Taylor-series integration of the heavy planar rod and its variational equations.
//!
//! The right-hand side is polynomial in (cos θ, sin θ, κ, t) (module docs of [`super`]):
//!
//! * θ' = κ, κ' = n_x(t) s − n_y(t) c, c' = −s κ, s' = c κ, x' = c, y' = s,
//! * n(t) = n(t₀) − w ĝ τ (τ = t − t₀), so each product with n is a two-term sum;
//! * variations (one column per parameter a3, a4, a5): δθ' = δκ,
//!   δκ' = P δθ + (0, s, −c)_j with P = n_x c + n_y s, δx' = −s δθ, δy' = c δθ;
//! * quadratures: elastic energy e' = κ²/2, potential p' = −ĝ · r.
//!
//! Each step computes the Taylor coefficients of every quantity to [`ORDER`] by the usual
//! recurrences (Cauchy products, no transcendental call but one `sin_cos` per step), so a
//! step is exact polynomial arithmetic plus a truncation of order τ^(ORDER+1), and gives
//! dense output for free (the shape and the stability scan evaluate the step's polynomials).
//!
//! Step size (Jorba & Zou 2005, "A software package for the numerical integration of ODEs
//! by means of high-order Taylor methods"): h = ρ · TRUNCATION^(1/ORDER) with ρ the radius
//! estimated from θ's last two coefficients, capped by [`OMEGA_STEP`] / ω where
//! ω = |κ(t₀)| + √max‖n‖ bounds the growth rate of the linear parts (a straight rod under
//! tension has an entire θ ≡ 0 but J growing like e^{√‖n‖ t}).

/// Order of the Taylor polynomials (Jorba & Zou: −½ ln ε + 1 ≈ 19 for f64).
pub(crate) const ORDER: usize = 20;
const N: usize = ORDER + 1;
/// Target truncation per step relative to the scale of θ: 1e-14 keeps the tip within 1e-11
/// and J within 1e-10 relative of the 1e-13 reference on the tests' families (issue 41 asks
/// 1e-9 and 1e-6).
const TRUNCATION: f64 = 1e-14;
/// ω h ≤ this: the terms of the entire parts are then ≤ 1.5^20 / 20! ≈ 1.4e-15.
const OMEGA_STEP: f64 = 1.5;
/// Steps allowed for one integration of the unit rod: ω ≤ |a3| + √(‖(a4, a5)‖ + w) with the
/// contract's bounds gives at most a few hundred; this is a safety net against a NaN loop.
pub(crate) const MAX_STEPS: usize = 20_000;

/// Evaluation of a polynomial with coefficients `c` at τ (Horner).
#[inline(always)]
pub(crate) fn horner(c: &[f64; N], tau: f64) -> f64 {
    let mut v = c[ORDER];
    for k in (0..ORDER).rev() {
        v = v * tau + c[k];
    }
    v
}

/// Four lanes: the three variational columns and a padding lane.
pub(crate) type Lanes = [f64; 4];

/// Horner on four lanes at once.
#[inline(always)]
pub(crate) fn horner_lanes(c: &[Lanes; N], tau: f64) -> Lanes {
    let mut v = c[ORDER];
    for k in (0..ORDER).rev() {
        for l in 0..4 {
            v[l] = v[l] * tau + c[k][l];
        }
    }
    v
}

/// The k-th coefficients of (s κ, c κ, κ κ), in one pass over κ.
#[inline(always)]
fn cauchy3(s: &[f64; N], c: &[f64; N], kappa: &[f64; N], k: usize) -> (f64, f64, f64) {
    let (mut sk, mut ck, mut kk) = (0.0, 0.0, 0.0);
    for i in 0..=k {
        let q = kappa[k - i];
        sk += s[i] * q;
        ck += c[i] * q;
        kk += kappa[i] * q;
    }
    (sk, ck, kk)
}

/// The data of the rod that the series needs: a and the load w ĝ.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Problem {
    /// a = (a3, a4, a5).
    pub a: [f64; 3],
    /// w ĝ (the weight per unit length, in the base frame).
    pub load: [f64; 2],
    /// ĝ (unit), for the potential energy.
    pub direction: [f64; 2],
}

impl Problem {
    /// n(t) = (a4, a5) − t w ĝ.
    #[inline(always)]
    pub(crate) fn force(&self, t: f64) -> [f64; 2] {
        [self.a[1] - t * self.load[0], self.a[2] - t * self.load[1]]
    }
}

/// The state at the start of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct State {
    pub t: f64,
    pub theta: f64,
    pub kappa: f64,
    pub x: f64,
    pub y: f64,
    pub elastic: f64,
    pub potential: f64,
    /// Columns (a3, a4, a5) of (δθ, δκ, δx, δy).
    pub var: [[f64; 4]; 3],
}

impl State {
    /// The base: identity pose, κ = a3, δκ/δa3 = 1.
    pub(crate) fn base(a: &[f64; 3]) -> Self {
        let mut var = [[0.0; 4]; 3];
        var[0][1] = 1.0;
        Self {
            kappa: a[0],
            var,
            ..Self::default()
        }
    }
}

/// The Taylor polynomials of one step, valid for τ = t − t0 ∈ [0, h].
#[derive(Clone, Debug)]
pub(crate) struct Step {
    pub t0: f64,
    pub h: f64,
    pub theta: [f64; N],
    pub kappa: [f64; N],
    pub cos: [f64; N],
    pub sin: [f64; N],
    pub x: [f64; N],
    pub y: [f64; N],
    pub elastic: [f64; N],
    pub potential: [f64; N],
    /// δθ, δκ, δx, δy, coefficient-major: `dx[k][j]` is coefficient k of column j (a3, a4,
    /// a5; lane 3 is padding), so that the three columns' products run as one vector loop.
    pub dtheta: [Lanes; N],
    pub dkappa: [Lanes; N],
    pub dx: [Lanes; N],
    pub dy: [Lanes; N],
    /// P = n_x c + n_y s, the coefficient of δθ in δκ'.
    stiffness: [f64; N],
    /// True when the variational polynomials were computed.
    pub with_jacobian: bool,
}

impl Step {
    fn zeroed() -> Self {
        Self {
            t0: 0.0,
            h: 0.0,
            theta: [0.0; N],
            kappa: [0.0; N],
            cos: [0.0; N],
            sin: [0.0; N],
            x: [0.0; N],
            y: [0.0; N],
            elastic: [0.0; N],
            potential: [0.0; N],
            dtheta: [[0.0; 4]; N],
            dkappa: [[0.0; 4]; N],
            dx: [[0.0; 4]; N],
            dy: [[0.0; 4]; N],
            stiffness: [0.0; N],
            with_jacobian: false,
        }
    }

    /// The state at τ ∈ [0, h] (the variations only when computed).
    pub(crate) fn state_at(&self, tau: f64) -> State {
        let mut var = [[0.0; 4]; 3];
        if self.with_jacobian {
            let (th, ka, x, y) = (
                horner_lanes(&self.dtheta, tau),
                horner_lanes(&self.dkappa, tau),
                horner_lanes(&self.dx, tau),
                horner_lanes(&self.dy, tau),
            );
            for (j, v) in var.iter_mut().enumerate() {
                *v = [th[j], ka[j], x[j], y[j]];
            }
        }
        State {
            t: self.t0 + tau,
            theta: horner(&self.theta, tau),
            kappa: horner(&self.kappa, tau),
            x: horner(&self.x, tau),
            y: horner(&self.y, tau),
            elastic: horner(&self.elastic, tau),
            potential: horner(&self.potential, tau),
            var,
        }
    }

    /// (x, y, θ) at τ.
    pub(crate) fn pose_at(&self, tau: f64) -> [f64; 3] {
        [
            horner(&self.x, tau),
            horner(&self.y, tau),
            horner(&self.theta, tau),
        ]
    }

    /// J(t0 + τ) as rows (x, y, θ) × columns (a3, a4, a5).
    pub(crate) fn jacobian_at(&self, tau: f64) -> [[f64; 3]; 3] {
        let (x, y, th) = (
            horner_lanes(&self.dx, tau),
            horner_lanes(&self.dy, tau),
            horner_lanes(&self.dtheta, tau),
        );
        [
            [x[0], x[1], x[2]],
            [y[0], y[1], y[2]],
            [th[0], th[1], th[2]],
        ]
    }

    /// Fills the coefficients from the state `s` (the recurrences of the module docs).
    fn expand(&mut self, p: &Problem, s: &State, jacobian: bool) {
        let (sn, cs) = s.theta.sin_cos();
        let n0 = p.force(s.t);
        let n1 = [-p.load[0], -p.load[1]];
        self.t0 = s.t;
        self.with_jacobian = jacobian;
        self.theta[0] = s.theta;
        self.kappa[0] = s.kappa;
        self.cos[0] = cs;
        self.sin[0] = sn;
        self.x[0] = s.x;
        self.y[0] = s.y;
        self.elastic[0] = s.elastic;
        self.potential[0] = s.potential;
        for j in 0..3 {
            self.dtheta[0][j] = s.var[j][0];
            self.dkappa[0][j] = s.var[j][1];
            self.dx[0][j] = s.var[j][2];
            self.dy[0][j] = s.var[j][3];
        }
        let (gx, gy) = (p.direction[0], p.direction[1]);
        for k in 0..ORDER {
            let inv = 1.0 / (k + 1) as f64;
            // Products with n(t) = n0 + n1 τ: two terms.
            let (s_prev, c_prev) = if k > 0 {
                (self.sin[k - 1], self.cos[k - 1])
            } else {
                (0.0, 0.0)
            };
            let torque =
                n0[0] * self.sin[k] + n1[0] * s_prev - n0[1] * self.cos[k] - n1[1] * c_prev;
            let (sk, ck, kk) = cauchy3(&self.sin, &self.cos, &self.kappa, k);
            self.theta[k + 1] = self.kappa[k] * inv;
            self.kappa[k + 1] = torque * inv;
            self.cos[k + 1] = -sk * inv;
            self.sin[k + 1] = ck * inv;
            self.x[k + 1] = self.cos[k] * inv;
            self.y[k + 1] = self.sin[k] * inv;
            self.elastic[k + 1] = 0.5 * kk * inv;
            self.potential[k + 1] = -(gx * self.x[k] + gy * self.y[k]) * inv;
            if jacobian {
                // P = n_x c + n_y s as its own series, coefficient k.
                let pk =
                    n0[0] * self.cos[k] + n1[0] * c_prev + n0[1] * self.sin[k] + n1[1] * s_prev;
                self.variation_coefficient(k, pk, inv);
            }
        }
    }

    /// Coefficient k + 1 of the three variational columns, given P_k: one loop over the
    /// Cauchy products P·δθ, s·δθ and c·δθ, four lanes wide.
    #[inline(always)]
    fn variation_coefficient(&mut self, k: usize, pk: f64, inv: f64) {
        self.stiffness[k] = pk;
        let mut pd = [0.0; 4];
        let mut sd = [0.0; 4];
        let mut cd = [0.0; 4];
        for i in 0..=k {
            let d = self.dtheta[k - i];
            let (p, sn, cs) = (self.stiffness[i], self.sin[i], self.cos[i]);
            for l in 0..4 {
                pd[l] += p * d[l];
                sd[l] += sn * d[l];
                cd[l] += cs * d[l];
            }
        }
        // The forcing of δκ' by the parameters: 0 for a3, s for a4, −c for a5.
        let forcing = [0.0, self.sin[k], -self.cos[k], 0.0];
        let dkappa = self.dkappa[k];
        for l in 0..4 {
            self.dtheta[k + 1][l] = dkappa[l] * inv;
            self.dkappa[k + 1][l] = (pd[l] + forcing[l]) * inv;
            self.dx[k + 1][l] = -sd[l] * inv;
            self.dy[k + 1][l] = cd[l] * inv;
        }
    }

    /// The step size from the coefficients just computed (module docs), at most `left`.
    fn choose_h(&self, p: &Problem, left: f64) -> f64 {
        let radius = |c: &[f64; N]| {
            let r1 = (1.0 / c[ORDER - 1].abs()).powf(1.0 / (ORDER - 1) as f64);
            let r2 = (1.0 / c[ORDER].abs()).powf(1.0 / ORDER as f64);
            r1.min(r2)
        };
        let rho = radius(&self.theta);
        let n0 = p.force(self.t0);
        let n1 = p.force(self.t0 + left.min(1.0));
        let nmax = n0[0].hypot(n0[1]).max(n1[0].hypot(n1[1]));
        let omega = self.kappa[0].abs() + nmax.sqrt();
        let h = (rho * TRUNCATION.powf(1.0 / ORDER as f64)).min(OMEGA_STEP / omega);
        if h.is_nan() {
            return left;
        }
        h.min(left)
    }
}

/// Why an integration stopped early.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Stop {
    /// A coefficient or the state overflowed.
    NonFinite { t: f64 },
    /// More than [`MAX_STEPS`] steps.
    Budget { t: f64 },
    /// The solver's deadline passed (checked once per step).
    Deadline { t: f64 },
}

/// Integrates from t = 0 to t = 1, handing each step's polynomials to `visit` (which may stop
/// the integration by returning `false`). Returns the state at the end of the last step.
pub(crate) fn integrate(
    p: &Problem,
    jacobian: bool,
    mut visit: impl FnMut(&Step) -> bool,
) -> Result<State, Stop> {
    let mut state = State::base(&p.a);
    let mut step = Step::zeroed();
    for _ in 0..MAX_STEPS {
        if crate::deadline::charge(crate::deadline::units::HEAVY_STEP) {
            return Err(Stop::Deadline { t: state.t });
        }
        step.expand(p, &state, jacobian);
        let left = 1.0 - state.t;
        let mut h = step.choose_h(p, left);
        // The step that ends the rod lands on t = 1 exactly (no sliver step after it).
        let last = h >= left * (1.0 - 1e-12);
        if last {
            h = left;
        }
        step.h = h;
        let mut next = step.state_at(h);
        next.t = if last { 1.0 } else { state.t + h };
        let finite = next.theta.is_finite()
            && next.kappa.is_finite()
            && next.x.is_finite()
            && next.y.is_finite()
            && next.var.iter().flatten().all(|v| v.is_finite());
        if !finite || !(h > 0.0) {
            return Err(Stop::NonFinite { t: state.t });
        }
        let go_on = visit(&step);
        state = next;
        if last || !go_on {
            return Ok(state);
        }
    }
    Err(Stop::Budget { t: state.t })
}
