//! A 3-D cable in motion (issue 51, item 4): its branch followed on its node states as the tip
//! gripper moves ([`SpatialCable::branch_to`]) or as the weight and gravity's direction change
//! at fixed grippers ([`SpatialCable::carry_load`]).
//!
//! Both keep to one branch as the planar cable's continuation does
//! ([`crate::planar::heavy::cable::Cable::follow`]): a step is accepted when Newton converges
//! in a few iterations, lands near where it started and keeps the sign of the Newton matrix's
//! determinant. That determinant vanishes exactly where J(1) does (the segments' blocks are
//! invertible), so a change of its sign is a fold of the branch, where the rod snaps.

use super::{segments_for, SpatialCable, TipGoal, ROWS};
use crate::planar::heavy::cable::{lu_sign, CableError};
use crate::spatial::heavy_ode::Gravity3;
use crate::RodError;
use nalgebra::{DVector, Vector3};

/// Newton iterations above which a step is refused (a long step, or one that went far).
const STEP_ITERATIONS: usize = 8;
/// Steps, taken or refused, of one load carry at most.
const MAX_LOAD_STEPS: u32 = 400;
/// The smallest load step, as a part of the way: below it the branch folds.
const MIN_LOAD_STEP: f64 = 1e-4;
/// A remeshed cable has segments for forces this many times its own.
const REMESH_HEADROOM: f64 = 1.5;
/// How far (rad) a node may turn in one accepted step.
const MAX_NODE_TURN: f64 = 0.5;

impl SpatialCable {
    /// Sign of the determinant of the Newton matrix with the tip held by `goal` (it changes at
    /// a fold of the branch: module docs).
    pub fn matrix_sign(&self, goal: &TipGoal) -> Result<f64, RodError> {
        let (_, j) = self.residual(goal, true)?;
        Ok(j.map_or(0.0, |j| lu_sign(&j.lu())))
    }

    /// True when `other` is this rod moved a little: the base wrenches within 0.3 of their
    /// scale, and every node turned by less than [`MAX_NODE_TURN`] and moved by less than 0.3.
    fn close_to(&self, other: &SpatialCable) -> bool {
        let scale = 1.0 + self.gravity.weight().max(other.gravity.weight());
        let b = other.a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let da = (0..6).fold(0.0_f64, |m, i| m.max((self.a[i] - other.a[i]).abs()));
        // A remeshed cable's nodes are elsewhere on the rod: compared by its wrench alone.
        let same_mesh = self.nodes.len() == other.nodes.len();
        da <= 0.3 * (scale + b)
            && (!same_mesh
                || self.nodes.iter().zip(&other.nodes).all(|(p, q)| {
                    p.rotation.angle_to(&q.rotation) <= MAX_NODE_TURN
                        && (p.position - q.position).norm() <= 0.3
                }))
    }

    /// The unknowns' change (module docs: δa, then each node's body twist and δP) that takes
    /// `before` (on the same mesh) to this cable, expressed at this cable's nodes: moving
    /// this cable by it once more is the secant predictor of a continuation.
    fn change_from(&self, before: &SpatialCable) -> DVector<f64> {
        let mut d = DVector::zeros(self.dimension());
        if self.pinned_base {
            let turn = (before.nodes[0].rotation.inverse() * self.nodes[0].rotation).scaled_axis();
            d.rows_mut(0, 3).copy_from(&turn);
        }
        for i in 0..6 {
            if !(self.pinned_base && i < 3) {
                d[i] = self.a[i] - before.a[i];
            }
        }
        for k in 1..self.segments() {
            let (now, then) = (&self.nodes[k], &before.nodes[k]);
            let offset = now.offset_from(then, &now.rotation);
            d.rows_mut(6 + ROWS * (k - 1), ROWS)
                .copy_from_slice(&offset);
        }
        d
    }

    /// This rod on a mesh fit for the forces it carries under its gravity (segments as
    /// [`segments_for`]), when it needs more segments than it has: its poses sampled at the
    /// new nodes, P carried by the segments ([`SpatialCable::from_poses`]); a start that
    /// Newton corrects.
    fn remeshed(&self) -> Result<Option<Self>, RodError> {
        let af = Vector3::new(self.a[3], self.a[4], self.a[5]);
        let n1 = af - Vector3::from(self.gravity.load());
        let c = self.stiffness.c2.min(self.stiffness.c3);
        if segments_for(af.norm().max(n1.norm()), c) <= self.segments() {
            return Ok(None);
        }
        // Headroom for forces 1.5× these: a carry growing the load remeshes every few steps,
        // not at each (each remesh costs the step its predictor).
        let needed = segments_for(REMESH_HEADROOM * af.norm().max(n1.norm()), c);
        let mesh: Vec<f64> = (0..=needed).map(|i| i as f64 / needed as f64).collect();
        let poses: Vec<_> = self
            .poses_at(&mesh[..needed])?
            .into_iter()
            .map(|p| (p.rotation, p.position))
            .collect();
        Self::through_poses(
            &self.params(),
            &self.stiffness,
            &self.gravity,
            mesh,
            &poses,
            self.pinned_base,
        )
        .map(Some)
    }

    /// One step of the branch from this cable (in equilibrium, its Newton matrix's sign
    /// `side`; None after a remesh, which changes the matrix) to `goal`: the cable reached and
    /// its matrix's sign, when Newton converges in a few iterations, near this one, on the
    /// same side of the fold.
    fn stepped(
        &self,
        goal: &TipGoal,
        side: Option<f64>,
    ) -> Result<Option<(Self, f64)>, CableError> {
        let mut next = self.clone();
        let sign = match next.solve_goal_signed(goal) {
            Ok((it, sign)) if it <= STEP_ITERATIONS && next.close_to(self) => sign,
            Ok(_) => return Ok(None),
            Err(CableError::Rod(RodError::Deadline { t })) => {
                return Err(RodError::Deadline { t }.into())
            }
            Err(_) => return Ok(None),
        };
        // The last matrix Newton factored is a step from the answer: its sign is the
        // answer's but where the answer sits on the fold itself.
        let sign = match sign {
            Some(s) => s,
            None => next.matrix_sign(goal)?,
        };
        let same_side = side.is_none_or(|side| sign == side);
        Ok((same_side && sign != 0.0).then_some((next, sign)))
    }

    /// The rod of this cable's branch with its tip held by `goal`, in one corrector step
    /// ([`crate::solver::BranchFollower`]'s on long cables); None when that step fails (too
    /// long, or across a fold). `from` is the goal this cable holds now.
    pub fn branch_to(&self, from: &TipGoal, goal: &TipGoal) -> Result<Option<Self>, CableError> {
        let side = self.matrix_sign(from)?;
        Ok(self.stepped(goal, Some(side))?.map(|(c, _)| c))
    }

    /// Carries this cable, in equilibrium with its tip held by `goal`, from its gravity to
    /// `to` with the grippers fixed: the load w ĝ on a line, in steps halved where a step is
    /// refused ([`SpatialCable::branch_to`]'s rule) and lengthened by half where one is
    /// taken, the mesh refined as the forces grow. Returns the steps taken; fails where the
    /// branch folds (the step falls below 1e-4 of the way: the rod would snap), after
    /// 400 steps taken or refused, or on the deadline. The cable is left where the last step
    /// converged.
    pub fn carry_load(&mut self, to: &Gravity3, goal: &TipGoal) -> Result<u32, CableError> {
        let (l0, l1) = (self.gravity.load(), to.load());
        let target_weight = to.weight();
        let lost = |c: &Self, why: String| CableError::Lost {
            weight: c.gravity.weight(),
            target_weight,
            why,
        };
        let mut side = self.matrix_sign(goal)?;
        let (mut s, mut ds, mut steps, mut tries) = (0.0_f64, 0.0625_f64, 0u32, 0u32);
        let mut previous: Option<(f64, Self)> = None;
        while s < 1.0 {
            if crate::deadline::expired() {
                return Err(RodError::Deadline { t: s }.into());
            }
            tries += 1;
            if tries > MAX_LOAD_STEPS {
                return Err(lost(
                    self,
                    format!("{MAX_LOAD_STEPS} steps did not reach it"),
                ));
            }
            let next = (s + ds).min(1.0);
            let load: [f64; 3] = std::array::from_fn(|i| l0[i] + (l1[i] - l0[i]) * next);
            let mut trial = self.clone();
            trial.gravity = Gravity3::from_load(load, to.direction())?;
            // Predictor: the secant through the last two rods where they share a mesh (a and
            // every node moved on), else the base taking half of the added weight (a cable
            // held at both ends).
            match &previous {
                Some((sp, before)) if before.segments() == self.segments() => {
                    let step = self.change_from(before);
                    trial.set_unknowns_moved(&step, (next - s) / (s - sp));
                }
                _ => {
                    for i in 0..3 {
                        trial.a[3 + i] += 0.5 * (load[i] - self.gravity.load()[i]);
                    }
                }
            }
            if let Some(m) = trial.remeshed()? {
                trial = m;
            }
            // A new mesh changes the matrix: its sign is read afresh after the step.
            let remeshed = trial.segments() != self.segments();
            match trial.stepped(goal, (!remeshed).then_some(side))? {
                Some((c, sign)) => {
                    side = sign;
                    previous = Some((s, self.clone()));
                    *self = c;
                    s = next;
                    steps += 1;
                    ds = (ds * 1.5).min(0.5);
                }
                None if ds > MIN_LOAD_STEP => ds *= 0.5,
                None => {
                    return Err(lost(
                        self,
                        format!("the branch folds at {s:.6} of the way (the rod would snap)"),
                    ))
                }
            }
        }
        Ok(steps)
    }
}
