//! The 3-D rod with weight as a model of the solvers: [`RodModel`], the continuation in load
//! ([`LoadedModel`]) and its search ([`InverseGeometry`]), which starts from the weightless
//! 3-D rods that reach the target (the 3-D robust search) and follows each to the weight.

use super::cable_search::{self, PlanarReduction};
use super::heavy::{self, Gravity3};
use super::{Spatial, SpatialParams, SpatialPose, Stiffness};
use crate::solver::load::{self, LoadedModel};
use crate::solver::{
    relative_distance, Failure, Found, IgError, InverseGeometry, ModelEvaluation, RodModel,
    Solution, SolveOptions, DISTINCT,
};
use crate::RodError;
use nalgebra::{SMatrix, SVector};

/// The 3-D rod with stiffnesses `stiffness` under `gravity` ([`super::heavy`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeavySpatial {
    /// Torsion and bending stiffnesses.
    pub stiffness: Stiffness,
    /// Weight and direction of gravity.
    pub gravity: Gravity3,
}

impl HeavySpatial {
    /// The weightless rod of the same stiffness, through the heavy integration.
    fn weightless(&self) -> Self {
        Self {
            gravity: Gravity3::NONE,
            ..*self
        }
    }

    /// True when single shooting from the base loses its digits (w above
    /// [`crate::planar::heavy::cable_search::LONG_CABLE_WEIGHT`], as for the planar rod): the
    /// search keeps to the nearest planar problem's rods (module `spatial::cable_search`).
    pub fn is_long_cable(&self) -> bool {
        self.gravity.weight() > crate::planar::heavy::cable_search::LONG_CABLE_WEIGHT
    }

    fn spatial(&self) -> Spatial {
        Spatial::with_stiffness(self.stiffness)
    }
}

type Options6 = SolveOptions<SVector<f64, 6>>;

impl RodModel<6> for HeavySpatial {
    type Pose = SpatialPose;

    fn name(&self) -> &'static str {
        "3-D rod with weight"
    }

    // Without weight every evaluation and search is the weightless model's, so that weight 0
    // and no weight answer bit for bit alike (issue 51, item 5).

    fn tip(&self, a: &SpatialParams) -> Result<SpatialPose, RodError> {
        if self.gravity.is_weightless() {
            return self.spatial().tip(a);
        }
        Ok(heavy::tip_and_jacobian(a, &self.stiffness, &self.gravity)?.0)
    }

    fn evaluate(&self, a: &SpatialParams) -> Result<ModelEvaluation<6, SpatialPose>, RodError> {
        if self.gravity.is_weightless() {
            return self.spatial().evaluate(a);
        }
        let e = heavy::evaluate(a, &self.stiffness, &self.gravity)?;
        Ok(ModelEvaluation {
            tip: e.tip,
            jacobian: e.jacobian,
            energy: e.energy,
            stability: e.stability,
            full_accuracy: true,
        })
    }

    fn tip_and_jacobian(
        &self,
        a: &SpatialParams,
    ) -> Result<(SpatialPose, SMatrix<f64, 6, 6>), RodError> {
        if self.gravity.is_weightless() {
            return self.spatial().tip_and_jacobian(a);
        }
        heavy::tip_and_jacobian(a, &self.stiffness, &self.gravity)
    }

    fn tip_and_jacobian_for_substep(
        &self,
        a: &SpatialParams,
    ) -> Result<(SpatialPose, SMatrix<f64, 6, 6>), RodError> {
        if self.gravity.is_weightless() {
            return self.spatial().tip_and_jacobian_for_substep(a);
        }
        self.tip_and_jacobian(a)
    }

    fn evaluate_iterate(
        &self,
        a: &SpatialParams,
        start: &SpatialParams,
    ) -> Result<ModelEvaluation<6, SpatialPose>, RodError> {
        if self.gravity.is_weightless() {
            return self.spatial().evaluate_iterate(a, start);
        }
        self.evaluate(a)
    }

    fn stability(&self, a: &SpatialParams) -> Result<crate::StabilityReport, RodError> {
        if self.gravity.is_weightless() {
            return self.spatial().stability(a);
        }
        Ok(self.evaluate(a)?.stability)
    }

    fn energy(&self, a: &SpatialParams) -> Result<f64, RodError> {
        if self.gravity.is_weightless() {
            return self.spatial().energy(a);
        }
        Ok(self.evaluate(a)?.energy)
    }

    fn is_straight(&self, a: &SpatialParams) -> bool {
        self.gravity.is_weightless() && self.spatial().is_straight(a)
    }

    fn param_scale(&self) -> SVector<f64, 6> {
        self.spatial().param_scale()
    }

    fn pose_error(&self, tip: &SpatialPose, target: &SpatialPose) -> (f64, f64) {
        self.spatial().pose_error(tip, target)
    }

    fn newton_increment(
        &self,
        tip: &SpatialPose,
        jacobian: &SMatrix<f64, 6, 6>,
        target: &SpatialPose,
    ) -> Result<SVector<f64, 6>, f64> {
        self.spatial().newton_increment(tip, jacobian, target)
    }

    fn check_target(&self, target: &SpatialPose) -> Result<(), IgError> {
        self.spatial().check_target(target)
    }

    fn jacobian_det(&self, jacobian: &SMatrix<f64, 6, 6>) -> f64 {
        jacobian.determinant()
    }

    fn interpolate(&self, from: &SpatialPose, to: &SpatialPose, s: f64) -> SpatialPose {
        self.spatial().interpolate(from, to, s)
    }

    fn check_settings(&self) -> Result<(), IgError> {
        self.spatial().check_settings()
    }

    /// A long cable's branch is followed on its node states
    /// (`SpatialCable::branch_to`) when the rod held is one a solver returned.
    fn branch_step(
        &self,
        from: &SpatialParams,
        goal: &SpatialPose,
        tolerance: f64,
    ) -> Option<Option<(SpatialParams, SpatialPose, SMatrix<f64, 6, 6>)>> {
        if !self.is_long_cable() {
            return None;
        }
        let cable = super::cable::recall(from, &self.stiffness, &self.gravity)?;
        Some(cable_search::branch_step(&cable, goal, tolerance))
    }
}

/// Carries the stable rod `a`, which holds the tip gripper at `gripper` under gravity `from`,
/// to `to`'s gravity with the gripper fixed (the 3-D twin of
/// [`crate::planar::heavy::carry`]): by the continuation in load on single shooting
/// ([`load::carry`]) while both weights are at most 200, else on the cable's node states
/// ([`super::cable::SpatialCable::carry_load`]). The rod returned passed the stability test
/// under `to`; fails where the branch folds or loses stability on the way (the rod would
/// snap), or on the deadline of `options`.
pub fn carry(
    a: &SpatialParams,
    from: &HeavySpatial,
    to: &HeavySpatial,
    gripper: &SpatialPose,
    options: &Options6,
) -> Result<Solution<SpatialParams, SpatialPose>, Failure<SpatialParams>> {
    if from.stiffness != to.stiffness {
        return Err(Failure::early(IgError::InvalidOptions(
            "a carried rod keeps its stiffness".into(),
        )));
    }
    if !(from.is_long_cable() || to.is_long_cable()) {
        return load::carry(from, to, a, gripper, options);
    }
    cable_search::carry(
        (&to.stiffness, &to.gravity),
        a,
        &from.gravity,
        gripper,
        options,
    )
}

impl LoadedModel<6> for HeavySpatial {
    fn blend(&self, from: &Self, s: f64) -> Result<Self, RodError> {
        let (l0, l1) = (from.gravity.load(), self.gravity.load());
        let load = std::array::from_fn(|i| l0[i] + (l1[i] - l0[i]) * s);
        Ok(Self {
            gravity: Gravity3::from_load(load, self.gravity.direction())?,
            ..*self
        })
    }

    fn load_change(&self, from: &Self) -> f64 {
        let (l0, l1) = (from.gravity.load(), self.gravity.load());
        (0..3).map(|i| (l1[i] - l0[i]).powi(2)).sum::<f64>().sqrt()
    }

    fn shared_load_step(&self, from: &Self) -> SVector<f64, 6> {
        let (l0, l1) = (from.gravity.load(), self.gravity.load());
        let h: [f64; 3] = std::array::from_fn(|i| 0.5 * (l1[i] - l0[i]));
        SVector::<f64, 6>::new(0.0, 0.0, 0.0, h[0], h[1], h[2])
    }
}

/// The weightless 3-D rods on target: the caller's guess, the robust search's first rod, then
/// every stable weightless solution (least energy first), each asked only when needed.
fn weightless_starts<'a>(
    spatial: Spatial,
    target: &'a SpatialPose,
    options: &'a Options6,
) -> impl Iterator<Item = SpatialParams> + 'a {
    let guess = options.initial_guess.into_iter();
    let first =
        std::iter::once_with(move || spatial.robust(target, options).ok().map(|s| s.a)).flatten();
    let every = std::iter::once_with(move || {
        let mut sols = spatial.robust_all(target, options).solutions;
        sols.sort_by(|a, b| a.energy.total_cmp(&b.energy));
        sols.into_iter().map(|s| s.a)
    })
    .flatten();
    guess.chain(first).chain(every)
}

impl InverseGeometry<6> for HeavySpatial {
    fn robust(
        &self,
        target: &SpatialPose,
        options: &Options6,
    ) -> Result<Solution<SpatialParams, SpatialPose>, Failure<SpatialParams>> {
        if self.gravity.is_weightless() {
            return self.spatial().robust(target, options);
        }
        // The caller's guess at the full weight; then the planar rods where they reach the
        // target exactly (the symmetric targets among them); then, for a long cable, the
        // planar problem nearest to the target carried to it, and otherwise the weightless
        // 3-D rods carried in load first (fast where single shooting keeps its digits) and
        // the nearest planar problem last.
        if let Some(a0) = options.initial_guess {
            if let Ok(s) = cable_search::from_guess((&self.stiffness, &self.gravity), &a0, target) {
                return Ok(s);
            }
        }
        let rod = (&self.stiffness, &self.gravity);
        let reduction = PlanarReduction::nearest(target, &self.stiffness, &self.gravity);
        let exact = reduction.as_ref().is_some_and(|r| r.is_exact_for(target));
        let planar = |r: &PlanarReduction| cable_search::first(rod, r, target, options);
        if let Some(r) = reduction.as_ref().filter(|_| exact || self.is_long_cable()) {
            if let Some(s) = planar(r) {
                return Ok(s);
            }
        }
        let starts = weightless_starts(self.spatial(), target, options);
        let carried = load::first(&self.weightless(), self, target, options, starts);
        match (carried, &reduction) {
            (Err(f), Some(r)) if !exact && !self.is_long_cable() && !crate::deadline::expired() => {
                planar(r).ok_or(f)
            }
            (other, _) => other,
        }
    }

    fn robust_all(
        &self,
        target: &SpatialPose,
        options: &Options6,
    ) -> Found<SpatialParams, SpatialPose> {
        if self.gravity.is_weightless() {
            return self.spatial().robust_all(target, options);
        }
        // The nearest planar problem for a long cable; below, only where it is exact (the
        // weightless rods carried in load are faster there).
        let mut found = PlanarReduction::nearest(target, &self.stiffness, &self.gravity)
            .filter(|r| self.is_long_cable() || r.is_exact_for(target))
            .map(|r| cable_search::all((&self.stiffness, &self.gravity), &r, target, options))
            .unwrap_or(Found {
                solutions: Vec::new(),
                iterations: 0,
                evaluations: 0,
                starts: 0,
            });
        if self.is_long_cable() && !found.solutions.is_empty() {
            return found;
        }
        // Where single shooting keeps its digits, the weightless rods carried in load too
        // (rods out of the plane among them).
        let starts = weightless_starts(self.spatial(), target, options);
        let carried = load::every(&self.weightless(), self, target, options, starts);
        let scale = self.param_scale();
        for s in carried.solutions {
            if found
                .solutions
                .iter()
                .all(|o| relative_distance(&o.a, &s.a, &scale) > DISTINCT)
            {
                found.solutions.push(s);
            }
        }
        found.iterations += carried.iterations;
        found.evaluations += carried.evaluations;
        found.starts += carried.starts;
        found
    }

    /// Above w = 200 the Newton iterates on the node states of the 3-D multiple shooting from
    /// the cable `a0` integrates to (single shooting from an f64 `a0` loses its digits there).
    fn newton(
        &self,
        target: &SpatialPose,
        a0: &SpatialParams,
        options: &Options6,
    ) -> Result<Solution<SpatialParams, SpatialPose>, Failure<SpatialParams>> {
        if !self.is_long_cable() {
            return crate::solver::newton_solve(self, target, a0, options);
        }
        cable_search::from_guess((&self.stiffness, &self.gravity), a0, target)
    }

    fn default_start(&self, target: &SpatialPose) -> Option<SpatialParams> {
        if self.gravity.is_weightless() {
            return self.spatial().default_start(target);
        }
        let a = self.spatial().default_start(target)?;
        Some(a + self.shared_load_step(&self.weightless()))
    }
}
