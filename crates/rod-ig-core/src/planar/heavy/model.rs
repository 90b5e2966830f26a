//! The heavy planar rod as a model of the solvers ([`RodModel`], [`InverseGeometry`]).
//!
//! Its robust search starts from the weightless rods that reach the target (the closed
//! forms' atlas and search, exact at w = 0) and follows each to the rod's weight by the
//! continuation in load of [`crate::solver::load`] (the shared load a + (0, w ĝ/2) first, exact
//! for a level rod). Every returned rod passed the heavy rod's stability test.

use super::cable_search::{self, Admission, LONG_CABLE_WEIGHT};
use super::{Gravity, HeavyEvaluation};
use crate::planar::ig::SolveOptions;
use crate::planar::model::PlanarClosedForm;

use crate::solver::load::{self, LoadedModel};
use crate::solver::{
    Failure, Found, IgError, InverseGeometry, ModelEvaluation, Objective, RodModel, Solution,
};
use crate::{PlanarJacobian, PlanarParams, PlanarPose, RodError};
use nalgebra::{SMatrix, Vector3};

/// The planar rod under its own weight ([`super`]): with [`Gravity::NONE`] it is
/// [`PlanarClosedForm`] exactly.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeavyPlanar {
    /// Weight and direction of gravity.
    pub gravity: Gravity,
}

impl HeavyPlanar {
    /// The model for `gravity`.
    pub fn new(gravity: Gravity) -> Self {
        Self { gravity }
    }

    /// Every stable rod the single-shooting search finds (the search below
    /// [`LONG_CABLE_WEIGHT`], at any weight): a start of the long-cable search a little above
    /// that weight, where single shooting still keeps a few digits.
    pub(crate) fn single_shooting_all(
        &self,
        target: &PlanarPose,
        options: &SolveOptions,
    ) -> Found<PlanarParams, PlanarPose> {
        let starts = weightless_starts(target, options);
        load::every(
            &HeavyPlanar::new(Gravity::NONE),
            self,
            target,
            options,
            starts,
        )
    }

    /// True when the rod is solved by multiple shooting (w > [`LONG_CABLE_WEIGHT`]).
    pub fn is_long_cable(&self) -> bool {
        self.gravity.weight() > LONG_CABLE_WEIGHT
    }

    /// Tip, J, energies and stability ([`super::evaluate`]).
    pub fn evaluate_heavy(&self, a: &PlanarParams) -> Result<HeavyEvaluation, RodError> {
        super::evaluate(a, &self.gravity)
    }
}

impl RodModel<3> for HeavyPlanar {
    type Pose = PlanarPose;

    fn name(&self) -> &'static str {
        "planar rod with weight"
    }

    fn tip(&self, a: &Vector3<f64>) -> Result<PlanarPose, RodError> {
        super::tip(a, &self.gravity)
    }

    fn evaluate(&self, a: &Vector3<f64>) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
        let e = super::evaluate(a, &self.gravity)?;
        Ok(ModelEvaluation {
            tip: e.tip,
            jacobian: e.jacobian,
            energy: e.energy,
            stability: e.stability,
            full_accuracy: true,
        })
    }

    fn tip_and_jacobian(&self, a: &Vector3<f64>) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        super::tip_and_jacobian(a, &self.gravity)
    }

    // Without weight, every method is the closed forms' (their cheaper evaluations included),
    // so that a follower of this model answers as one of `PlanarClosedForm` does.

    fn tip_and_jacobian_for_substep(
        &self,
        a: &Vector3<f64>,
    ) -> Result<(PlanarPose, PlanarJacobian), RodError> {
        if self.gravity.is_weightless() {
            return PlanarClosedForm.tip_and_jacobian_for_substep(a);
        }
        self.tip_and_jacobian(a)
    }

    fn evaluate_iterate(
        &self,
        a: &Vector3<f64>,
        start: &Vector3<f64>,
    ) -> Result<ModelEvaluation<3, PlanarPose>, RodError> {
        if self.gravity.is_weightless() {
            return PlanarClosedForm.evaluate_iterate(a, start);
        }
        self.evaluate(a)
    }

    fn stability(&self, a: &Vector3<f64>) -> Result<crate::StabilityReport, RodError> {
        if self.gravity.is_weightless() {
            return PlanarClosedForm.stability(a);
        }
        Ok(self.evaluate(a)?.stability)
    }

    fn energy(&self, a: &Vector3<f64>) -> Result<f64, RodError> {
        Ok(super::energy(a, &self.gravity)?.0)
    }

    fn param_scale(&self) -> Vector3<f64> {
        PlanarClosedForm.param_scale()
    }

    /// Straight along its force and along gravity (ĝ along the base tangent, or no weight).
    fn is_straight(&self, a: &Vector3<f64>) -> bool {
        PlanarClosedForm.is_straight(a)
            && (self.gravity.is_weightless() || self.gravity.direction()[1] == 0.0)
    }

    fn pose_error(&self, tip: &PlanarPose, target: &PlanarPose) -> (f64, f64) {
        PlanarClosedForm.pose_error(tip, target)
    }

    fn newton_increment(
        &self,
        tip: &PlanarPose,
        jacobian: &SMatrix<f64, 3, 3>,
        target: &PlanarPose,
    ) -> Result<Vector3<f64>, f64> {
        PlanarClosedForm.newton_increment(tip, jacobian, target)
    }

    /// A long cable's branch is followed on its node states ([`cable_search::branch_step`]).
    fn branch_step(
        &self,
        from: &PlanarParams,
        goal: &PlanarPose,
        tolerance: f64,
    ) -> Option<Option<(PlanarParams, PlanarPose, PlanarJacobian)>> {
        if !self.is_long_cable() {
            return None;
        }
        Some(cable_search::branch_step(
            from,
            &self.gravity,
            goal,
            tolerance,
        ))
    }

    fn check_target(&self, target: &PlanarPose) -> Result<(), IgError> {
        PlanarClosedForm.check_target(target)
    }

    fn canonical_target(&self, target: &PlanarPose) -> PlanarPose {
        PlanarClosedForm.canonical_target(target)
    }

    fn jacobian_det(&self, jacobian: &SMatrix<f64, 3, 3>) -> f64 {
        jacobian.determinant()
    }

    fn interpolate(&self, from: &PlanarPose, to: &PlanarPose, s: f64) -> PlanarPose {
        PlanarClosedForm.interpolate(from, to, s)
    }
}

impl LoadedModel<3> for HeavyPlanar {
    fn blend(&self, from: &Self, s: f64) -> Result<Self, RodError> {
        let (l0, l1) = (from.gravity.load(), self.gravity.load());
        let load = [l0[0] + (l1[0] - l0[0]) * s, l0[1] + (l1[1] - l0[1]) * s];
        Ok(Self::new(Gravity::from_load(
            load,
            self.gravity.direction(),
        )?))
    }

    fn load_change(&self, from: &Self) -> f64 {
        let (l0, l1) = (from.gravity.load(), self.gravity.load());
        (l1[0] - l0[0]).hypot(l1[1] - l0[1])
    }

    fn shared_load_step(&self, from: &Self) -> Vector3<f64> {
        let (l0, l1) = (from.gravity.load(), self.gravity.load());
        Vector3::new(0.0, 0.5 * (l1[0] - l0[0]), 0.5 * (l1[1] - l0[1]))
    }
}

/// Carries the stable rod `a`, which holds the tip gripper at `gripper` under gravity `from`, to
/// gravity `to` with the gripper fixed: the equilibrium branch followed as the weight or the
/// direction of gravity changes (the base gripper turning; [`crate::solver::load::carry`]).
/// The rod returned passed the stability test under `to`. Fails where the branch folds or
/// loses stability on the way (the rod would snap), or on the deadline of `options`.
pub fn carry(
    a: &PlanarParams,
    from: &Gravity,
    to: &Gravity,
    gripper: &PlanarPose,
    options: &SolveOptions,
) -> Result<Solution<PlanarParams, PlanarPose>, Failure<PlanarParams>> {
    if from.weight().max(to.weight()) > LONG_CABLE_WEIGHT {
        return cable_search::carry(a, from, to, gripper, options);
    }
    load::carry(
        &HeavyPlanar::new(*from),
        &HeavyPlanar::new(*to),
        a,
        gripper,
        options,
    )
}

/// The weightless rods the search starts from, in order: the caller's guess, the weightless
/// robust search's first rod (one call of a few µs), then, only when `all` or when those fail,
/// every stable weightless solution (least energy first).
struct Starts<'a> {
    target: &'a PlanarPose,
    options: &'a SolveOptions,
    queue: Vec<PlanarParams>,
    stage: u8,
}

impl Iterator for Starts<'_> {
    type Item = PlanarParams;
    fn next(&mut self) -> Option<PlanarParams> {
        while self.queue.is_empty() && self.stage < 3 {
            self.stage += 1;
            match self.stage {
                1 => self.queue.extend(self.options.initial_guess),
                2 => self.queue.extend(
                    PlanarClosedForm
                        .robust(self.target, self.options)
                        .map(|s| s.a),
                ),
                _ => {
                    let mut sols = PlanarClosedForm
                        .robust_all(self.target, self.options)
                        .solutions;
                    sols.sort_by(|a, b| b.energy.total_cmp(&a.energy));
                    self.queue.extend(sols.into_iter().map(|s| s.a));
                }
            }
        }
        self.queue.pop()
    }
}

fn weightless_starts<'a>(target: &'a PlanarPose, options: &'a SolveOptions) -> Starts<'a> {
    Starts {
        target,
        options,
        queue: Vec::new(),
        stage: 0,
    }
}

impl InverseGeometry<3> for HeavyPlanar {
    fn robust(
        &self,
        target: &PlanarPose,
        options: &SolveOptions,
    ) -> Result<Solution<PlanarParams, PlanarPose>, Failure<PlanarParams>> {
        if self.gravity.is_weightless() {
            return PlanarClosedForm.robust(target, options);
        }
        if self.is_long_cable() {
            let admission = Admission::of(options);
            let found = cable_search::search(target, &self.gravity, options, admission);
            return match found.solutions.first() {
                Some(s) => Ok(cable_search::solution_of(s, target, &found)),
                None => Err(cable_search::failure_of(&found, admission)),
            };
        }
        let starts = weightless_starts(target, options);
        load::first(
            &HeavyPlanar::new(Gravity::NONE),
            self,
            target,
            options,
            starts,
        )
    }

    fn robust_all(
        &self,
        target: &PlanarPose,
        options: &SolveOptions,
    ) -> Found<PlanarParams, PlanarPose> {
        if self.gravity.is_weightless() {
            return PlanarClosedForm.robust_all(target, options);
        }
        if self.is_long_cable() {
            let all = SolveOptions {
                objective: Objective::LeastEnergy,
                ..*options
            };
            let found = cable_search::search(target, &self.gravity, &all, Admission::of(options));
            let work: u32 = found.solutions.iter().map(|s| s.iterations).sum();
            return Found {
                solutions: found
                    .solutions
                    .iter()
                    .map(|s| cable_search::solution_of(s, target, &found))
                    .collect(),
                iterations: work,
                evaluations: work,
                starts: found.starts,
            };
        }
        self.single_shooting_all(target, options)
    }

    /// Above w = 200 the Newton iterates on the node states of the multiple-shooting
    /// formulation from the cable `a0` integrates to (single shooting from an f64 `a0` loses
    /// its digits there), and the answer must pass the same admission as the search's.
    fn newton(
        &self,
        target: &PlanarPose,
        a0: &PlanarParams,
        options: &SolveOptions,
    ) -> Result<Solution<PlanarParams, PlanarPose>, Failure<PlanarParams>> {
        if !self.is_long_cable() {
            return crate::solver::newton_solve(self, target, a0, options);
        }
        cable_search::newton(target, &self.gravity, a0, options)
    }

    fn default_start(&self, target: &PlanarPose) -> Option<PlanarParams> {
        let a = PlanarClosedForm.default_start(target)?;
        Some(a + self.shared_load_step(&HeavyPlanar::new(Gravity::NONE)))
    }
}
