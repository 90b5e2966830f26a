//! Tracking a stream of nearby targets: each solve starts from the previous solution (warm
//! start), so a small target increment costs one or two Newton iterations (quadratic
//! convergence of eq. 3.1 near a regular solution). When the warm start fails (a large jump, or
//! the path leaves the stable workspace), the tracker falls back to the robust solver.

use super::{local, model, newton::make_solution, robust, Failure, Solution, SolveOptions};
use crate::{PlanarParams, PlanarPose};

/// Warm-started solver for a stream of targets. Every returned solution is stable (FINDINGS §5
/// test) and within the tolerance of its target.
#[derive(Clone, Debug)]
pub struct Tracker {
    options: SolveOptions,
    last: Option<(PlanarParams, PlanarPose)>,
    prev: Option<(PlanarParams, PlanarPose)>,
}

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

    /// Solves for `target`, warm-starting from the previous solution.
    pub fn solve(&mut self, target: &PlanarPose) -> Result<Solution, Failure> {
        let t0 = std::time::Instant::now();
        if let Err(e) = super::check_target(target) {
            let mut f = Failure::early(e);
            f.elapsed_us = t0.elapsed().as_secs_f64() * 1e6;
            return Err(f);
        }
        let warm = self.last.map(|l| l.0).or(self.options.initial_guess);
        let mut iterations = 0;
        if let Some(a0) = warm {
            let budget = self.options.max_iterations.clamp(1, 20);
            let r = local::solve(target, &a0, 1.0, budget, self.options.tolerance);
            iterations += r.iterations;
            if let Some((a, e)) = r.found {
                if let Ok(st) = model::stability(&a) {
                    if st.stable {
                        let mut s = make_solution(&a, &e, true, st.margin, iterations);
                        s.elapsed_us = t0.elapsed().as_secs_f64() * 1e6;
                        self.prev = self.last;
                        self.last = Some((a, *target));
                        return Ok(s);
                    }
                }
            }
        }
        let mut opts = self.options;
        opts.initial_guess = warm;
        opts.alpha = 1.0;
        let r = robust::solve(target, &opts);
        match r {
            Ok(mut s) => {
                s.iterations += iterations;
                s.elapsed_us = t0.elapsed().as_secs_f64() * 1e6;
                self.prev = self.last;
                self.last = Some((s.a, *target));
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
