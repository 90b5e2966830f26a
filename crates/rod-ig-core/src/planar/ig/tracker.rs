//! Tracking a stream of nearby targets: each solve starts from the previous solution (warm
//! start), so a small target increment costs one or two Newton iterations (quadratic
//! convergence of eq. 3.1 near a regular solution). When the warm start fails (a large jump, or
//! the path leaves the stable workspace), the tracker falls back to the robust solver.
//!
//! Predictor: the previous solve ended with J(1, a_prev) already evaluated at its solution, so
//! the first Newton step a_prev + J(1, a_prev)⁻¹ (b − b_prev) (the tangent of the solution
//! branch) costs one 3×3 solve and no evaluation. It is counted as an iteration all the same;
//! the `evaluations` field of [`Solution`] counts every evaluation of Υ and J.

use super::{local, newton::make_solution, robust, Failure, Solution, SolveOptions};
use crate::planar::model::{self as model, solve3};
use crate::{wrap_angle, PlanarJacobian, PlanarParams, PlanarPose};
use nalgebra::Vector3;

/// Warm-started solver for a stream of targets. Every returned solution is stable (docs/math.md §5
/// test) and within the tolerance of its target.
#[derive(Clone, Debug)]
pub struct Tracker {
    options: SolveOptions,
    /// Last solution, its target, and J(1, a) there when known.
    last: Option<(PlanarParams, PlanarPose, Option<PlanarJacobian>)>,
    /// The solution and target before it (for the second-order predictor term).
    prev: Option<(PlanarParams, PlanarPose)>,
}

/// Largest predictor step accepted, in units of the local solver's step box
/// (`local::MAX_DA3`, `local::MAX_DA45`): a prediction larger than one step of the solver is
/// no better than a restart.
const MAX_PREDICT: f64 = 1.0;

impl Tracker {
    /// A tracker with these options (`method` and `objective` are ignored: tracking follows one
    /// branch; `initial_guess`, if any, is the first warm start).
    pub fn new(options: SolveOptions) -> Self {
        Self {
            options,
            last: None,
            prev: None,
        }
    }

    /// Forgets the previous solution (the next solve is a cold robust solve).
    pub fn reset(&mut self) {
        self.last = None;
        self.prev = None;
    }

    /// The last solution's parameters, if any.
    pub fn last(&self) -> Option<PlanarParams> {
        self.last.map(|l| l.0)
    }

    /// Predicted solution for `target` on the branch of the last solution: with g the local
    /// inverse of Υ (g' = J⁻¹), g(b + Δ) ≈ g(b) + J⁻¹Δ + ½g''[Δ, Δ]; the second-order term is
    /// estimated from the previous step when the target moves on (nearly) straight: from
    /// g(b_prev) = a_prev, ½g''[Δp, Δp] ≈ a_prev − a + J⁻¹Δp, scaled by ρ² (Δ ≈ ρ Δp).
    /// Returns the prediction and ‖Δ‖ (the residual at the last solution, estimated).
    fn predict(&self, target: &PlanarPose) -> Option<(PlanarParams, f64)> {
        let (a, b, j) = self.last?;
        let j = j?;
        let diff = |p: &PlanarPose, q: &PlanarPose| {
            Vector3::new(p.x - q.x, p.y - q.y, wrap_angle(p.theta - q.theta))
        };
        let db = diff(target, &b);
        let mut da = solve3(&j, &db).ok()?;
        if let Some((ap, bp)) = self.prev {
            let dp = diff(&bp, &b);
            let n2 = dp.norm_squared();
            if n2 > 0.0 {
                let rho = -db.dot(&dp) / n2;
                let cos = -db.dot(&dp) / (db.norm() * n2.sqrt());
                if cos > 0.95 && rho > 0.0 && rho < 2.0 {
                    if let Ok(lin) = solve3(&j, &dp) {
                        let second = ap - a + lin;
                        da += rho * rho * second;
                    }
                }
            }
        }
        let size = (da[0].abs() / local::MAX_DA3)
            .max(da[1].abs() / local::MAX_DA45)
            .max(da[2].abs() / local::MAX_DA45);
        (size <= MAX_PREDICT && da.iter().all(|v| v.is_finite())).then(|| (a + da, db.norm()))
    }

    /// Solves for `target`, warm-starting from the previous solution. The first solve (or the
    /// first after [`Tracker::reset`], without initial guess) is a cold start that picks, among
    /// the distinct stable solutions found near the target, the one with the best-conditioned
    /// J(1, a) (slower, ~1 ms, but the branch then tracks well).
    pub fn solve(&mut self, target: &PlanarPose) -> Result<Solution, Failure> {
        let t0 = std::time::Instant::now();
        let mut result = self.solve_untimed(target);
        let us = t0.elapsed().as_secs_f64() * 1e6;
        match &mut result {
            Ok(s) => s.elapsed_us = us,
            Err(f) => f.elapsed_us = us,
        }
        result
    }

    fn solve_untimed(&mut self, target: &PlanarPose) -> Result<Solution, Failure> {
        let _deadline = crate::deadline::scope(self.options.deadline);
        super::check_target(target).map_err(Failure::early)?;
        // The angle reduced exactly (as every entry point does, `RodModel::canonical_target`).
        let target = &PlanarPose::new(target.x, target.y, wrap_angle(target.theta));
        let warm = self.last.map(|l| l.0).or(self.options.initial_guess);
        let (mut iterations, mut evaluations) = (0, 0);
        if let Some(a0) = warm {
            match self.warm_step(target, &a0) {
                Ok(s) => return Ok(s),
                Err((it, ev)) => (iterations, evaluations) = (it, ev),
            }
        }
        let mut opts = self.options;
        opts.initial_guess = warm;
        opts.alpha = 1.0;
        if warm.is_none() {
            if let Some(s) = self.cold_start(target, &opts) {
                return Ok(s);
            }
        }
        match robust::solve(target, &opts) {
            Ok(mut s) => {
                s.iterations += iterations;
                s.evaluations += evaluations;
                self.prev = None;
                self.last = Some((s.a, *target, None));
                Ok(s)
            }
            Err(mut f) => {
                f.iterations += iterations;
                Err(f)
            }
        }
    }

    /// The warm start: a few Newton iterations from `a0` (with the predicted first step),
    /// verified and tested for stability. `Err((iterations, evaluations))` when it fails.
    fn warm_step(
        &mut self,
        target: &PlanarPose,
        a0: &PlanarParams,
    ) -> Result<Solution, (u32, u32)> {
        let predicted = self.predict(target);
        let budget = self.options.max_iterations.clamp(1, 20);
        let tolerance = self.options.tolerance;
        let r = local::solve_predicted(target, a0, predicted, 1.0, budget, tolerance);
        let work = (r.iterations, r.evaluations);
        let (a, _) = r.found.ok_or(work)?;
        // One evaluation (one closed form) gives the tip, J, the energy and the stability
        // test; separate calls built the form three times.
        let (e, st) = super::newton::verify_with_stability(&a, target, tolerance)
            .filter(|(_, st)| st.stable)
            .ok_or(work)?;
        let mut s = make_solution(&a, &e, true, st.margin, r.iterations);
        s.evaluations = r.evaluations;
        self.prev = self.last.map(|l| (l.0, l.1));
        self.last = Some((a, *target, Some(e.jac)));
        Ok(s)
    }

    /// Cold start: among the stable solutions near the target, the best conditioned J(1, a)
    /// (largest σ_min/σ_max): far from the fold det J(1, a) = 0 and from the separatrix
    /// λ4 = 0, where branches end or Newton's basin shrinks, so the branch followed afterwards
    /// is the easiest to track.
    fn cold_start(&mut self, target: &PlanarPose, opts: &SolveOptions) -> Option<Solution> {
        let all = robust::solve_all(target, opts, Some(opts.max_iterations));
        let conditioning = |a: &PlanarParams| {
            model::tip_and_jacobian_for_iteration(a, model::Precision::Fast)
                .ok()
                .map(|(_, j)| {
                    let sv = j.singular_values();
                    sv.min() / sv.max()
                })
                .filter(|c| c.is_finite())
                .unwrap_or(0.0)
        };
        let mut s = all
            .solutions
            .into_iter()
            .max_by(|p, q| conditioning(&p.a).total_cmp(&conditioning(&q.a)))?;
        s.iterations = all.iterations;
        s.evaluations = all.evaluations;
        s.starts = all.starts;
        self.prev = None;
        self.last = Some((s.a, *target, None));
        Some(s)
    }
}
