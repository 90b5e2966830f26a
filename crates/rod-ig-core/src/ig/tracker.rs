//! Tracking a stream of nearby targets: each solve starts from the previous solution (warm
//! start), so a small target increment costs one or two Newton iterations (quadratic
//! convergence of eq. 3.1 near a regular solution). When the warm start fails (a large jump, or
//! the path leaves the stable workspace), the tracker falls back to the robust solver.
//!
//! Predictor: the previous solve ended with J(1, a_prev) already evaluated at its solution, so
//! the first-order prediction a_prev + J(1, a_prev)⁻¹ (b − b_prev) (the tangent of the solution
//! branch) costs one 3×3 solve and no evaluation. It is not counted as an iteration; the
//! `evaluations` field of [`Solution`] counts every evaluation of Υ and J.

use super::{
    local, model, newton::make_solution, newton::solve3, robust, Failure, Solution, SolveOptions,
};
use crate::{wrap_angle, PlanarJacobian, PlanarParams, PlanarPose};
use nalgebra::Vector3;

/// Warm-started solver for a stream of targets. Every returned solution is stable (FINDINGS §5
/// test) and within the tolerance of its target.
#[derive(Clone, Debug)]
pub struct Tracker {
    options: SolveOptions,
    /// Last solution, its target, and J(1, a) there when known.
    last: Option<(PlanarParams, PlanarPose, Option<PlanarJacobian>)>,
}

/// Largest predictor step accepted (scaled like the trust box of the local solver).
const MAX_PREDICT: f64 = 1.0;

impl Tracker {
    /// A tracker with these options (`method` and `objective` are ignored: tracking follows one
    /// branch; `initial_guess`, if any, is the first warm start).
    pub fn new(options: SolveOptions) -> Self {
        Self {
            options,
            last: None,
        }
    }

    /// Forgets the previous solution (the next solve is a cold robust solve).
    pub fn reset(&mut self) {
        self.last = None;
    }

    /// The last solution's parameters, if any.
    pub fn last(&self) -> Option<PlanarParams> {
        self.last.map(|l| l.0)
    }

    fn predict(&self, target: &PlanarPose) -> Option<PlanarParams> {
        let (a, b, j) = self.last?;
        let j = j?;
        let db = Vector3::new(
            target.x - b.x,
            target.y - b.y,
            wrap_angle(target.theta - b.theta),
        );
        let da = solve3(&j, &db).ok()?;
        let size = (da[0].abs() / 4.0)
            .max(da[1].abs() / 40.0)
            .max(da[2].abs() / 40.0);
        (size <= MAX_PREDICT).then(|| a + da)
    }

    /// Solves for `target`, warm-starting from the previous solution.
    pub fn solve(&mut self, target: &PlanarPose) -> Result<Solution, Failure> {
        let t0 = std::time::Instant::now();
        if let Err(e) = super::check_target(target) {
            let mut f = Failure::early(e);
            f.elapsed_us = t0.elapsed().as_secs_f64() * 1e6;
            return Err(f);
        }
        let warm = self.last.map(|l| l.0).or(self.options.initial_guess);
        let predicted = self.predict(target);
        let mut iterations = 0;
        let mut evaluations = 0;
        let budget = self.options.max_iterations.clamp(1, 20);
        for a0 in [predicted, warm].into_iter().flatten() {
            let r = local::solve(target, &a0, 1.0, budget, self.options.tolerance);
            iterations += r.iterations;
            evaluations += r.evaluations;
            if let Some((a, e)) = r.found {
                if let Ok(st) = model::stability(&a) {
                    if st.stable {
                        let mut s = make_solution(&a, &e, true, st.margin, iterations);
                        s.evaluations = evaluations;
                        s.elapsed_us = t0.elapsed().as_secs_f64() * 1e6;
                        self.last = Some((a, *target, Some(e.jac)));
                        return Ok(s);
                    }
                }
            }
        }
        let mut opts = self.options;
        opts.initial_guess = warm;
        opts.alpha = 1.0;
        match robust::solve(target, &opts) {
            Ok(mut s) => {
                s.iterations += iterations;
                s.evaluations += evaluations;
                s.elapsed_us = t0.elapsed().as_secs_f64() * 1e6;
                self.last = Some((s.a, *target, None));
                Ok(s)
            }
            Err(mut f) => {
                f.iterations += iterations;
                f.elapsed_us = t0.elapsed().as_secs_f64() * 1e6;
                Err(f)
            }
        }
    }
}
