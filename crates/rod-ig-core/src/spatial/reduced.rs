//! The production formulation: the rod integrated on (q, p) only, μ recovered from the
//! conserved world wrench, with 6-dimensional variational equations per parameter.
//!
//! Equilibrium (m' = m × ω + f × e1, f' = f × ω) is equivalent to the conservation of the
//! world wrench: R f = a_f and R m + p × R f = a_m (docs/math.md §10, checked first integrals). Hence
//! f = Rᵀ a_f, m = Rᵀ(a_m − p × a_f), and only q' = ½ q ⊗ (0, ω), p' = R e1 are integrated.
//! Differentiating with δR = R[η_ω]×, δp = R η_v (η = q⁻¹ δq, the columns of J):
//! δm = −η_ω × m − η_v × f + Rᵀ δa_m − Rᵀ(p × δa_f), δω = δm / c, and
//! η' = δξ − ad_ξ η, i.e. η_ω' = δω − ω × η_ω, η_v' = −ω × η_v + η_ω × e1 (δf is not needed).
//! State: q (w, x, y, z), p, energy, then η for a1..a6, row-major (component r of column c
//! at 8 + 6 r + c): 8 + 36 = 44 values (the literal μ-form of [`super`] needs 86).

use super::{SpatialJacobian, SpatialParams, SpatialPose};
use crate::ode::{solve, OdeError, OdeOptions};

/// Base state size (q, p, energy).
pub(crate) const NRB: usize = 8;
/// Base + variational state size.
pub(crate) const NR: usize = NRB + 36;
/// Index of the energy quadrature.
pub(crate) const ENERGY: usize = 7;

#[inline(always)]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Rotation matrix (row-major r[i][j] = R_ij) of the quaternion, normalised on the fly.
#[inline(always)]
pub(crate) fn rotmat(w: f64, x: f64, y: f64, z: f64) -> [[f64; 3]; 3] {
    let n2 = w * w + x * x + y * y + z * z;
    let s = if n2 > 0.0 { 2.0 / n2 } else { 0.0 };
    [
        [
            1.0 - s * (y * y + z * z),
            s * (x * y - w * z),
            s * (x * z + w * y),
        ],
        [
            s * (x * y + w * z),
            1.0 - s * (x * x + z * z),
            s * (y * z - w * x),
        ],
        [
            s * (x * z - w * y),
            s * (y * z + w * x),
            1.0 - s * (x * x + y * y),
        ],
    ]
}

#[inline(always)]
pub(crate) fn rt_mul(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
        r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
        r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2],
    ]
}

/// The rod's kinematics shared by every formulation on (q, p, energy): ω = m / c,
/// q' = ½ q ⊗ (0, ω), p' = R e1 and the elastic energy's rate ½ m · ω, written to `ds[0..8]`.
/// Returns ω.
#[inline(always)]
pub(crate) fn kinematics(
    ci: &[f64; 3],
    [w, x, y, z]: [f64; 4],
    r: &[[f64; 3]; 3],
    m: [f64; 3],
    ds: &mut [f64],
) -> [f64; 3] {
    let om = [m[0] * ci[0], m[1] * ci[1], m[2] * ci[2]];
    ds[0] = -0.5 * (x * om[0] + y * om[1] + z * om[2]);
    ds[1] = 0.5 * (w * om[0] + y * om[2] - z * om[1]);
    ds[2] = 0.5 * (w * om[1] + z * om[0] - x * om[2]);
    ds[3] = 0.5 * (w * om[2] + x * om[1] - y * om[0]);
    ds[4] = r[0][0];
    ds[5] = r[1][0];
    ds[6] = r[2][0];
    ds[7] = 0.5 * (m[0] * om[0] + m[1] * om[1] + m[2] * om[2]);
    om
}

/// Right-hand side of the reduced rod (+ variational equations when `VAR`), module docs.
#[inline(always)]
pub(crate) fn rhs<const N: usize, const VAR: bool>(
    ci: &[f64; 3],
    a: &[f64; 6],
    s: &[f64; N],
    ds: &mut [f64; N],
) {
    let (w, x, y, z) = (s[0], s[1], s[2], s[3]);
    let p = [s[4], s[5], s[6]];
    let r = rotmat(w, x, y, z);
    let am = [a[0], a[1], a[2]];
    let af = [a[3], a[4], a[5]];
    let f = rt_mul(&r, af);
    let pxf = cross(p, af);
    let m = rt_mul(&r, [am[0] - pxf[0], am[1] - pxf[1], am[2] - pxf[2]]);
    let om = kinematics(ci, [w, x, y, z], &r, m, ds);
    if !VAR {
        return;
    }
    // The variational block is stored row-major (component r of every column c at
    // NRB + 6 r + c) so that each line below is one operation on 6 columns at once: the loops
    // over c vectorise.
    //
    // g_c = Rᵀ δa_m − Rᵀ (p × δa_f) for δa = e_c, component i: R[c][i] for c < 3, and
    // (p × u_i) for c = 3, 4, 5, where u_i is column i of R.
    let mut g = [[0.0; 6]; 3];
    for (i, gi) in g.iter_mut().enumerate() {
        let u = [r[0][i], r[1][i], r[2][i]];
        let pu = cross(p, u);
        *gi = [u[0], u[1], u[2], pu[0], pu[1], pu[2]];
    }
    let (_, var) = s.split_at(NRB);
    let (_, dvar) = ds.split_at_mut(NRB);
    let row = |k: usize| -> [f64; 6] { std::array::from_fn(|c| var[6 * k + c]) };
    let (e0, e1, e2) = (row(0), row(1), row(2));
    let (v0, v1, v2) = (row(3), row(4), row(5));
    for c in 0..6 {
        // δm = −η_ω × m − η_v × f + g; η_ω' = δm / c − ω × η_ω.
        let c1 = [
            e1[c] * m[2] - e2[c] * m[1],
            e2[c] * m[0] - e0[c] * m[2],
            e0[c] * m[1] - e1[c] * m[0],
        ];
        let c2 = [
            v1[c] * f[2] - v2[c] * f[1],
            v2[c] * f[0] - v0[c] * f[2],
            v0[c] * f[1] - v1[c] * f[0],
        ];
        dvar[c] = (g[0][c] - c1[0] - c2[0]) * ci[0] - (om[1] * e2[c] - om[2] * e1[c]);
        dvar[6 + c] = (g[1][c] - c1[1] - c2[1]) * ci[1] - (om[2] * e0[c] - om[0] * e2[c]);
        dvar[12 + c] = (g[2][c] - c1[2] - c2[2]) * ci[2] - (om[0] * e1[c] - om[1] * e0[c]);
        // η_v' = −ω × η_v + η_ω × e1, with η_ω × e1 = (0, η_ω3, −η_ω2).
        dvar[18 + c] = -(om[1] * v2[c] - om[2] * v1[c]);
        dvar[24 + c] = -(om[2] * v0[c] - om[0] * v2[c]) + e2[c];
        dvar[30 + c] = -(om[0] * v1[c] - om[1] * v0[c]) - e1[c];
    }
}

/// Initial state: q = identity, p = 0, energy 0, η = 0.
pub(crate) fn initial<const N: usize>() -> [f64; N] {
    let mut s = [0.0; N];
    s[0] = 1.0;
    s
}

pub(crate) fn params(a: &SpatialParams) -> [f64; 6] {
    [a[0], a[1], a[2], a[3], a[4], a[5]]
}

/// Pose from a reduced state (quaternion renormalised).
pub(crate) fn pose(s: &[f64]) -> SpatialPose {
    super::pose_from_parts([s[0], s[1], s[2], s[3]], [s[4], s[5], s[6]])
}

/// Entry (r, c) of J in a reduced state (the variational block is row-major).
#[inline(always)]
pub(crate) fn jac_entry(s: &[f64], r: usize, c: usize) -> f64 {
    s[NRB + 6 * r + c]
}

/// J from a reduced state.
pub(crate) fn jac(s: &[f64]) -> SpatialJacobian {
    SpatialJacobian::from_fn(|r, c| jac_entry(s, r, c))
}

/// The reduced rod (with its variational equations when `VAR`) integrated from the base to t:
/// the final state. Compiled twice (see [`crate::simd`]); the AVX2 build where the CPU has it.
pub(crate) fn integrate<const N: usize, const VAR: bool>(
    ci: &[f64; 3],
    a: &[f64; 6],
    t: f64,
    opts: &OdeOptions,
) -> Result<[f64; N], OdeError> {
    crate::simd::pick_build!(
        integrate_avx2::<N, VAR>,
        integrate_baseline::<N, VAR>,
        ci,
        a,
        t,
        opts
    )
}

/// Defines one build of [`integrate`]'s work. The right-hand side's closure must be written
/// inside the function whose target features it is to inherit ([`crate::simd`]), so both
/// builds are generated from this one text.
macro_rules! integrator {
    ($(#[$attr:meta])* fn $name:ident) => {
        $(#[$attr])*
        pub(super) fn $name<const N: usize, const VAR: bool>(
            ci: &[f64; 3],
            a: &[f64; 6],
            t: f64,
            opts: &OdeOptions,
        ) -> Result<[f64; N], OdeError> {
            let f = |_: f64, s: &[f64; N], ds: &mut [f64; N]| rhs::<N, VAR>(ci, a, s, ds);
            Ok(solve(f, 0.0, initial::<N>(), t, opts)?.0)
        }
    };
}

integrator!(
    /// [`integrate`] as the crate is built.
    fn integrate_baseline
);
integrator!(
    /// [`integrate`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn integrate_avx2
);
