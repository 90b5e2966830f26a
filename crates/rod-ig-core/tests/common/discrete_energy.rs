//! An independent reference for the heavy planar rod: the discretised energy minimised with
//! both ends clamped (issue 41, item 5). No shooting, no ODE: the rod is N straight segments
//! of length h = 1/N with tangent angles φ_1..φ_N.
//!
//! * Bending energy (second-order accurate; the clamped tangents θ(0) = 0 and θ(1) = θ* are
//!   h/2 from the first and last segment's middle):
//!   E_b = φ_1²/h + Σ_{i<N} (φ_{i+1} − φ_i)²/(2h) + (θ* − φ_N)²/h.
//! * Potential w ∫(−ĝ·r) dt, exact for the polygon: Σ_i h (−ĝ · r(t_{i−1/2})).
//! * Constraints: the tip at p*: Σ_i h (cos φ_i, sin φ_i) = p*.
//!
//! Newton on the KKT system ∇E = λ·∇c, c = 0. The multiplier λ is the force the tip gripper
//! exerts, n(1); so n(0) = λ + w ĝ (a4, a5). The base moment a3 comes from the moment balance
//! m(0) = m(t₁) + ∫₀^{t₁} (cos θ n_y − sin θ n_x) dt at the first node (both second order).
//! Richardson in N removes the h² term. Stability: the smallest eigenvalue of the Hessian of
//! the Lagrangian on the constraints' tangent space, divided by h (continuum units).

use nalgebra::{DMatrix, DVector};

/// The discrete solution at one N.
#[derive(Clone, Debug)]
pub struct Discrete {
    /// (a3, a4, a5).
    pub a: [f64; 3],
    /// Smallest eigenvalue of the projected Hessian (continuum units).
    pub min_eig: f64,
    /// Total energy.
    pub energy: f64,
}

/// The problem: weight w along unit ĝ, tip target (x, y, θ).
#[derive(Clone, Copy, Debug)]
pub struct Problem {
    pub weight: f64,
    pub direction: [f64; 2],
    pub target: [f64; 3],
}

impl Problem {
    /// Energy gradient and Hessian in φ (bending + potential).
    fn energy_derivatives(&self, phi: &[f64]) -> (f64, DVector<f64>, DMatrix<f64>) {
        let n = phi.len();
        let h = 1.0 / n as f64;
        let (w, g) = (self.weight, self.direction);
        let mut e = 0.0;
        let mut grad = DVector::zeros(n);
        let mut hess = DMatrix::zeros(n, n);
        // Bending: differences d_k with weights c_k (1/h at the ends, 1/(2h) inside).
        let mut add = |i: Option<usize>, j: Option<usize>, fixed: f64, c: f64| {
            // d = (φ_j or fixed) − (φ_i or 0)
            let vi = i.map_or(0.0, |i| phi[i]);
            let vj = j.map_or(fixed, |j| phi[j]);
            let d = vj - vi;
            e += c * d * d;
            if let Some(j) = j {
                grad[j] += 2.0 * c * d;
                hess[(j, j)] += 2.0 * c;
            }
            if let Some(i) = i {
                grad[i] -= 2.0 * c * d;
                hess[(i, i)] += 2.0 * c;
            }
            if let (Some(i), Some(j)) = (i, j) {
                hess[(i, j)] -= 2.0 * c;
                hess[(j, i)] -= 2.0 * c;
            }
        };
        add(None, Some(0), 0.0, 1.0 / h);
        for i in 0..n - 1 {
            add(Some(i), Some(i + 1), 0.0, 0.5 / h);
        }
        add(Some(n - 1), None, self.target[2], 1.0 / h);
        // Potential: Σ_i h (−ĝ · r_i), r_i = Σ_{j<i} h e_j + (h/2) e_i; −ĝ·e_j = −(g_x c_j + g_y s_j).
        // d/dφ_j of −ĝ·e_j = g_x s_j − g_y c_j; its weight is h · (h (N − 1 − j) + h/2).
        for j in 0..n {
            let (s, c) = phi[j].sin_cos();
            let weight = w * h * (h * (n - 1 - j) as f64 + 0.5 * h);
            e += weight * -(g[0] * c + g[1] * s);
            grad[j] += weight * (g[0] * s - g[1] * c);
            hess[(j, j)] += weight * (g[0] * c + g[1] * s);
        }
        (e, grad, hess)
    }

    /// Newton on the KKT system from `phi0`, `lambda0`.
    pub fn solve(&self, phi0: &[f64], lambda0: [f64; 2]) -> Option<Discrete> {
        let n = phi0.len();
        let h = 1.0 / n as f64;
        let mut phi = phi0.to_vec();
        let mut lambda = lambda0;
        for _ in 0..60 {
            let (_, grad, hess) = self.energy_derivatives(&phi);
            let mut k = DMatrix::zeros(n + 2, n + 2);
            let mut r = DVector::zeros(n + 2);
            let (mut cx, mut cy) = (-self.target[0], -self.target[1]);
            for i in 0..n {
                let (s, c) = phi[i].sin_cos();
                cx += h * c;
                cy += h * s;
                // ∇E − λ·∇c, ∇c_x = −h s, ∇c_y = h c.
                r[i] = grad[i] - (lambda[0] * (-h * s) + lambda[1] * (h * c));
                for j in 0..n {
                    k[(i, j)] = hess[(i, j)];
                }
                k[(i, i)] -= lambda[0] * (-h * c) + lambda[1] * (-h * s);
                k[(i, n)] = h * s;
                k[(i, n + 1)] = -h * c;
                k[(n, i)] = -h * s;
                k[(n + 1, i)] = h * c;
            }
            r[n] = cx;
            r[n + 1] = cy;
            let step = k.lu().solve(&(-&r))?;
            for i in 0..n {
                phi[i] += step[i];
            }
            lambda[0] += step[n];
            lambda[1] += step[n + 1];
            if step.amax() < 1e-13 * (1.0 + lambda[0].abs() + lambda[1].abs()) {
                return Some(self.finish(phi, lambda));
            }
        }
        None
    }

    fn finish(&self, phi: Vec<f64>, lambda: [f64; 2]) -> Discrete {
        let n = phi.len();
        let h = 1.0 / n as f64;
        let (energy, _, hess) = self.energy_derivatives(&phi);
        let load = [
            self.weight * self.direction[0],
            self.weight * self.direction[1],
        ];
        let n0 = [lambda[0] + load[0], lambda[1] + load[1]];
        let force = |t: f64| [n0[0] - t * load[0], n0[1] - t * load[1]];
        let f = force(0.5 * h);
        let (s, c) = phi[0].sin_cos();
        let a3 = (phi[1] - phi[0]) / h + h * (c * f[1] - s * f[0]);
        // Projected Hessian of the Lagrangian: H − Σ λ_k ∇²c_k, on the null space of ∇c.
        let mut lag = hess;
        let mut cmat = DMatrix::zeros(2, n);
        for i in 0..n {
            let (s, c) = phi[i].sin_cos();
            lag[(i, i)] -= lambda[0] * (-h * c) + lambda[1] * (-h * s);
            cmat[(0, i)] = -h * s;
            cmat[(1, i)] = h * c;
        }
        let cct = &cmat * cmat.transpose();
        let proj = DMatrix::identity(n, n)
            - cmat.transpose() * cct.try_inverse().expect("independent constraints") * &cmat;
        let shift = 1e3 * lag.amax();
        let m = &proj * &lag * &proj + (DMatrix::identity(n, n) - &proj) * shift;
        let eig = m.symmetric_eigen().eigenvalues.min() / h;
        Discrete {
            a: [a3, n0[0], n0[1]],
            min_eig: eig,
            energy,
        }
    }
}

/// The angles of a shape at the segments' middles, from a sampler of θ(t).
pub fn angles(n: usize, theta: impl Fn(f64) -> f64) -> Vec<f64> {
    (0..n).map(|i| theta((i as f64 + 0.5) / n as f64)).collect()
}

/// Richardson extrapolation of an O(h²) quantity from N and 2N.
pub fn richardson(coarse: f64, fine: f64) -> f64 {
    fine + (fine - coarse) / 3.0
}
