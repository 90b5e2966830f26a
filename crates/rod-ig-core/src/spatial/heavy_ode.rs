//! The ODE of the 3-D rod with weight (module docs of [`super::heavy`]): the gravity it carries
//! and the right-hand side with its variational columns, shared by single shooting from the
//! base ([`super::heavy`]) and the segments of the multiple shooting ([`super::cable`]).

// Index loops mirror the formulas.
#![allow(clippy::needless_range_loop)]

use super::reduced::{cross, kinematics, rotmat, rt_mul as rt};
use crate::RodError;

/// Base state: q (w, x, y, z), p, elastic energy, P = ∫p.
pub(super) const NB: usize = 11;

/// Gravity acting on a 3-D rod: the dimensionless weight w = ρgAL³/EI and the unit direction of
/// gravity in the base frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gravity3 {
    weight: f64,
    direction: [f64; 3],
}

impl Gravity3 {
    /// No weight.
    pub const NONE: Gravity3 = Gravity3 {
        weight: 0.0,
        direction: [0.0, 0.0, -1.0],
    };

    /// Weight `weight` ∈ [0, [`crate::planar::heavy::MAX_WEIGHT`]] along `direction` (any
    /// non-zero finite vector; normalised).
    pub fn new(weight: f64, direction: [f64; 3]) -> Result<Self, RodError> {
        RodError::check_finite("weight", &[weight])?;
        RodError::check_finite("gravity", &direction)?;
        let max = crate::planar::heavy::MAX_WEIGHT;
        if !(0.0..=max).contains(&weight) {
            return Err(RodError::OutOfDomain(format!(
                "weight must be in [0, {max:e}] (got {weight})"
            )));
        }
        let norm = direction.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 1e-300 && norm.is_finite()) {
            return Err(RodError::OutOfDomain(
                "gravity must be a non-zero vector".into(),
            ));
        }
        Ok(Self {
            weight,
            direction: direction.map(|v| v / norm),
        })
    }

    /// The gravity whose load per unit length is w ĝ = `load` (direction `fallback` when the
    /// load is zero).
    pub fn from_load(load: [f64; 3], fallback: [f64; 3]) -> Result<Self, RodError> {
        let w = load.iter().map(|v| v * v).sum::<f64>().sqrt();
        if w == 0.0 {
            return Self::new(0.0, fallback);
        }
        Self::new(w, load)
    }

    /// The dimensionless weight w.
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// The unit direction ĝ.
    pub fn direction(&self) -> [f64; 3] {
        self.direction
    }

    /// True when w = 0.
    pub fn is_weightless(&self) -> bool {
        self.weight == 0.0
    }

    /// The weight per unit length w ĝ.
    pub fn load(&self) -> [f64; 3] {
        self.direction.map(|v| v * self.weight)
    }
}

fn rv(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

/// The right-hand side (module docs); `var`: with the variational equations of its `C`
/// columns (state size `N` = [`NB`] + 9 `C`; the last six columns are ∂/∂a, the first `C` − 6
/// start from unit perturbations of the state at the start of the integration, as the
/// segments of [`super::cable`] do).
pub(super) fn rhs<const N: usize, const C: usize>(
    ci: &[f64; 3],
    a: &[f64; 6],
    load: [f64; 3],
    t: f64,
    s: &[f64; N],
    ds: &mut [f64; N],
    var: bool,
) {
    let (w, x, y, z) = (s[0], s[1], s[2], s[3]);
    let p = [s[4], s[5], s[6]];
    let pp = [s[8], s[9], s[10]];
    let r = rotmat(w, x, y, z);
    let n = [a[3] - t * load[0], a[4] - t * load[1], a[5] - t * load[2]];
    let moment = cross(pp, load);
    let pxn = cross(p, n);
    let f = rt(&r, n);
    let m = rt(
        &r,
        [
            a[0] - moment[0] - pxn[0],
            a[1] - moment[1] - pxn[1],
            a[2] - moment[2] - pxn[2],
        ],
    );
    let om = kinematics(ci, [w, x, y, z], &r, m, ds);
    ds[8] = p[0];
    ds[9] = p[1];
    ds[10] = p[2];
    if var {
        variations::<N, C>(ci, load, &r, (p, f, m, om), s, ds);
    }
}

/// The variational equations of [`rhs`], given R and the body wrench (p, f, m, ω) there.
fn variations<const N: usize, const C: usize>(
    ci: &[f64; 3],
    load: [f64; 3],
    r: &[[f64; 3]; 3],
    (p, f, m, om): ([f64; 3], [f64; 3], [f64; 3], [f64; 3]),
    s: &[f64; N],
    ds: &mut [f64; N],
) {
    debug_assert!(N == NB + 9 * C && C >= 6);
    let r = *r;
    let eta = |k: usize, c: usize| s[NB + C * k + c];
    let dp = |k: usize, c: usize| s[NB + 6 * C + C * k + c];
    for c in 0..C {
        // g_c = Rᵀ δa_m − Rᵀ (p × δa_f) − Rᵀ (δP × w ĝ).
        let mut unit = [0.0; 6];
        if c + 6 >= C {
            unit[c + 6 - C] = 1.0;
        }
        let dam = [unit[0], unit[1], unit[2]];
        let daf = [unit[3], unit[4], unit[5]];
        let dpp = [dp(0, c), dp(1, c), dp(2, c)];
        let pxd = cross(p, daf);
        let dxl = cross(dpp, load);
        let g = rt(
            &r,
            [
                dam[0] - pxd[0] - dxl[0],
                dam[1] - pxd[1] - dxl[1],
                dam[2] - pxd[2] - dxl[2],
            ],
        );
        let e = [eta(0, c), eta(1, c), eta(2, c)];
        let v = [eta(3, c), eta(4, c), eta(5, c)];
        let c1 = cross(e, m);
        let c2 = cross(v, f);
        let dm = [
            g[0] - c1[0] - c2[0],
            g[1] - c1[1] - c2[1],
            g[2] - c1[2] - c2[2],
        ];
        let oxe = cross(om, e);
        let oxv = cross(om, v);
        ds[NB + c] = dm[0] * ci[0] - oxe[0];
        ds[NB + C + c] = dm[1] * ci[1] - oxe[1];
        ds[NB + C * 2 + c] = dm[2] * ci[2] - oxe[2];
        // η_v' = −ω × η_v + η_ω × e1, with η_ω × e1 = (0, η_ω3, −η_ω2).
        ds[NB + C * 3 + c] = -oxv[0];
        ds[NB + C * 4 + c] = -oxv[1] + e[2];
        ds[NB + C * 5 + c] = -oxv[2] - e[1];
        // δP' = δp = R η_v.
        let dpw = rv(&r, v);
        ds[NB + 6 * C + c] = dpw[0];
        ds[NB + 6 * C + C + c] = dpw[1];
        ds[NB + 6 * C + 2 * C + c] = dpw[2];
    }
}
