//! The branch follower of a `track` or `track3d` stream: one [`BranchFollower`] on the
//! weightless model until the stream has weight, on the heavy model after. Each front end
//! builds its own two models; the follower only dispatches.

use crate::answer::MoveAnswer;
use nalgebra::SVector;
use rod_ig_core::solver::{
    self, BranchFollower, InverseGeometry, Move, Objective, SolveOptions, Termination,
};

/// The model a stream's follower runs on.
#[derive(Clone, Copy)]
pub enum Model<W, H> {
    /// The weightless rod.
    Weightless(W),
    /// The rod with weight.
    Heavy(H),
}

/// A stream's follower: the weightless rod `W`, or the rod with weight `H` (same pose type).
pub enum Follower<const N: usize, W, H>
where
    W: InverseGeometry<N>,
    H: InverseGeometry<N, Pose = W::Pose>,
{
    /// No weight: the weightless model.
    Weightless(BranchFollower<N, W>),
    /// With weight.
    Heavy(BranchFollower<N, H>),
}

impl<const N: usize, W, H> Follower<N, W, H>
where
    W: InverseGeometry<N>,
    H: InverseGeometry<N, Pose = W::Pose>,
{
    /// A follower on `model`, holding nothing yet.
    pub fn new(model: Model<W, H>, options: SolveOptions<SVector<f64, N>>) -> Self {
        match model {
            Model::Weightless(w) => Self::Weightless(BranchFollower::new(w, options)),
            Model::Heavy(h) => Self::Heavy(BranchFollower::new(h, options)),
        }
    }

    /// A follower holding the rod `a` (see [`BranchFollower::holding`]).
    pub fn holding(
        model: Model<W, H>,
        options: SolveOptions<SVector<f64, N>>,
        a: SVector<f64, N>,
    ) -> Result<Self, String> {
        let held = match model {
            Model::Weightless(w) => BranchFollower::holding(w, options, a).map(Self::Weightless),
            Model::Heavy(h) => BranchFollower::holding(h, options, a).map(Self::Heavy),
        };
        held.map_err(|e| e.to_string())
    }

    /// One step of the stream to `target` under `options`.
    pub fn follow(
        &mut self,
        target: &W::Pose,
        options: SolveOptions<SVector<f64, N>>,
    ) -> Move<SVector<f64, N>, W::Pose> {
        match self {
            Self::Weightless(f) => {
                f.set_options(options);
                f.follow(target)
            }
            Self::Heavy(f) => {
                f.set_options(options);
                f.follow(target)
            }
        }
    }

    /// The rod held.
    pub fn rod(&self) -> Option<SVector<f64, N>> {
        match self {
            Self::Weightless(f) => f.rod(),
            Self::Heavy(f) => f.rod(),
        }
    }

    /// Where the gripper stands.
    pub fn gripper(&self) -> Option<W::Pose> {
        match self {
            Self::Weightless(f) => f.gripper(),
            Self::Heavy(f) => f.gripper(),
        }
    }
}

/// What a change of weight or gravity at fixed grippers did to the held rod.
pub struct LoadChange<P, X> {
    /// The rod before the change, when the branch folded and the rod snapped.
    pub snapped_from: Option<P>,
    /// Where the gripper stood when it snapped or the rod was lost.
    pub gripper: Option<X>,
    /// Total energy released by the snap.
    pub energy_released: f64,
    /// The rod was not carried to the new load (no stable rod where the gripper stands, or
    /// not within the deadline): the event "lost"; the line's target is then solved afresh.
    pub lost: bool,
}

impl<P, X> LoadChange<P, X> {
    /// The rod followed its branch under the new load: nothing to report.
    fn carried() -> Self {
        Self {
            snapped_from: None,
            gripper: None,
            energy_released: 0.0,
            lost: false,
        }
    }

    /// The change's event on the answer to the line's move, unless the move had its own snap:
    /// "lost", or "snap" with where and from which rod.
    pub fn mark<A, T>(
        &self,
        answer: &mut MoveAnswer<A, T>,
        a_of: impl Fn(&P) -> A,
        tip_of: impl Fn(&X) -> T,
    ) {
        if answer.event == "snap" {
            return;
        }
        if self.lost {
            answer.event = "lost";
        } else if let Some(from) = &self.snapped_from {
            answer.event = "snap";
            answer.critical = self.gripper.as_ref().map(tip_of);
            answer.critical_a = Some(a_of(from));
            answer.energy_released = Some(self.energy_released);
        }
    }
}

/// Carries the rod `follower` holds to the load of `to` (its follower's model, and the heavy
/// model that solves under it), the gripper fixed: along its branch by `carry`, or, where
/// the branch folds, by a snap to the least-energy stable rod under the new load (`energy` of
/// the old rod under it gives the energy released), or the rod is lost (an event, never an
/// error): no stable rod where the gripper stands, or the carry ran out of time (a snap is
/// claimed only where the branch was followed to its end). The follower returned holds the
/// rod, or nothing.
#[allow(clippy::type_complexity)]
pub fn change_load<const N: usize, W, H>(
    follower: &Follower<N, W, H>,
    to: (Model<W, H>, H),
    options: SolveOptions<SVector<f64, N>>,
    carry: impl FnOnce(&SVector<f64, N>, &W::Pose) -> Result<SVector<f64, N>, Termination>,
    energy: impl FnOnce(&SVector<f64, N>) -> f64,
) -> Result<(Follower<N, W, H>, LoadChange<SVector<f64, N>, W::Pose>), String>
where
    W: InverseGeometry<N> + Copy,
    H: InverseGeometry<N, Pose = W::Pose> + Copy,
{
    let (model, heavy) = to;
    let (Some(a), Some(gripper)) = (follower.rod(), follower.gripper()) else {
        return Ok((Follower::new(model, options), LoadChange::carried()));
    };
    let lost = LoadChange {
        gripper: Some(gripper),
        lost: true,
        ..LoadChange::carried()
    };
    match carry(&a, &gripper) {
        Ok(carried) => {
            return Ok((
                Follower::holding(model, options, carried)?,
                LoadChange::carried(),
            ))
        }
        // Not carried in time: whether the branch folds is not known, so no snap is
        // claimed; the rod is lost and the line's target solved afresh.
        Err(Termination::Deadline) => return Ok((Follower::new(model, options), lost)),
        Err(_) => {}
    }
    let least = SolveOptions {
        objective: Objective::LeastEnergy,
        ..options
    };
    let Ok(s) = solver::solve(&heavy, &gripper, &least) else {
        return Ok((Follower::new(model, options), lost));
    };
    let change = LoadChange {
        snapped_from: Some(a),
        gripper: Some(gripper),
        energy_released: energy(&a) - s.energy,
        lost: false,
    };
    Ok((Follower::holding(model, options, s.a)?, change))
}
