//! The branch follower of a `track` or `track3d` stream: one [`BranchFollower`] on the
//! weightless model until the stream has weight, on the heavy model after. Each front end
//! builds its own two models; the follower only dispatches.

use nalgebra::SVector;
use rod_ig_core::solver::{BranchFollower, InverseGeometry, Move, SolveOptions};

/// The model a stream's follower runs on.
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
