//! Long cables: the heavy planar rod by multiple shooting (issue 51).
//!
//! Single shooting from the base (`series`) amplifies every rounding of a by the growth of the
//! linearised rod, ≈ e^{√‖n‖}: for a cable held level 0.8 apart cond J(1) is 4e9 at w = 1,000
//! and 1e11 at w = 2,000, so an f64 `a` no longer reproduces the tip. Here the rod is cut at
//! nodes 0 = t₀ < … < t_M = 1 short enough that each segment amplifies errors by at most
//! e^{[`GROWTH_PER_SEGMENT`]}, and the unknowns are the state of every node:
//!
//! z = (κ(0), n(0), (x, y, θ, κ)(t₁), …, (x, y, θ, κ)(t_{M−1})),
//!
//! with the equations "each segment ends where the next begins" and "the last one ends at the
//! target" (docs/weight.md, "Long cables"). The segments are integrated by DOP853 with their
//! variational equations (per segment: ∂/∂θ_k, ∂/∂κ_k, ∂/∂n(0)), and Newton solves the
//! almost-block-diagonal system, whose condition does not grow with w.
//!
//! Stability is the second variation of the energy on the constraints' tangent space
//! ([`SecondVariation`]): Q(v) = ∫₀¹ v'² + (n(t) · (cos θ, sin θ)) v² dt over v(0) = v(1) = 0,
//! ∫ v sin θ = ∫ v cos θ = 0 (the tip's position held). The rod is stable iff its least
//! eigenvalue μ is positive; it is computed on a grid by Sturm counts of the bordered
//! tridiagonal matrix (no integration from the base, no growth) and extrapolated in the
//! grid's step (Richardson), with the difference of two grids as its error estimate.

// `!(x > y)` comparisons deliberately reject NaN; index loops mirror the formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use super::Gravity;
use crate::ends::{EndCondition, HeldEnds};
use crate::ode::dop853;
use crate::ode::OdeOptions;
use crate::{PlanarParams, PlanarPose, RodError};
use nalgebra::{DMatrix, DVector};
use std::ops::ControlFlow;

/// Growth allowed per segment: √max‖n‖ · h ≤ this, so an error at a node grows by at most
/// e^2 ≈ 7.4 before the next node.
pub const GROWTH_PER_SEGMENT: f64 = 2.0;
/// Most segments of one cable (w = 10⁴ with ‖n‖ ≤ 2 · 10⁴ needs 71).
pub const MAX_SEGMENTS: usize = 96;
/// Relative tolerance of each segment's integration.
const SEGMENT_RTOL: f64 = 1e-13;
/// Newton iterations of one solve.
const NEWTON_ITERATIONS: usize = 30;
/// Scaled residual at which Newton has converged (every row: positions and angles in rod
/// lengths and radians, curvatures relative to 1 + |κ|).
const RESIDUAL_TOLERANCE: f64 = 1e-12;
/// The least eigenvalue of the second variation for the straight weightless rod (clamped at
/// both ends, tip position held): μ₀ = 4 ξ² with tan ξ = ξ, ξ = 4.4934…, i.e. 80.763; the
/// normalised margin is μ / μ₀.
pub const STRAIGHT_ROD_EIGENVALUE: f64 = 80.763_179_582_317_7;

/// State components integrated on a segment: x, y, θ, κ, the elastic energy ½∫κ², ∫x, ∫y.
const STATE: usize = 7;
/// Plus four variational columns of (x, y, θ, κ): ∂/∂θ_k, ∂/∂κ_k, ∂/∂n_x(0), ∂/∂n_y(0).
const FULL: usize = STATE + 16;

/// Why a cable could not be solved.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CableError {
    /// A segment's integration failed (overflow, budget, deadline).
    #[error("{0}")]
    Rod(#[from] RodError),
    /// Newton did not converge.
    #[error(
        "multiple shooting did not converge in {iterations} iterations (residual {residual:e})"
    )]
    NoConvergence {
        /// Iterations run.
        iterations: usize,
        /// Scaled residual reached.
        residual: f64,
    },
    /// The Newton matrix was singular (a fold of the equilibria through the target).
    #[error("the multiple-shooting matrix is singular (a fold)")]
    Singular,
    /// Continuation in the load stopped.
    #[error("the cable was lost at weight {weight:.6} on the way to {target_weight}: {why}")]
    Lost {
        /// Last weight reached.
        weight: f64,
        /// Weight asked.
        target_weight: f64,
        /// What stopped it.
        why: String,
    },
}

/// The right-hand side on a segment: the rod (docs/math.md §1 with n(t) = n(0) − w t ĝ) and, with
/// `VARS`, its four variational columns.
#[inline(always)]
fn rhs<const D: usize>(load: [f64; 2], n0: [f64; 2], t: f64, y: &[f64; D], dy: &mut [f64; D]) {
    let nx = n0[0] - t * load[0];
    let ny = n0[1] - t * load[1];
    let (s, c) = y[2].sin_cos();
    dy[0] = c;
    dy[1] = s;
    dy[2] = y[3];
    dy[3] = nx * s - ny * c;
    dy[4] = 0.5 * y[3] * y[3];
    dy[5] = y[0];
    dy[6] = y[1];
    if D == FULL {
        let tension = nx * c + ny * s;
        for col in 0..4 {
            let o = STATE + 4 * col;
            let (dth, dk) = (y[o + 2], y[o + 3]);
            let extra = match col {
                2 => s,
                3 => -c,
                _ => 0.0,
            };
            dy[o] = -s * dth;
            dy[o + 1] = c * dth;
            dy[o + 2] = dk;
            dy[o + 3] = tension * dth + extra;
        }
    }
}

fn ode_options_at(rtol: f64) -> OdeOptions {
    OdeOptions {
        rtol,
        atol: rtol,
        max_steps: 20_000,
        error_components: 4,
        ..OdeOptions::default()
    }
}

fn ode_options() -> OdeOptions {
    ode_options_at(SEGMENT_RTOL)
}

/// Relative tolerance of the segments while a continuation moves between its intermediate
/// rods (their accuracy only needs to keep the next predictor in Newton's basin); the rod a
/// continuation ends with is corrected at [`SEGMENT_RTOL`].
const SUBSTEP_RTOL: f64 = 1e-9;

/// One segment from `start` = (x, y, θ, κ) at t0 to t1: with `D` = [`FULL`] its variational
/// columns too (starting as ∂/∂θ_k = e_θ, ∂/∂κ_k = e_κ, ∂/∂n(0) = 0), with [`STATE`] without.
fn integrate_segment<const D: usize>(
    rtol: f64,
    load: [f64; 2],
    n0: [f64; 2],
    (t0, t1): (f64, f64),
    start: [f64; 4],
) -> Result<[f64; D], RodError> {
    let mut y = [0.0; D];
    y[..4].copy_from_slice(&start);
    if D == FULL {
        y[STATE + 2] = 1.0; // ∂θ/∂θ_k
        y[STATE + 4 + 3] = 1.0; // ∂κ/∂κ_k
    }
    let (end, _) = dop853::solve(
        |t, y: &[f64; D], dy: &mut [f64; D]| rhs(load, n0, t, y, dy),
        t0,
        y,
        t1,
        &ode_options_at(rtol),
    )?;
    Ok(end)
}

/// The mesh of `segments` equal segments.
fn uniform_mesh(segments: usize) -> Vec<f64> {
    (0..=segments).map(|i| i as f64 / segments as f64).collect()
}

/// Segments needed for internal forces up to `force_max`: √force_max · h ≤ GROWTH_PER_SEGMENT.
pub fn segments_for(force_max: f64) -> usize {
    let m = (force_max.max(0.0).sqrt() / GROWTH_PER_SEGMENT).ceil() as usize;
    m.clamp(2, MAX_SEGMENTS)
}

fn force_max(n0: [f64; 2], load: [f64; 2]) -> f64 {
    let n1 = [n0[0] - load[0], n0[1] - load[1]];
    n0[0].hypot(n0[1]).max(n1[0].hypot(n1[1]))
}

/// A heavy rod in equilibrium as the states of its nodes: what multiple shooting solves for.
#[derive(Clone, Debug, PartialEq)]
pub struct Cable {
    gravity: Gravity,
    mesh: Vec<f64>,
    /// n(0) = (a4, a5).
    force: [f64; 2],
    /// (x, y, θ, κ) at t₀ … t_{M−1}; the first is (0, 0, 0, a3) (pinned base: (0, 0, θ₀, 0)).
    nodes: Vec<[f64; 4]>,
    /// Relative tolerance of the segments' integration in the Newton equations: the full
    /// [`SEGMENT_RTOL`], or [`SUBSTEP_RTOL`] on a continuation's intermediate rods.
    rtol: f64,
    /// How the ends are held: which node-0 component is unknown (κ(0) clamped, θ(0) pinned),
    /// whether n(0) is (free tip: n(0) = w ĝ) and which tip components are equations.
    ends: HeldEnds,
    /// The curvature a pinned or free tip's equation asks, κ(1) = this: 0, except while
    /// [`Cable::release_into`] lets a clamp's moment go.
    tip_curvature_goal: f64,
    /// A point force applied at a free tip (base frame; zero: nothing hangs from it): then
    /// n(1) = this and n(0) = w ĝ + this.
    tip_load: [f64; 2],
}

impl Cable {
    /// The cable whose base wrench is `a`, its nodes found by integrating from the base on a
    /// mesh fit for its forces. Exact where single shooting is (w ≲ 300); at larger w it is
    /// a starting guess that [`Cable::solve`] corrects.
    pub fn from_params(a: &PlanarParams, gravity: &Gravity) -> Result<Self, RodError> {
        Self::held(0.0, a, gravity, HeldEnds::CLAMPED)
    }

    /// The cable held by `ends` whose base leaves at angle `base_angle` (0 for a clamped base)
    /// with base wrench `a`, its nodes integrated from the base as [`Cable::from_params`]. A
    /// pinned base has κ(0) = 0 (a3 is ignored); a free tip has n(0) = w ĝ, so that n(1) = 0
    /// (a4, a5 are ignored).
    pub fn held(
        base_angle: f64,
        a: &PlanarParams,
        gravity: &Gravity,
        ends: HeldEnds,
    ) -> Result<Self, RodError> {
        RodError::check_finite("a", a.as_slice())?;
        RodError::check_finite("base_angle", &[base_angle])?;
        let load = gravity.load();
        let force = if ends.tip() == EndCondition::Free {
            load
        } else {
            [a[1], a[2]]
        };
        let (theta0, kappa0) = match ends.base() {
            EndCondition::Pinned => (base_angle, 0.0),
            _ => (base_angle, a[0]),
        };
        let mesh = uniform_mesh(segments_for(force_max(force, load)));
        let mut nodes = vec![[0.0, 0.0, theta0, kappa0]];
        for k in 0..mesh.len() - 2 {
            let e = integrate_segment::<STATE>(
                SEGMENT_RTOL,
                load,
                force,
                (mesh[k], mesh[k + 1]),
                nodes[k],
            )?;
            nodes.push([e[0], e[1], e[2], e[3]]);
        }
        Ok(Self::assembled(gravity, mesh, force, nodes, ends))
    }

    /// The cable of these parts at the full integration tolerance, its tip asked no curvature
    /// and carrying no load.
    fn assembled(
        gravity: &Gravity,
        mesh: Vec<f64>,
        force: [f64; 2],
        nodes: Vec<[f64; 4]>,
        ends: HeldEnds,
    ) -> Self {
        Self {
            gravity: *gravity,
            mesh,
            force,
            nodes,
            rtol: SEGMENT_RTOL,
            ends,
            tip_curvature_goal: 0.0,
            tip_load: [0.0; 2],
        }
    }

    /// A clamped cable with base force `force` whose node states are a guessed shape:
    /// `angle_of(t)` = (θ, κ) at t, positions integrated from the angle (Simpson, `steps` per
    /// segment). Not an equilibrium: a start for [`Cable::solve`]
    /// ([`super::catenary::seed`]).
    pub(crate) fn from_states(
        gravity: &Gravity,
        force: [f64; 2],
        angle_of: impl Fn(f64) -> (f64, f64),
        steps: usize,
    ) -> Result<Self, RodError> {
        RodError::check_finite("force", &force)?;
        let mesh = uniform_mesh(segments_for(force_max(force, gravity.load())));
        let mut nodes = Vec::with_capacity(mesh.len() - 1);
        let (mut x, mut y) = (0.0, 0.0);
        for k in 0..mesh.len() - 1 {
            let (theta, kappa) = angle_of(mesh[k]);
            RodError::check_finite("the seed's state", &[theta, kappa, x, y])?;
            nodes.push([x, y, if k == 0 { 0.0 } else { theta }, kappa]);
            let h = (mesh[k + 1] - mesh[k]) / steps as f64;
            for i in 0..steps {
                let t = mesh[k] + i as f64 * h;
                for (weight, s) in [(1.0, t), (4.0, t + 0.5 * h), (1.0, t + h)] {
                    let theta = angle_of(s).0;
                    x += weight * h / 6.0 * theta.cos();
                    y += weight * h / 6.0 * theta.sin();
                }
            }
        }
        Ok(Self::assembled(
            gravity,
            mesh,
            force,
            nodes,
            HeldEnds::CLAMPED,
        ))
    }

    /// The same free-tip cable with the point force `load` (base frame, unit rod's units)
    /// applied at its tip: n(0) = w ĝ + load. Refused unless the tip is free (a held tip's
    /// gripper takes any load).
    pub fn with_tip_load(mut self, load: [f64; 2]) -> Result<Self, RodError> {
        RodError::check_finite("tip_load", &load)?;
        if self.ends.tip() != EndCondition::Free {
            return Err(RodError::OutOfDomain(
                "a tip load needs a free tip (a held tip's gripper takes it)".into(),
            ));
        }
        let l = self.gravity.load();
        self.tip_load = load;
        self.force = [l[0] + load[0], l[1] + load[1]];
        Ok(self)
    }

    /// The point force applied at a free tip (zero otherwise).
    pub fn tip_load(&self) -> [f64; 2] {
        self.tip_load
    }

    /// How the two ends are held.
    pub fn ends(&self) -> HeldEnds {
        self.ends
    }

    /// The rod's angle at the base, θ(0): 0 unless the base is pinned.
    pub fn base_angle(&self) -> f64 {
        self.nodes[0][2]
    }

    /// The same rod with every angle shifted by a whole number of turns so that the base angle
    /// is in (−π, π] (a pinned base's angle is found modulo 2π).
    pub fn unwind_base_angle(&mut self) {
        let shift = self.nodes[0][2] - crate::wrap_angle(self.nodes[0][2]);
        if shift != 0.0 {
            for n in &mut self.nodes {
                n[2] -= shift;
            }
        }
    }

    /// Turns this cable, both ends clamped and on `target`, into the equilibrium held by `ends`
    /// through the same target: the moments at the ends that become pinned or free are let go
    /// gradually (a homotopy κ_end = (1 − s) κ_end(clamped), s from 0 to 1, each step corrected
    /// by Newton; the clamped rod solves the s = 0 equations exactly). Returns the steps.
    pub fn release_into(&mut self, ends: HeldEnds, target: &PlanarPose) -> Result<u32, CableError> {
        if ends.tip() == EndCondition::Free {
            return Err(RodError::OutOfDomain(
                "a free tip is not reached by releasing a clamp (its force changes too)".into(),
            )
            .into());
        }
        let base_moment = if ends.base() == EndCondition::Pinned {
            self.nodes[0][3]
        } else {
            0.0
        };
        let tip_moment = if ends.tip() == EndCondition::Pinned {
            self.tip_curvature()?
        } else {
            0.0
        };
        self.ends = ends;
        let (mut s, mut ds, mut steps) = (0.0, 1.0, 0u32);
        while s < 1.0 {
            if crate::deadline::expired() {
                return Err(RodError::Deadline { t: s }.into());
            }
            let next = (s + ds).min(1.0);
            let mut trial = self.clone();
            if ends.base() == EndCondition::Pinned {
                trial.nodes[0][3] = (1.0 - next) * base_moment;
            }
            trial.tip_curvature_goal = (1.0 - next) * tip_moment;
            steps += 1;
            match trial.solve(target) {
                Ok(it) if it <= 10 && trial.close_to(self) => {
                    *self = trial;
                    s = next;
                    ds = (2.0 * ds).min(1.0);
                }
                Err(CableError::Rod(RodError::Deadline { t })) => {
                    return Err(RodError::Deadline { t }.into())
                }
                _ if ds > 1.0 / 256.0 => ds *= 0.5,
                _ => {
                    return Err(CableError::Lost {
                        weight: self.gravity.weight(),
                        target_weight: self.gravity.weight(),
                        why: format!("the end moments could not be released past s = {s:.4}"),
                    })
                }
            }
        }
        Ok(steps)
    }

    /// a = (κ(0), n(0)): the base wrench.
    pub fn params(&self) -> PlanarParams {
        PlanarParams::new(self.nodes[0][3], self.force[0], self.force[1])
    }

    /// The gravity this cable carries.
    pub fn gravity(&self) -> &Gravity {
        &self.gravity
    }

    /// True when `other` is this rod: the same base wrench under the same gravity.
    pub fn same_rod(&self, other: &Cable) -> bool {
        self.params() == other.params()
            && self.gravity == other.gravity
            && self.ends == other.ends
            && self.base_angle() == other.base_angle()
    }

    /// Segments of the mesh.
    pub fn segments(&self) -> usize {
        self.mesh.len() - 1
    }

    /// The mesh t₀ = 0 < … < t_M = 1.
    pub fn mesh(&self) -> &[f64] {
        &self.mesh
    }

    /// The node states (x, y, θ, κ) at t₀ … t_{M−1}.
    pub fn nodes(&self) -> &[[f64; 4]] {
        &self.nodes
    }

    /// The state at the end of the last segment: the tip (x, y, θ), θ unwrapped.
    pub fn tip(&self) -> Result<PlanarPose, RodError> {
        let e = self.last_segment()?;
        Ok(PlanarPose::new(e[0], e[1], e[2]))
    }

    /// The tip's curvature κ(1) (the moment the tip gripper holds, with its sign reversed).
    pub fn tip_curvature(&self) -> Result<f64, RodError> {
        Ok(self.last_segment()?[3])
    }

    /// The last segment's end state, without variations (the tip needs none).
    fn last_segment(&self) -> Result<[f64; STATE], RodError> {
        let m = self.segments();
        integrate_segment::<STATE>(
            SEGMENT_RTOL,
            self.gravity.load(),
            self.force,
            (self.mesh[m - 1], self.mesh[m]),
            self.nodes[m - 1],
        )
    }

    /// Which component of node 0 is unknown: κ(0) for a clamped base, θ(0) for a pinned one.
    fn base_unknown(&self) -> usize {
        match self.ends.base() {
            EndCondition::Pinned => 2,
            _ => 3,
        }
    }

    /// Unknowns before the interior nodes': node 0's, then n(0) unless the tip is free.
    fn node_offset(&self) -> usize {
        if self.ends.tip() == EndCondition::Free {
            1
        } else {
            3
        }
    }

    /// The tip components that are equations: (x, y, θ) clamped, (x, y, κ) pinned, κ free.
    fn tip_equations(&self) -> &'static [usize] {
        match self.ends.tip() {
            EndCondition::Clamped => &[0, 1, 2],
            EndCondition::Pinned => &[0, 1, 3],
            EndCondition::Free => &[3],
        }
    }

    fn unknowns(&self) -> DVector<f64> {
        let m = self.segments();
        let off = self.node_offset();
        let mut z = DVector::zeros(off + 4 * (m - 1));
        z[0] = self.nodes[0][self.base_unknown()];
        if off == 3 {
            z[1] = self.force[0];
            z[2] = self.force[1];
        }
        for k in 1..m {
            for c in 0..4 {
                z[off + 4 * (k - 1) + c] = self.nodes[k][c];
            }
        }
        z
    }

    fn set_unknowns(&mut self, z: &DVector<f64>) {
        let m = self.segments();
        let off = self.node_offset();
        let b = self.base_unknown();
        self.nodes[0][b] = z[0];
        if off == 3 {
            self.force = [z[1], z[2]];
        }
        for k in 1..m {
            for c in 0..4 {
                self.nodes[k][c] = z[off + 4 * (k - 1) + c];
            }
        }
    }

    /// Residual of the multiple-shooting equations (continuity, then the tip on `target`),
    /// each row scaled, and with `jacobian` their derivative in the unknowns.
    fn residual(
        &self,
        target: &PlanarPose,
        jacobian: bool,
    ) -> Result<(DVector<f64>, Option<DMatrix<f64>>), RodError> {
        let m = self.segments();
        let off = self.node_offset();
        let dim = off + 4 * (m - 1);
        let load = self.gravity.load();
        // The variational column of node 0's unknown: ∂/∂κ_k (clamped base) or ∂/∂θ_k.
        let base_column = if self.base_unknown() == 3 { 1 } else { 0 };
        let mut r = DVector::zeros(dim);
        let mut j = jacobian.then(|| DMatrix::zeros(dim, dim));
        for k in 0..m {
            let (t0, t1, start) = (self.mesh[k], self.mesh[k + 1], self.nodes[k]);
            let mut e = [0.0; FULL];
            if jacobian {
                e = integrate_segment::<FULL>(self.rtol, load, self.force, (t0, t1), start)?;
            } else {
                e[..STATE].copy_from_slice(&integrate_segment::<STATE>(
                    self.rtol,
                    load,
                    self.force,
                    (t0, t1),
                    start,
                )?);
            }
            let row = 4 * k;
            let (components, goal): (&[usize], [f64; 4]) = if k + 1 < m {
                (&[0, 1, 2, 3], self.nodes[k + 1])
            } else {
                (
                    self.tip_equations(),
                    [target.x, target.y, target.theta, self.tip_curvature_goal],
                )
            };
            // Curvature rows are scaled by 1 + |κ|, so that one tolerance fits every row.
            let scale = |c: usize| {
                if c == 3 {
                    1.0 / (1.0 + goal[3].abs().max(e[3].abs()))
                } else {
                    1.0
                }
            };
            for (i, &c) in components.iter().enumerate() {
                r[row + i] = (e[c] - goal[c]) * scale(c);
            }
            let Some(j) = j.as_mut() else { continue };
            for (i, &c) in components.iter().enumerate() {
                let sc = scale(c);
                let col_of = |v: usize| e[STATE + 4 * v + c] * sc;
                if k == 0 {
                    j[(row + i, 0)] = col_of(base_column);
                } else {
                    let base = off + 4 * (k - 1);
                    if c < 2 {
                        j[(row + i, base + c)] = sc; // ∂x/∂x_k, ∂y/∂y_k
                    }
                    j[(row + i, base + 2)] = col_of(0);
                    j[(row + i, base + 3)] = col_of(1);
                }
                if off == 3 {
                    j[(row + i, 1)] = col_of(2);
                    j[(row + i, 2)] = col_of(3);
                }
                if k + 1 < m {
                    j[(row + i, off + 4 * k + c)] = -sc;
                }
            }
        }
        Ok((r, j))
    }

    /// Newton on the multiple-shooting equations from this cable's state: the equilibrium
    /// whose tip is at `target`. Backtracks on the residual's norm. Returns the iterations.
    pub fn solve(&mut self, target: &PlanarPose) -> Result<usize, CableError> {
        self.solve_with_sign(target).map(|(it, _)| it)
    }

    /// [`Cable::solve`], and the sign of the determinant of the last Newton matrix factored
    /// (it changes where the equilibria through the target fold).
    pub(crate) fn solve_with_sign(
        &mut self,
        target: &PlanarPose,
    ) -> Result<(usize, f64), CableError> {
        let (mut r, _) = self.residual(target, false)?;
        let mut norm = r.amax();
        let mut sign = 0.0;
        for it in 0..NEWTON_ITERATIONS {
            let (r_now, j) = self.residual(target, true)?;
            r = r_now;
            let Some(j) = j else { unreachable!() };
            let lu = j.lu();
            sign = lu_sign(&lu);
            let Some(step) = lu.solve(&(-&r)) else {
                return Err(CableError::Singular);
            };
            let z = self.unknowns();
            let scale = 1.0 + z.amax();
            let mut alpha = 1.0;
            loop {
                let mut trial = self.clone();
                trial.set_unknowns(&(&z + alpha * &step));
                match trial.residual(target, false) {
                    Ok((rt, _)) if rt.amax() < (1.0 - 1e-4 * alpha) * norm || rt.amax() == 0.0 => {
                        *self = trial;
                        norm = rt.amax();
                        break;
                    }
                    Err(RodError::Deadline { t }) => return Err(RodError::Deadline { t }.into()),
                    _ if alpha > 1.0 / 64.0 => alpha *= 0.5,
                    // At the rounding floor no step decreases the residual further.
                    _ if norm <= self.residual_tolerance() => return Ok((it, sign)),
                    _ => {
                        return Err(CableError::NoConvergence {
                            iterations: it,
                            residual: norm,
                        })
                    }
                }
            }
            let small = alpha * step.amax() <= 1e-9 * scale;
            if norm <= 1e-14 || (norm <= self.residual_tolerance() && small) {
                return Ok((it + 1, sign));
            }
        }
        if norm <= self.residual_tolerance() {
            return Ok((NEWTON_ITERATIONS, sign));
        }
        Err(CableError::NoConvergence {
            iterations: NEWTON_ITERATIONS,
            residual: norm,
        })
    }

    /// J(1, a) = ∂(x, y, θ)(1)/∂(a3, a4, a5), rows x, y, θ: the segments' transition matrices
    /// multiplied along the rod (each accurate; the product is the true, ill-conditioned J).
    /// With a pinned base the first column is ∂/∂θ(0) (its κ(0) is 0).
    pub fn jacobian(&self) -> Result<crate::PlanarJacobian, RodError> {
        let load = self.gravity.load();
        // d[r][c] = ∂(x, y, θ, κ)_r / ∂a_c at the current node.
        let mut d = [[0.0; 3]; 4];
        d[self.base_unknown()][0] = 1.0;
        for k in 0..self.segments() {
            let e = integrate_segment::<FULL>(
                SEGMENT_RTOL,
                load,
                self.force,
                (self.mesh[k], self.mesh[k + 1]),
                self.nodes[k],
            )?;
            let col = |v: usize, r: usize| e[STATE + 4 * v + r];
            let mut next = [[0.0; 3]; 4];
            for r in 0..4 {
                for c in 0..3 {
                    let carried = if r < 2 { d[r][c] } else { 0.0 }
                        + col(0, r) * d[2][c]
                        + col(1, r) * d[3][c];
                    let direct = if c == 0 { 0.0 } else { col(c + 1, r) };
                    next[r][c] = carried + direct;
                }
            }
            d = next;
        }
        let mut j = crate::PlanarJacobian::zeros();
        for c in 0..3 {
            j[(0, c)] = d[0][c];
            j[(1, c)] = d[1][c];
            j[(2, c)] = d[2][c];
        }
        Ok(j)
    }

    /// The scaled residual at which Newton stops: [`RESIDUAL_TOLERANCE`], or 100 × the
    /// integration's tolerance when that is looser (a continuation's intermediate rods).
    fn residual_tolerance(&self) -> f64 {
        RESIDUAL_TOLERANCE.max(100.0 * self.rtol)
    }

    /// The same rod on a mesh fit for its current forces (more segments when the forces
    /// grew), each new node integrated from the old node before it (one short segment: no
    /// amplification).
    pub fn remesh(&mut self) -> Result<(), RodError> {
        let need = segments_for(force_max(self.force, self.gravity.load()));
        if need <= self.segments() {
            return Ok(());
        }
        let mesh = uniform_mesh(need);
        let nodes = self.states_at(&mesh[..need])?;
        self.mesh = mesh;
        self.nodes = nodes;
        Ok(())
    }

    /// The same cable under another gravity (its state unchanged: a predictor).
    fn with_gravity(&self, gravity: Gravity) -> Self {
        let force = if self.ends.tip() == EndCondition::Free {
            let l = gravity.load();
            [l[0] + self.tip_load[0], l[1] + self.tip_load[1]]
        } else {
            self.force
        };
        Self {
            gravity,
            force,
            ..self.clone()
        }
    }

    /// States (x, y, θ, κ) at the sorted times `ts` ⊂ [0, 1], each integrated from the node
    /// before it.
    fn states_at(&self, ts: &[f64]) -> Result<Vec<[f64; 4]>, RodError> {
        let mut out = Vec::with_capacity(ts.len());
        self.sample(ts, |_, y| out.push([y[0], y[1], y[2], y[3]]))?;
        Ok(out)
    }

    /// Calls `f(i, state)` for each of the sorted times `ts`, with the full state
    /// (x, y, θ, κ, elastic energy, ∫x, ∫y) integrated from the node before each time (the
    /// quadratures restart at 0 on each segment; [`Cable::energies`] sums them).
    fn sample(&self, ts: &[f64], mut f: impl FnMut(usize, &[f64; STATE])) -> Result<(), RodError> {
        let load = self.gravity.load();
        let n0 = self.force;
        let m = self.segments();
        let mut i = 0;
        for k in 0..m {
            let (t0, t1) = (self.mesh[k], self.mesh[k + 1]);
            let end = i + ts[i..]
                .iter()
                .take_while(|&&t| t < t1 || (k + 1 == m && t <= t1))
                .count();
            if end == i {
                continue;
            }
            let mut y0 = [0.0; STATE];
            y0[..4].copy_from_slice(&self.nodes[k]);
            let slice = &ts[i..end];
            let first = i;
            dop853::solve_dense(
                |t, y: &[f64; STATE], dy: &mut [f64; STATE]| rhs(load, n0, t, y, dy),
                t0,
                y0,
                slice,
                &ode_options(),
                |j, _, y| {
                    f(first + j, y);
                    ControlFlow::Continue(())
                },
            )?;
            i = end;
            if i == ts.len() {
                break;
            }
        }
        Ok(())
    }

    /// `samples` poses at t_i = i/(samples − 1), base to tip.
    pub fn shape(&self, samples: usize) -> Result<Vec<PlanarPose>, RodError> {
        let ts: Vec<f64> = match samples {
            0 => Vec::new(),
            1 => vec![0.0],
            n => (0..n).map(|i| i as f64 / (n - 1) as f64).collect(),
        };
        let mut out = Vec::with_capacity(samples);
        self.sample(&ts, |_, y| out.push(PlanarPose::new(y[0], y[1], y[2])))?;
        Ok(out)
    }

    /// (total, elastic) energy: ½∫κ² + w ∫(−ĝ · r) dt, segment by segment.
    pub fn energies(&self) -> Result<(f64, f64), RodError> {
        let m = self.segments();
        let load = self.gravity.load();
        let (mut elastic, mut rx, mut ry) = (0.0, 0.0, 0.0);
        for k in 0..m {
            let mut y0 = [0.0; STATE];
            y0[..4].copy_from_slice(&self.nodes[k]);
            let (e, _) = dop853::solve(
                |t, y: &[f64; STATE], dy: &mut [f64; STATE]| rhs(load, self.force, t, y, dy),
                self.mesh[k],
                y0,
                self.mesh[k + 1],
                &ode_options(),
            )?;
            elastic += e[4];
            rx += e[5];
            ry += e[6];
        }
        Ok((elastic - (load[0] * rx + load[1] * ry), elastic))
    }

    /// The second variation's least eigenvalue (the stability test; module docs).
    pub fn second_variation(&self) -> Result<SecondVariation, RodError> {
        SecondVariation::of(self)
    }

    /// How many full turns the tangent makes along the rod: ⌊(max θ − min θ) / 2π⌋ on the
    /// sampled shape. 0 for a loop-free cable.
    pub fn turns(&self) -> Result<u32, RodError> {
        let shape = self.shape(SHAPE_CHECK_SAMPLES)?;
        Ok(turns_of(&shape))
    }

    /// True when the centreline crosses itself (checked on [`SHAPE_CHECK_SAMPLES`] chords).
    pub fn self_intersects(&self) -> Result<bool, RodError> {
        let shape = self.shape(SHAPE_CHECK_SAMPLES)?;
        Ok(self_intersects(&shape))
    }

    /// Carries this cable (on target at `target` under its gravity) to gravity `to` with the
    /// gripper fixed: continuation in the load (geometric in w when the direction is kept),
    /// [`Cable::follow`]. Returns the continuation's steps.
    pub fn carry(&mut self, to: &Gravity, target: &PlanarPose) -> Result<u32, CableError> {
        self.carry_within(to, target, &FollowLimits::default())
    }

    /// [`Cable::carry`] within `limits`.
    pub fn carry_within(
        &mut self,
        to: &Gravity,
        target: &PlanarPose,
        limits: &FollowLimits,
    ) -> Result<u32, CableError> {
        let path = LoadPath::new(&self.gravity, to);
        let target = *target;
        self.follow(path.initial_step(), limits, |s| Ok((path.at(s)?, target)))
    }

    /// Moves the tip gripper from where this cable ends to `target` (θ lifted to the turn
    /// nearest the current tip's) under the same gravity: continuation in the target,
    /// [`Cable::follow`]. Returns the continuation's steps.
    pub fn move_to(&mut self, target: &PlanarPose) -> Result<u32, CableError> {
        self.move_within(target, &FollowLimits::default())
    }

    /// [`Cable::move_to`] within `limits`.
    pub fn move_within(
        &mut self,
        target: &PlanarPose,
        limits: &FollowLimits,
    ) -> Result<u32, CableError> {
        let from = self.tip()?;
        let to = lift_near(target, from.theta);
        let g = self.gravity;
        self.follow(0.1, limits, |s| {
            Ok((
                g,
                PlanarPose::new(
                    from.x + s * (to.x - from.x),
                    from.y + s * (to.y - from.y),
                    from.theta + s * (to.theta - from.theta),
                ),
            ))
        })
    }

    /// Follows the equilibrium as gravity and the target move along `path(s)`, s from 0 (this
    /// cable, on `path(0)`'s target) to 1: each step predicted by a secant in the unknowns and
    /// corrected by [`Cable::solve`], accepted when the corrector converges quickly, lands near
    /// the prediction and keeps the sign of the Newton matrix's determinant (it changes at a
    /// fold, where the branch ends). Polls the deadline once per step.
    pub fn follow(
        &mut self,
        initial_step: f64,
        limits: &FollowLimits,
        path: impl Fn(f64) -> Result<(Gravity, PlanarPose), RodError>,
    ) -> Result<u32, CableError> {
        let (_, start_target) = path(0.0)?;
        let mut sign = self.matrix_sign(&start_target)?;
        let mut s = 0.0;
        let mut ds = initial_step.clamp(1e-4, 1.0);
        let mut prev: Option<(f64, DVector<f64>)> = None;
        let mut steps = 0u32;
        while s < 1.0 {
            if crate::deadline::expired() {
                return Err(RodError::Deadline { t: s }.into());
            }
            if steps >= limits.max_steps {
                return Err(CableError::Lost {
                    weight: self.gravity.weight(),
                    target_weight: path(1.0)?.0.weight(),
                    why: format!(
                        "{} continuation steps did not reach the end",
                        limits.max_steps
                    ),
                });
            }
            let spread = self.node_theta_spread();
            if spread > limits.max_theta_spread {
                return Err(CableError::Lost {
                    weight: self.gravity.weight(),
                    target_weight: path(1.0)?.0.weight(),
                    why: format!("the cable coils (its tangent turns through {spread:.1} rad)"),
                });
            }
            let next = (s + ds).min(1.0);
            let (g, target) = path(next)?;
            let mut trial = self.with_gravity(g);
            trial.rtol = if next < 1.0 {
                SUBSTEP_RTOL
            } else {
                SEGMENT_RTOL
            };
            if let Some((sp, zp)) = &prev {
                let z = self.unknowns();
                let f = (next - s) / (s - sp);
                trial.set_unknowns(&(&z + f * (&z - zp)));
            }
            steps += 1;
            let remeshed = trial.remesh().map(|()| trial.segments() != self.segments());
            let accepted = match (remeshed, trial.solve_with_sign(&target)) {
                (Ok(remeshed), Ok((it, sg))) => {
                    (it <= 8 && trial.close_to(self) && (remeshed || sg == sign)).then_some(sg)
                }
                (_, Err(CableError::Rod(RodError::Deadline { t }))) => {
                    return Err(RodError::Deadline { t }.into())
                }
                _ => None,
            };
            if let Some(sg) = accepted {
                prev = (trial.segments() == self.segments()).then(|| (s, self.unknowns()));
                sign = sg;
                *self = trial;
                s = next;
                ds = (ds * 2.0).min(0.5);
            } else {
                ds /= 3.0;
                if ds < 1e-5 {
                    return Err(CableError::Lost {
                        weight: self.gravity.weight(),
                        target_weight: path(1.0)?.0.weight(),
                        why: format!("the branch folds or turns away at s = {s:.6} of the path"),
                    });
                }
            }
        }
        Ok(steps)
    }

    /// max θ − min θ over the nodes (a lower bound of the tangent's turning).
    pub fn node_theta_spread(&self) -> f64 {
        let (lo, hi) = self
            .nodes
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), n| {
                (lo.min(n[2]), hi.max(n[2]))
            });
        hi - lo
    }

    /// True when `other`'s base wrench is within 30 % (relative, scale 1 + w) of this one's:
    /// a corrector that lands farther has likely jumped to another branch.
    pub(crate) fn close_to(&self, other: &Cable) -> bool {
        let (a, b) = (self.params(), other.params());
        let scale = 1.0 + self.gravity.weight().max(other.gravity.weight());
        (a - b).amax() <= 0.3 * (scale + b.amax())
            && (self.base_angle() - other.base_angle()).abs() <= 0.5
    }

    /// Sign of the determinant of the Newton matrix (changes at a fold).
    pub(crate) fn matrix_sign(&self, target: &PlanarPose) -> Result<f64, RodError> {
        let (_, j) = self.residual(target, true)?;
        let Some(j) = j else { unreachable!() };
        Ok(lu_sign(&j.lu()))
    }
}

/// The sign of a determinant from its LU factors.
pub(crate) fn lu_sign(lu: &nalgebra::linalg::LU<f64, nalgebra::Dyn, nalgebra::Dyn>) -> f64 {
    let u = lu.u();
    let mut sign = if lu.p().determinant::<f64>() < 0.0 {
        -1.0
    } else {
        1.0
    };
    for i in 0..u.nrows() {
        sign *= u[(i, i)].signum();
    }
    sign
}

/// `target` with θ lifted by whole turns to the value nearest `theta`.
pub fn lift_near(target: &PlanarPose, theta: f64) -> PlanarPose {
    let k = ((theta - target.theta) / std::f64::consts::TAU).round();
    PlanarPose::new(target.x, target.y, target.theta + k * std::f64::consts::TAU)
}

/// Bounds of one continuation ([`Cable::follow`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FollowLimits {
    /// Steps (accepted and rejected) at most.
    pub max_steps: u32,
    /// The nodes' tangent angles may spread over at most this (rad): a search that admits
    /// only loop-free rods abandons a branch that coils.
    pub max_theta_spread: f64,
}

impl Default for FollowLimits {
    fn default() -> Self {
        Self {
            max_steps: 4096,
            max_theta_spread: f64::INFINITY,
        }
    }
}

/// Samples of the shape used for the loop and self-crossing checks.
pub const SHAPE_CHECK_SAMPLES: usize = 401;

/// ⌊(max θ − min θ) / 2π⌋ over sampled poses.
pub fn turns_of(shape: &[PlanarPose]) -> u32 {
    let (lo, hi) = shape
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.theta), hi.max(p.theta))
        });
    if !(hi >= lo) {
        return 0;
    }
    ((hi - lo) / std::f64::consts::TAU).floor() as u32
}

/// True when two non-adjacent chords of the polyline cross (proper crossings; the chords
/// between consecutive samples).
pub fn self_intersects(shape: &[PlanarPose]) -> bool {
    let n = shape.len();
    let cross = |o: &PlanarPose, a: &PlanarPose, b: &PlanarPose| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    for i in 0..n.saturating_sub(1) {
        let (p1, p2) = (&shape[i], &shape[i + 1]);
        let (xmin, xmax) = (p1.x.min(p2.x), p1.x.max(p2.x));
        let (ymin, ymax) = (p1.y.min(p2.y), p1.y.max(p2.y));
        for j in i + 2..n - 1 {
            let (q1, q2) = (&shape[j], &shape[j + 1]);
            if q1.x.max(q2.x) < xmin || q1.x.min(q2.x) > xmax {
                continue;
            }
            if q1.y.max(q2.y) < ymin || q1.y.min(q2.y) > ymax {
                continue;
            }
            let d1 = cross(p1, p2, q1);
            let d2 = cross(p1, p2, q2);
            let d3 = cross(q1, q2, p1);
            let d4 = cross(q1, q2, p2);
            if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
                return true;
            }
        }
    }
    false
}

/// The path of the load in a continuation: geometric in 1 + w when the direction is kept (or
/// the start is weightless; the rod's response scales with √w), linear in the load vector
/// otherwise.
struct LoadPath {
    from: Gravity,
    to: Gravity,
    geometric: bool,
}

impl LoadPath {
    fn new(from: &Gravity, to: &Gravity) -> Self {
        let geometric = from.is_weightless() || from.direction() == to.direction();
        Self {
            from: *from,
            to: *to,
            geometric,
        }
    }

    fn initial_step(&self) -> f64 {
        if self.geometric {
            let ratio = ((1.0 + self.to.weight()) / (1.0 + self.from.weight()))
                .ln()
                .abs();
            (0.3 / ratio.max(1e-9)).min(1.0)
        } else {
            0.05
        }
    }

    fn at(&self, s: f64) -> Result<Gravity, RodError> {
        if s >= 1.0 {
            return Ok(self.to);
        }
        if self.geometric {
            let (w0, w1) = (1.0 + self.from.weight(), 1.0 + self.to.weight());
            return self.to.with_weight((w0 * (w1 / w0).powf(s) - 1.0).max(0.0));
        }
        let (l0, l1) = (self.from.load(), self.to.load());
        Gravity::from_load(
            [l0[0] + (l1[0] - l0[0]) * s, l0[1] + (l1[1] - l0[1]) * s],
            self.to.direction(),
        )
    }
}

/// Grid of the coarser of the two discretisations of the second variation, at least.
const MIN_GRID: usize = 200;
/// Grid points per unit of √max‖n‖ (the boundary layers are 1/√‖n‖ wide).
const GRID_PER_ROOT_FORCE: f64 = 24.0;
/// Finest grid.
const MAX_GRID: usize = 6000;
/// Relative width to which the coarse grid's least eigenvalue is bisected: its error is a
/// thousandth of the extrapolation's correction on the level cable (5e-4 at w = 2,000).
const COARSE_BISECTION_REL: f64 = 1e-9;

/// The least eigenvalue μ of the second variation of a heavy rod's energy on the tangent
/// space of its constraints (module docs; at a pinned or free end the variation is free there,
/// the natural boundary condition v' = 0, and a free tip drops the tip-position constraints),
/// in continuum units: the rod is stable iff μ > 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondVariation {
    /// μ extrapolated from two grids (h² Richardson).
    pub eigenvalue: f64,
    /// Its error estimate: the extrapolation's correction, |μ_fine − μ_coarse| / 3, plus the
    /// bisection's width.
    pub error: f64,
    /// Negative eigenvalues on the fine grid (the Morse index: 0 for a stable rod).
    pub index: usize,
    /// Points of the coarse grid (the fine one has twice as many).
    pub grid: usize,
    /// μ₀ of the straight weightless rod held by the same ends (the margin's unit):
    /// [`STRAIGHT_ROD_EIGENVALUE`] for both ends clamped.
    pub straight: f64,
}

impl SecondVariation {
    /// True when μ exceeds its error estimate.
    pub fn stable(&self) -> bool {
        self.eigenvalue > self.error && self.index == 0
    }

    /// True when |μ| is within its error estimate.
    pub fn uncertain(&self) -> bool {
        self.eigenvalue.abs() <= self.error
    }

    /// μ / μ₀ with μ₀ the straight weightless rod's under the same ends (`straight`): a margin
    /// that is 1 for that rod and does not shrink with w for a hanging cable.
    pub fn normalised(&self) -> f64 {
        self.eigenvalue / self.straight
    }

    fn of(cable: &Cable) -> Result<Self, RodError> {
        let (fine, coarse, points) = Self::grids(cable)?;
        let (eigenvalue, error, index) = Self::extrapolated(&fine, &coarse);
        Ok(Self {
            eigenvalue,
            error,
            index,
            grid: points,
            straight: Self::straight_rod(cable.ends),
        })
    }

    /// The fine and the coarse grid of `cable`'s second variation, and the coarse grid's points.
    fn grids(cable: &Cable) -> Result<(Grid, Grid, usize), RodError> {
        let fmax = force_max(cable.force, cable.gravity.load());
        let coarse =
            ((GRID_PER_ROOT_FORCE * fmax.sqrt()).ceil() as usize).clamp(MIN_GRID, MAX_GRID / 2);
        let fine = 2 * coarse;
        let ts: Vec<f64> = (0..=fine).map(|i| i as f64 / fine as f64).collect();
        let load = cable.gravity.load();
        let mut sin = vec![0.0; fine + 1];
        let mut cos = vec![0.0; fine + 1];
        let mut tension = vec![0.0; fine + 1];
        cable.sample(&ts, |i, y| {
            let (s, c) = y[2].sin_cos();
            let t = ts[i];
            let n = [cable.force[0] - t * load[0], cable.force[1] - t * load[1]];
            sin[i] = s;
            cos[i] = c;
            tension[i] = n[0] * c + n[1] * s;
        })?;
        let ends = cable.ends;
        Ok((
            Grid::new(&sin, &cos, &tension, 1, ends),
            Grid::new(&sin, &cos, &tension, 2, ends),
            coarse,
        ))
    }

    /// (μ, its error, the fine grid's index) from a fine grid and one twice as coarse. The
    /// fine grid's μ is bracketed around the coarse one's and bisected only until its width is
    /// a hundredth of their difference (that difference, the extrapolation's correction, is
    /// most of the error anyway): 2.0× fewer counts than bisecting both to 1e-11.
    fn extrapolated(fine: &Grid, coarse: &Grid) -> (f64, f64, usize) {
        let (mu_c, width_c) = coarse.least_eigenvalue();
        let (mu_f, width_f) = fine.least_eigenvalue_near(mu_c);
        let eigenvalue = mu_f + (mu_f - mu_c) / 3.0;
        let error = (mu_f - mu_c).abs() / 3.0 + width_f + width_c + 1e-9 * mu_f.abs();
        (eigenvalue, error, fine.count_below(0.0))
    }

    /// μ₀ of the straight weightless rod (θ = 0, no force) held by `ends`: 4ξ² (tan ξ = ξ) when
    /// both are clamped, else computed on the grid (e.g. (π/2)² for a free tip).
    pub fn straight_rod(ends: HeldEnds) -> f64 {
        if ends.both_clamped() {
            return STRAIGHT_ROD_EIGENVALUE;
        }
        let n = 2 * MIN_GRID;
        let (sin, cos, tension) = (vec![0.0; n + 1], vec![1.0; n + 1], vec![0.0; n + 1]);
        let fine = Grid::new(&sin, &cos, &tension, 1, ends);
        let coarse = Grid::new(&sin, &cos, &tension, 2, ends);
        Self::extrapolated(&fine, &coarse).0
    }
}

/// The second variation on a uniform grid (linear elements, lumped masses): the unknowns are
/// v_j at the interior points, and at a pinned or free end its end point too (mass h/2,
/// stiffness row 1/h: the natural condition v' = 0 in the weak form). The matrix is
/// A(σ) = K + M (diag(c) − σ) with K the stiffness (tridiag(−1, 2, −1)/h) and M the masses;
/// while the tip's position is held, two constraint rows m_j sin θ_j, m_j cos θ_j.
struct Grid {
    h: f64,
    diag: Vec<f64>,
    sin: Vec<f64>,
    cos: Vec<f64>,
    mass: Vec<f64>,
    stiffness: Vec<f64>,
    constrained: bool,
    /// The factors and solves of one count, kept between the bisection's counts.
    scratch: std::cell::RefCell<Scratch>,
}

/// Work space of [`Grid::count_below`]: pivots, multipliers and A⁻¹ C's two columns.
struct Scratch {
    d: Vec<f64>,
    l: Vec<f64>,
    us: Vec<f64>,
    uc: Vec<f64>,
}

impl Grid {
    fn new(sin: &[f64], cos: &[f64], tension: &[f64], stride: usize, ends: HeldEnds) -> Self {
        let n = (sin.len() - 1) / stride;
        let h = 1.0 / n as f64;
        let first = usize::from(ends.base() == EndCondition::Clamped);
        let last = if ends.tip() == EndCondition::Clamped {
            n - 1
        } else {
            n
        };
        let pick = |v: &[f64]| (first..=last).map(|j| v[j * stride]).collect::<Vec<_>>();
        let at_end = |j: usize| j == 0 || j == n;
        Self {
            h,
            diag: pick(tension),
            sin: pick(sin),
            cos: pick(cos),
            mass: (first..=last)
                .map(|j| if at_end(j) { 0.5 * h } else { h })
                .collect(),
            stiffness: (first..=last)
                .map(|j| if at_end(j) { 1.0 / h } else { 2.0 / h })
                .collect(),
            constrained: ends.tip() != EndCondition::Free,
            scratch: std::cell::RefCell::new(Scratch {
                d: vec![0.0; last + 1 - first],
                l: vec![0.0; last + 1 - first],
                us: vec![0.0; last + 1 - first],
                uc: vec![0.0; last + 1 - first],
            }),
        }
    }

    /// Eigenvalues of the constrained problem below σ: neg(A) + pos(Cᵀ A⁻¹ C) − 2 (the
    /// inertia of the bordered matrix, Haynsworth; C has rank 2), neg(A) without constraints.
    fn count_below(&self, sigma: f64) -> usize {
        self.count(sigma, false)
    }

    /// Whether the constrained problem has an eigenvalue below σ: the bisection's question,
    /// answered by the inertia of A(σ) alone when it has no negative pivot (then none: the
    /// constraints only raise eigenvalues) or three or more (then some).
    fn has_eigenvalue_below(&self, sigma: f64) -> bool {
        self.count(sigma, true) >= 1
    }

    /// [`Self::count_below`]; with `any`, a count that is only right as far as ≥ 1 goes.
    fn count(&self, sigma: f64, any: bool) -> usize {
        let off = -1.0 / self.h;
        let mut scratch = self.scratch.borrow_mut();
        let Scratch { d, l, us, uc } = &mut *scratch;
        // LDLᵀ of the tridiagonal A(σ): pivots d, multipliers l.
        let mut neg = 0usize;
        let mut prev = f64::INFINITY; // the first pivot is A's own diagonal
        let rows = self.stiffness.iter().zip(&self.mass).zip(&self.diag);
        for (((k, m), c), (dj, lj)) in rows.zip(d.iter_mut().zip(l.iter_mut())) {
            let mut pivot = k + m * (c - sigma) - off * off / prev;
            if pivot == 0.0 {
                pivot = -f64::EPSILON * (2.0 / self.h);
            }
            *lj = off / pivot;
            neg += usize::from(pivot < 0.0);
            *dj = pivot;
            prev = pivot;
        }
        if !self.constrained {
            return neg;
        }
        if neg == 0 || (any && neg >= 3) {
            // pos ≤ 2: none below σ without negative pivots, some with three or more.
            return neg.saturating_sub(2);
        }
        // A⁻¹ C for both constraint columns (m sin θ, m cos θ) by the same factors, and Cᵀ A⁻¹ C.
        let (mut ps, mut pc, mut pl) = (0.0, 0.0, 0.0);
        let columns = self.mass.iter().zip(&self.sin).zip(&self.cos);
        for (((m, sn), cs), ((ys, yc), lj)) in
            columns.zip(us.iter_mut().zip(uc.iter_mut()).zip(l.iter()))
        {
            *ys = m * sn - pl * ps;
            *yc = m * cs - pl * pc;
            (ps, pc, pl) = (*ys, *yc, *lj);
        }
        let (mut ns, mut nc) = (0.0, 0.0);
        let (mut s11, mut s12, mut s22) = (0.0, 0.0, 0.0);
        let back = us.iter_mut().zip(uc.iter_mut()).zip(d.iter().zip(l.iter()));
        let weights = self.mass.iter().zip(&self.sin).zip(&self.cos);
        for (((ys, yc), (dj, lj)), ((m, sn), cs)) in back.zip(weights).rev() {
            *ys = *ys / dj - lj * ns;
            *yc = *yc / dj - lj * nc;
            (ns, nc) = (*ys, *yc);
            s11 += ns * m * sn;
            s12 += nc * m * sn;
            s22 += nc * m * cs;
        }
        // Positive eigenvalues of the symmetric 2×2 [[s11, s12], [s12, s22]].
        let tr = s11 + s22;
        let det = s11 * s22 - s12 * s12;
        let pos = if det > 0.0 {
            if tr > 0.0 {
                2
            } else {
                0
            }
        } else {
            1
        };
        (neg + pos).saturating_sub(2)
    }

    /// The least eigenvalue by bisection on the counts to [`COARSE_BISECTION_REL`], and the
    /// bracket's half width.
    fn least_eigenvalue(&self) -> (f64, f64) {
        let cmin = self.diag.iter().cloned().fold(f64::INFINITY, f64::min);
        let lo = cmin - 1.0;
        let mut hi = lo.abs().max(1.0) + 100.0;
        while !self.has_eigenvalue_below(hi) && hi < 1e12 {
            hi = hi * 2.0 + 100.0;
        }
        self.bisect(lo, hi, |lo, hi| {
            hi - lo <= COARSE_BISECTION_REL * (1.0 + hi.abs())
        })
    }

    /// The least eigenvalue near `guess` (the coarse grid's), bracketed by the counts within
    /// ±1 % of it (else searched as [`Self::least_eigenvalue`]), bisected until the bracket is
    /// a hundredth of its distance to `guess` or 1e-11 relative.
    fn least_eigenvalue_near(&self, guess: f64) -> (f64, f64) {
        let delta = 1e-2 * guess.abs().max(1.0);
        let (lo, hi) = (guess - delta, guess + delta);
        if self.has_eigenvalue_below(lo) || !self.has_eigenvalue_below(hi) {
            return self.least_eigenvalue();
        }
        self.bisect(lo, hi, |lo, hi| {
            let width = hi - lo;
            width <= 1e-2 * (0.5 * (lo + hi) - guess).abs() || width <= 1e-11 * (1.0 + hi.abs())
        })
    }

    /// Bisection of the first eigenvalue in [lo, hi] (none below lo, one or more below hi)
    /// until `done(lo, hi)`: the midpoint and the half width.
    fn bisect(&self, mut lo: f64, mut hi: f64, done: impl Fn(f64, f64) -> bool) -> (f64, f64) {
        for _ in 0..200 {
            if done(lo, hi) {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if self.has_eigenvalue_below(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        (0.5 * (lo + hi), 0.5 * (hi - lo))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cables whose second variations the tests take apart, integrated from the base (the
    /// grids need a state, not an equilibrium): the level cable's base wrench at w = 200 and
    /// 2,000, a tilted one, and a cable hanging by a free tip.
    fn cables() -> Vec<Cable> {
        let mut out = Vec::new();
        for (w, a) in [
            (200.0, PlanarParams::new(-9.0, 60.0, -100.0)),
            (2_000.0, PlanarParams::new(-32.9, 557.7, -1_000.0)),
            (2_000.0, PlanarParams::new(12.0, -300.0, -700.0)),
        ] {
            let g = Gravity::new(w, [0.0, -1.0]).expect("gravity");
            out.push(Cable::from_params(&a, &g).expect("integrated"));
        }
        let g = Gravity::new(300.0, [0.3, -1.0]).expect("gravity");
        let free = HeldEnds::new(EndCondition::Clamped, EndCondition::Free).expect("ends");
        out.push(Cable::held(0.0, &PlanarParams::new(2.0, 0.0, 0.0), &g, free).expect("held"));
        out
    }

    /// The bisection's shortcut (the inertia of A(σ) alone when it has no negative pivot or
    /// three or more) answers as the full count does, across each grid's spectrum.
    #[test]
    fn the_bisection_question_agrees_with_the_count() {
        for cable in cables() {
            let (fine, coarse, _) = SecondVariation::grids(&cable).expect("grids");
            for grid in [&fine, &coarse] {
                let (mu, _) = grid.least_eigenvalue();
                for k in -40..=40 {
                    let sigma = mu + f64::from(k) * 0.05 * mu.abs().max(1.0);
                    assert_eq!(
                        grid.has_eigenvalue_below(sigma),
                        grid.count_below(sigma) >= 1,
                        "sigma {sigma}, least eigenvalue {mu}"
                    );
                }
            }
        }
    }

    /// The fine grid's eigenvalue bracketed near the coarse one's equals the full bisection's
    /// within their widths, and that width is at most a hundredth of the extrapolation's
    /// correction (or 1e-11 relative).
    #[test]
    fn the_bracketed_eigenvalue_is_the_bisected_one() {
        for cable in cables() {
            let (fine, coarse, _) = SecondVariation::grids(&cable).expect("grids");
            let (mu_c, _) = coarse.least_eigenvalue();
            let (near, width) = fine.least_eigenvalue_near(mu_c);
            let (full, full_width) = fine.least_eigenvalue();
            assert!(
                (near - full).abs() <= width + full_width,
                "bracketed {near} ± {width}, bisected {full} ± {full_width}"
            );
            let correction = (near - mu_c).abs();
            assert!(
                2.0 * width <= 1e-2 * correction + 1e-11 * (1.0 + near.abs()) + 1e-3 * width,
                "width {width} against the correction {correction}"
            );
        }
    }
}
