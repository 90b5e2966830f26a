//! Long cables in 3-D: the heavy 3-D rod by multiple shooting (issue 51, item 5).
//!
//! Single shooting from the base ([`super::heavy`]) amplifies every rounding of a by the growth
//! of the linearised rod, ≈ e^{√(‖n‖/c)}: at w = 2,000 an f64 `a` no longer reproduces the
//! tip. As for the planar cable ([`crate::planar::heavy::cable`]), the rod is cut at nodes
//! 0 = t₀ < … < t_M = 1, each segment amplifying errors by at most e^{`GROWTH_PER_SEGMENT`},
//! and the unknowns are a and the state of every interior node in the reduced formulation of
//! [`super::heavy`]: its orientation R_k, position p_k and P_k = ∫₀^{t_k} p (which, with a,
//! gives the internal moment there: m = Rᵀ(a_m − P × w ĝ − p × n(t))).
//!
//! Node corrections are body twists (R ← R exp(ε_ω), p ← p + R ε_v) and world δP, so the
//! segments' variational columns (∂/∂ε, ∂/∂δP, ∂/∂a; 15 columns of 9 rows) are the blocks of
//! the Newton matrix. The equations: each segment ends where the next begins
//! (log(R_{k+1}ᵀ R_e), R_{k+1}ᵀ(p_e − p_{k+1}), P_e − P_{k+1}) and the last ends at the
//! target (its body error). The condition of this system does not grow with w.
//!
//! Stability (docs/math.md §10): det J(t) > 0 on the grid t = i/2000 ∈ [0.02, 1], as for the
//! single-shooting rod, but with J(t) carried across the nodes as an orthonormal basis: the
//! columns X(t) = ∂(η, P, a)/∂a (15 × 6) are re-orthonormalised at every node (X = Q U, the
//! sign and the log of det U kept), so that det J(t) = det X_η(t) · det U never overflows. The
//! margin is the single-shooting rod's (det J / its small-t leading term), formed in logs.

// `!(x > y)` comparisons deliberately reject NaN; index loops mirror the formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use super::heavy_ode::{self, Gravity3, NB};
use super::{SpatialParams, SpatialPose, Stiffness};
use crate::conjugate::Stream;
use crate::ends::EndCondition;
use crate::ode::{dop853, OdeOptions};
use crate::planar::heavy::cable::{lu_sign, CableError, GROWTH_PER_SEGMENT, MAX_SEGMENTS};
use crate::{RodError, StabilityReport};
use nalgebra::{DMatrix, DVector, Quaternion, SMatrix, UnitQuaternion, Vector3};
use std::ops::ControlFlow;
use std::sync::Mutex;

mod motion;

/// Variational columns of a segment: ε_ω, ε_v, δP at its start (9), then δa (6).
const COLUMNS: usize = 15;
/// Rows per column: η (6), δP (3).
const ROWS: usize = 9;
/// State of a segment with its variations.
const FULL: usize = NB + ROWS * COLUMNS;
/// Relative tolerance of each segment's integration.
const SEGMENT_RTOL: f64 = 1e-12;
/// Newton iterations of one solve.
const NEWTON_ITERATIONS: usize = 30;
/// Residual (rod lengths, radians) at which Newton has converged.
const RESIDUAL_TOLERANCE: f64 = 1e-11;
/// The stability grid: t = i / `GRID` for i ≥ `GRID_FROM` (docs/math.md §10).
const GRID: u32 = 2000;
const GRID_FROM: u32 = 40;
/// |det X_η| / Π‖rows of X_η‖ below which the verdict is left undecided (rounding of the
/// segments' columns).
const MARGIN_FLOOR: f64 = 1e-12;

/// The state of the rod at one node (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Node {
    rotation: UnitQuaternion<f64>,
    position: Vector3<f64>,
    /// P = ∫₀ᵗ p.
    moment_arm: Vector3<f64>,
}

impl Node {
    const BASE: Node = Node {
        rotation: UnitQuaternion::new_unchecked(Quaternion::new(1.0, 0.0, 0.0, 0.0)),
        position: Vector3::new(0.0, 0.0, 0.0),
        moment_arm: Vector3::new(0.0, 0.0, 0.0),
    };

    fn of_state(s: &[f64]) -> Self {
        let q = Quaternion::new(s[0], s[1], s[2], s[3]);
        Self {
            rotation: UnitQuaternion::new_normalize(q),
            position: Vector3::new(s[4], s[5], s[6]),
            moment_arm: Vector3::new(s[8], s[9], s[10]),
        }
    }

    /// This node's offset from `from`: the body turn log(R_fromᵀ R), the shift p − p_from
    /// in the frame `frame`, and P − P_from (the residual's node rows and a continuation's
    /// secant, module docs).
    fn offset_from(&self, from: &Node, frame: &UnitQuaternion<f64>) -> [f64; ROWS] {
        let turn = (from.rotation.inverse() * self.rotation).scaled_axis();
        let shift = frame.inverse() * (self.position - from.position);
        let arm = self.moment_arm - from.moment_arm;
        std::array::from_fn(|i| match i / 3 {
            0 => turn[i],
            1 => shift[i - 3],
            _ => arm[i - 6],
        })
    }

    /// The node moved by the correction (ε_ω, ε_v, δP) (module docs).
    fn moved(&self, d: &[f64]) -> Self {
        let eps = Vector3::new(d[0], d[1], d[2]);
        Self {
            rotation: self.rotation * UnitQuaternion::from_scaled_axis(eps),
            position: self.position + self.rotation * Vector3::new(d[3], d[4], d[5]),
            moment_arm: self.moment_arm + Vector3::new(d[6], d[7], d[8]),
        }
    }
}

/// What the equations at a 3-D cable's tip hold (issue 52): its six last rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TipGoal {
    /// A clamped tip at this pose: its body error (6 rows).
    Pose(SpatialPose),
    /// A pinned tip at this position (base frame): p(1) − target (3 rows) and no moment there,
    /// M(1) = 0 (3 rows).
    Position(Vector3<f64>),
    /// A free tip: no moment, M(1) = 0 (3 rows), and no force but `tip_load`, i.e. the base
    /// force a_f = w ĝ + tip_load (3 rows).
    Free {
        /// A point force at the tip (base frame; zero for a cable hanging free).
        tip_load: Vector3<f64>,
    },
}

impl TipGoal {
    /// The goal `s` of the way from `self` to `to` (positions and forces on a line,
    /// orientations by slerp); None when the two are not of one kind.
    fn between(&self, to: &TipGoal, s: f64) -> Option<TipGoal> {
        match (self, to) {
            (TipGoal::Pose(a), TipGoal::Pose(b)) => Some(TipGoal::Pose(SpatialPose {
                position: a.position + (b.position - a.position) * s,
                rotation: a.rotation.slerp(&b.rotation, s),
            })),
            (TipGoal::Position(a), TipGoal::Position(b)) => {
                Some(TipGoal::Position(a + (b - a) * s))
            }
            (TipGoal::Free { tip_load: a }, TipGoal::Free { tip_load: b }) => Some(TipGoal::Free {
                tip_load: a + (b - a) * s,
            }),
            _ => None,
        }
    }
}

/// A heavy 3-D rod in equilibrium as the states of its nodes: what multiple shooting solves
/// for (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialCable {
    stiffness: Stiffness,
    gravity: Gravity3,
    mesh: Vec<f64>,
    a: [f64; 6],
    /// Node states at t₀ … t_{M−1}; the first is the base.
    nodes: Vec<Node>,
    /// The base is pinned (issue 52): a_m = 0, and the base's orientation is an unknown in
    /// a_m's place (its correction ε_ω takes the first three slots of the unknowns).
    pinned_base: bool,
}

fn ode_options() -> OdeOptions {
    OdeOptions {
        rtol: SEGMENT_RTOL,
        atol: SEGMENT_RTOL,
        max_steps: 20_000,
        error_components: NB,
        ..OdeOptions::default()
    }
}

/// Segments for internal forces up to `force_max` on bending stiffness `c`:
/// √(force_max / c) · h ≤ [`GROWTH_PER_SEGMENT`].
pub fn segments_for(force_max: f64, c: f64) -> usize {
    let m = ((force_max.max(0.0) / c).sqrt() / GROWTH_PER_SEGMENT).ceil() as usize;
    m.clamp(2, MAX_SEGMENTS)
}

impl SpatialCable {
    /// The cable whose base wrench is `a`, its nodes integrated from the base on a mesh fit
    /// for its forces: exact where single shooting is (w ≲ 300), elsewhere a starting guess
    /// that [`SpatialCable::solve`] corrects.
    pub fn from_params(
        a: &SpatialParams,
        stiffness: &Stiffness,
        gravity: &Gravity3,
    ) -> Result<Self, RodError> {
        super::check_params(a, stiffness)?;
        let a: [f64; 6] = std::array::from_fn(|i| a[i]);
        let load = gravity.load();
        let n0 = Vector3::new(a[3], a[4], a[5]);
        let n1 = n0 - Vector3::from(load);
        let c = stiffness.c2.min(stiffness.c3);
        let segments = segments_for(n0.norm().max(n1.norm()), c);
        let mesh: Vec<f64> = (0..=segments).map(|i| i as f64 / segments as f64).collect();
        let mut cable = Self {
            stiffness: *stiffness,
            gravity: *gravity,
            mesh,
            a,
            nodes: vec![Node::BASE],
            pinned_base: false,
        };
        for k in 0..segments - 1 {
            let e = cable.segment::<NB>(k)?;
            cable.nodes.push(Node::of_state(&e));
        }
        Ok(cable)
    }

    /// The cable with base wrench `a` whose nodes on `mesh` (t₀ = 0 < … < t_M = 1) have the
    /// orientations and positions `poses` (at t₀ … t_{M−1}; the first is the base): each
    /// node's P = ∫p is carried from the previous one by its segment. How an answer of another
    /// formulation (the planar cable's nodes) becomes a start of this one.
    pub fn from_poses(
        a: &SpatialParams,
        stiffness: &Stiffness,
        gravity: &Gravity3,
        mesh: Vec<f64>,
        poses: &[(UnitQuaternion<f64>, Vector3<f64>)],
    ) -> Result<Self, RodError> {
        Self::through_poses(a, stiffness, gravity, mesh, poses, false)
    }

    /// [`SpatialCable::from_poses`] pinned at its base: the first pose's orientation is the
    /// base's (a_m is set to 0).
    pub fn pinned_from_poses(
        a: &SpatialParams,
        stiffness: &Stiffness,
        gravity: &Gravity3,
        mesh: Vec<f64>,
        poses: &[(UnitQuaternion<f64>, Vector3<f64>)],
    ) -> Result<Self, RodError> {
        Self::through_poses(a, stiffness, gravity, mesh, poses, true)
    }

    fn through_poses(
        a: &SpatialParams,
        stiffness: &Stiffness,
        gravity: &Gravity3,
        mesh: Vec<f64>,
        poses: &[(UnitQuaternion<f64>, Vector3<f64>)],
        pinned_base: bool,
    ) -> Result<Self, RodError> {
        super::check_params(a, stiffness)?;
        if mesh.len() < 2 || poses.len() + 1 != mesh.len() {
            return Err(RodError::OutOfDomain(
                "a cable needs one pose per node of its mesh".into(),
            ));
        }
        let mut base = Node::BASE;
        let mut a: [f64; 6] = std::array::from_fn(|i| a[i]);
        if pinned_base {
            base.rotation = poses[0].0;
            a[..3].fill(0.0);
        }
        let mut cable = Self {
            stiffness: *stiffness,
            gravity: *gravity,
            mesh,
            a,
            nodes: vec![base],
            pinned_base,
        };
        for (rotation, position) in &poses[1..] {
            let k = cable.nodes.len() - 1;
            let e = cable.segment::<NB>(k)?;
            cable.nodes.push(Node {
                rotation: *rotation,
                position: *position,
                moment_arm: Vector3::new(e[8], e[9], e[10]),
            });
        }
        Ok(cable)
    }

    /// The same rod pinned at its base: its base turned to `rotation` (base frame of the
    /// grippers; the base position stays at the origin), no moment there (a_m is set to 0),
    /// the nodes kept. Where the nodes do not fit the turned base, [`SpatialCable::solve_goal`]
    /// moves them.
    pub fn pinned_at(mut self, rotation: UnitQuaternion<f64>) -> Self {
        self.nodes[0].rotation = rotation;
        self.a[..3].fill(0.0);
        self.pinned_base = true;
        self
    }

    /// The cable of [`SpatialCable::from_params`] pinned at its base, turned to `rotation`:
    /// its nodes integrated from that base.
    pub fn pinned_from_params(
        a: &SpatialParams,
        stiffness: &Stiffness,
        gravity: &Gravity3,
        rotation: UnitQuaternion<f64>,
    ) -> Result<Self, RodError> {
        let mut cable = Self::from_params(a, stiffness, gravity)?.pinned_at(rotation);
        cable.nodes.truncate(1);
        for k in 0..cable.segments() - 1 {
            let e = cable.segment::<NB>(k)?;
            cable.nodes.push(Node::of_state(&e));
        }
        Ok(cable)
    }

    /// The mesh t₀ = 0 < … < t_M = 1.
    pub fn mesh(&self) -> &[f64] {
        &self.mesh
    }

    /// The orientation and position of the nodes at t₀ … t_{M−1} (the first is the base).
    pub fn node_poses(&self) -> Vec<(UnitQuaternion<f64>, Vector3<f64>)> {
        self.nodes
            .iter()
            .map(|n| (n.rotation, n.position))
            .collect()
    }

    /// The base's orientation (the identity unless the base is pinned).
    pub fn base_rotation(&self) -> UnitQuaternion<f64> {
        self.nodes[0].rotation
    }

    /// True when the base is pinned.
    pub fn is_base_pinned(&self) -> bool {
        self.pinned_base
    }

    /// a = (a_m, a_f): the base wrench.
    pub fn params(&self) -> SpatialParams {
        SpatialParams::from_row_slice(&self.a)
    }

    /// Segments of the mesh.
    pub fn segments(&self) -> usize {
        self.mesh.len() - 1
    }

    /// The gravity this cable carries.
    pub fn gravity(&self) -> &Gravity3 {
        &self.gravity
    }

    /// Segment `k` from its start node; with `N` = the full state, its variational columns.
    fn segment<const N: usize>(&self, k: usize) -> Result<[f64; N], RodError> {
        let y = self.start_state::<N>(k);
        let var = N == FULL;
        let (ci, a, load) = (self.stiffness.inv(), self.a, self.gravity.load());
        let (end, _) = dop853::solve(
            |t, s: &[f64; N], ds: &mut [f64; N]| {
                heavy_ode::rhs::<N, COLUMNS>(&ci, &a, load, t, s, ds, var)
            },
            self.mesh[k],
            y,
            self.mesh[k + 1],
            &ode_options(),
        )?;
        super::finite(&end)?;
        Ok(end)
    }

    /// The tip pose (the last segment's end).
    pub fn tip(&self) -> Result<SpatialPose, RodError> {
        Ok(self.tip_and_moment_arm()?.0)
    }

    /// The tip pose and P(1) = ∫₀¹ p (the world moment at the tip is a_m − P(1) × w ĝ).
    pub fn tip_and_moment_arm(&self) -> Result<(SpatialPose, Vector3<f64>), RodError> {
        let e = self.segment::<NB>(self.segments() - 1)?;
        Ok((
            super::pose_from_parts([e[0], e[1], e[2], e[3]], [e[4], e[5], e[6]]),
            Vector3::new(e[8], e[9], e[10]),
        ))
    }

    /// The poses at `ts` (sorted, in [0, 1]), each from the segment holding it.
    pub fn poses_at(&self, ts: &[f64]) -> Result<Vec<SpatialPose>, RodError> {
        let mut out = Vec::with_capacity(ts.len());
        let (ci, a, load) = (self.stiffness.inv(), self.a, self.gravity.load());
        for k in 0..self.segments() {
            let (t0, t1) = (self.mesh[k], self.mesh[k + 1]);
            let last = k + 1 == self.segments();
            let inside: Vec<f64> = ts
                .iter()
                .copied()
                .filter(|&t| t >= t0 && (t < t1 || (last && t <= t1)))
                .collect();
            if inside.is_empty() {
                continue;
            }
            let mut start = self.start_state::<NB>(k);
            if inside[0] == t0 {
                out.push(super::pose_from_parts(
                    [start[0], start[1], start[2], start[3]],
                    [start[4], start[5], start[6]],
                ));
            }
            let rest: Vec<f64> = inside.into_iter().filter(|&t| t > t0).collect();
            if rest.is_empty() {
                continue;
            }
            start[7] = 0.0;
            dop853::solve_dense(
                |t, s: &[f64; NB], ds: &mut [f64; NB]| {
                    heavy_ode::rhs::<NB, COLUMNS>(&ci, &a, load, t, s, ds, false)
                },
                t0,
                start,
                &rest,
                &ode_options(),
                |_, _, s| {
                    out.push(super::pose_from_parts(
                        [s[0], s[1], s[2], s[3]],
                        [s[4], s[5], s[6]],
                    ));
                    ControlFlow::Continue(())
                },
            )?;
        }
        Ok(out)
    }

    /// The wrenches the rod exerts on its grippers ([`crate::wrench::spatial`]): the world
    /// wrench at the tip n(1) = a_f − w ĝ and, about the base, a_m − P(1) × w ĝ.
    pub fn wrenches(
        &self,
    ) -> Result<crate::wrench::GripperWrenches<crate::wrench::SpatialWrench>, RodError> {
        let (tip, arm) = self.tip_and_moment_arm()?;
        let l = Vector3::from(self.gravity.load());
        let a = self.params();
        let (am, af) = (
            Vector3::new(a[0], a[1], a[2]),
            Vector3::new(a[3], a[4], a[5]),
        );
        Ok(crate::wrench::spatial(&a, &tip, af - l, am - arm.cross(&l)))
    }

    /// Elastic energy and total energy (elastic + gravitational, −w ĝ · P(1)).
    pub fn energies(&self) -> Result<(f64, f64), RodError> {
        let mut elastic = 0.0;
        let mut last = [0.0; NB];
        for k in 0..self.segments() {
            last = self.segment::<NB>(k)?;
            elastic += last[7];
        }
        let load = self.gravity.load();
        let potential = -(load[0] * last[8] + load[1] * last[9] + load[2] * last[10]);
        Ok((elastic, elastic + potential))
    }

    fn dimension(&self) -> usize {
        6 + ROWS * (self.segments() - 1)
    }

    fn set_unknowns_moved(&mut self, step: &DVector<f64>, alpha: f64) {
        let first = if self.pinned_base {
            let d: [f64; ROWS] = std::array::from_fn(|c| if c < 3 { alpha * step[c] } else { 0.0 });
            self.nodes[0] = self.nodes[0].moved(&d);
            3
        } else {
            0
        };
        for i in first..6 {
            self.a[i] += alpha * step[i];
        }
        for k in 1..self.segments() {
            let d: [f64; ROWS] = std::array::from_fn(|c| alpha * step[6 + ROWS * (k - 1) + c]);
            self.nodes[k] = self.nodes[k].moved(&d);
        }
    }

    /// Residual of the multiple-shooting equations (module docs) and, with `jacobian`, their
    /// derivative in the unknowns (a, then each node's correction).
    fn residual(
        &self,
        goal: &TipGoal,
        jacobian: bool,
    ) -> Result<(DVector<f64>, Option<DMatrix<f64>>), RodError> {
        let m = self.segments();
        let dim = self.dimension();
        let mut r = DVector::zeros(dim);
        let mut j = jacobian.then(|| DMatrix::zeros(dim, dim));
        for k in 0..m {
            let e = if jacobian {
                self.segment::<FULL>(k)?
            } else {
                let mut e = [0.0; FULL];
                e[..NB].copy_from_slice(&self.segment::<NB>(k)?);
                e
            };
            if k + 1 < m {
                self.continuity_rows(k, &e, &mut r, j.as_mut());
            } else if let TipGoal::Pose(target) = goal {
                tip_rows(self.pinned_base, k, &e, target, &mut r, j.as_mut());
            } else {
                self.held_tip_rows(k, &e, goal, &mut r, j.as_mut());
            }
        }
        Ok((r, j))
    }

    /// The world moment at the end `e` of the last segment, M(1) = a_m − P(1) × w ĝ −
    /// p(1) × n(1) with n(1) = a_f − w ĝ (module docs of [`super::heavy`]), and, for column `c`
    /// of that segment's variations, its derivative: δa_m − δP × w ĝ − (R η_v) × n(1) −
    /// p(1) × δa_f.
    fn tip_moment(&self, e: &[f64; FULL], column: Option<usize>) -> Vector3<f64> {
        let l = Vector3::from(self.gravity.load());
        let end = Node::of_state(e);
        let n1 = Vector3::new(self.a[3], self.a[4], self.a[5]) - l;
        let Some(c) = column else {
            let am = Vector3::new(self.a[0], self.a[1], self.a[2]);
            return am - end.moment_arm.cross(&l) - end.position.cross(&n1);
        };
        let col = |rr: usize| e[NB + COLUMNS * rr + c];
        let dp_world = end.rotation * Vector3::new(col(3), col(4), col(5));
        let d_arm = Vector3::new(col(6), col(7), col(8));
        let mut d = -d_arm.cross(&l) - dp_world.cross(&n1);
        if c >= ROWS {
            let mut unit = [0.0; 6];
            unit[c - ROWS] = 1.0;
            d += Vector3::new(unit[0], unit[1], unit[2]);
            d -= end.position.cross(&Vector3::new(unit[3], unit[4], unit[5]));
        }
        d
    }

    /// The last rows for a pinned or free tip ([`TipGoal`]): the position (pinned) or the base
    /// force (free), then M(1) = 0, scaled by 1 / max(1, ‖a‖∞) so that its rounding compares
    /// with the position's.
    fn held_tip_rows(
        &self,
        k: usize,
        e: &[f64; FULL],
        goal: &TipGoal,
        r: &mut DVector<f64>,
        j: Option<&mut DMatrix<f64>>,
    ) {
        let row = ROWS * k;
        let scale = 1.0 / self.a.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        let end = Node::of_state(e);
        let first = match goal {
            TipGoal::Position(p) => end.position - p,
            TipGoal::Free { tip_load } => {
                let l = Vector3::from(self.gravity.load());
                Vector3::new(self.a[3], self.a[4], self.a[5]) - l - tip_load
            }
            TipGoal::Pose(_) => unreachable!("a clamped tip has its own rows"),
        };
        // Pinned at both ends, an isotropic rod spun about its tangent by a constant angle is
        // the same rod (its twist is zero): the base's spin is fixed (a gauge row in place of
        // the tip's twisting moment, which is then zero by itself), the moment's bending
        // components taken in the tip's frame.
        let gauge = self.pinned_base && matches!(goal, TipGoal::Position(_));
        let to_tip = end.rotation.inverse();
        let body = |m: Vector3<f64>| if gauge { to_tip * m } else { m };
        let moment = body(self.tip_moment(e, None) * scale);
        for i in 0..3 {
            r[row + i] = first[i];
            r[row + 3 + i] = moment[i];
        }
        if gauge {
            r[row + 3] = 0.0;
        }
        let Some(j) = j else { return };
        for c in 0..COLUMNS {
            let Some(jc) = start_column(self.pinned_base, k, c) else {
                continue;
            };
            let mut dm = self.tip_moment(e, Some(c)) * scale;
            if gauge {
                // δ(Rᵀ M) = Rᵀ δM − η_ω × (Rᵀ M).
                let eta = Vector3::new(e[NB + c], e[NB + COLUMNS + c], e[NB + 2 * COLUMNS + c]);
                dm = to_tip * dm - eta.cross(&moment);
                dm[0] = 0.0;
            }
            let d_first = match goal {
                TipGoal::Position(_) => {
                    end.rotation
                        * Vector3::new(
                            e[NB + COLUMNS * 3 + c],
                            e[NB + COLUMNS * 4 + c],
                            e[NB + COLUMNS * 5 + c],
                        )
                }
                _ => Vector3::zeros(),
            };
            for i in 0..3 {
                j[(row + i, jc)] = d_first[i];
                j[(row + 3 + i, jc)] = dm[i];
            }
        }
        if gauge {
            j[(row + 3, 0)] = 1.0;
        }
        if matches!(goal, TipGoal::Free { .. }) {
            // a_f − w ĝ − load: ∂/∂a_f = 1.
            for i in 0..3 {
                j[(row + i, 3 + i)] = 1.0;
            }
        }
    }

    /// The rows "segment `k`, ended at `e`, ends at node k + 1" (module docs).
    fn continuity_rows(
        &self,
        k: usize,
        e: &[f64; FULL],
        r: &mut DVector<f64>,
        j: Option<&mut DMatrix<f64>>,
    ) {
        let (end, goal, row) = (Node::of_state(e), &self.nodes[k + 1], ROWS * k);
        let rho = end.offset_from(goal, &goal.rotation);
        r.rows_mut(row, ROWS).copy_from_slice(&rho);
        let Some(j) = j else { return };
        let rel = goal.rotation.inverse() * end.rotation;
        let rel_m = rel.to_rotation_matrix().into_inner();
        let col = |rr: usize, c: usize| e[NB + COLUMNS * rr + c];
        for c in 0..COLUMNS {
            let Some(jc) = start_column(self.pinned_base, k, c) else {
                continue;
            };
            let v = rel_m * Vector3::new(col(3, c), col(4, c), col(5, c));
            for i in 0..3 {
                j[(row + i, jc)] = col(i, c);
                j[(row + 3 + i, jc)] = v[i];
                j[(row + 6 + i, jc)] = col(6 + i, c);
            }
        }
        // The next node's own columns: R exp(ε) and p + R ε_v move the residual by −ε_ω,
        // ρ_v × ε_ω − ε_v and −δP.
        let next = 6 + ROWS * k;
        let skew = Vector3::new(rho[3], rho[4], rho[5]).cross_matrix();
        for i in 0..3 {
            j[(row + i, next + i)] = -1.0;
            j[(row + 3 + i, next + 3 + i)] = -1.0;
            j[(row + 6 + i, next + 6 + i)] = -1.0;
            for c in 0..3 {
                j[(row + 3 + i, next + c)] += skew[(i, c)];
            }
        }
    }

    /// Newton on the multiple-shooting equations from this cable's state: the equilibrium whose
    /// tip is at `target`. Backtracks on the residual's max norm. Returns the iterations.
    pub fn solve(&mut self, target: &SpatialPose) -> Result<usize, CableError> {
        self.solve_goal(&TipGoal::Pose(*target))
    }

    /// Newton on the multiple-shooting equations with the tip held by `goal` ([`TipGoal`]):
    /// as [`SpatialCable::solve`].
    pub fn solve_goal(&mut self, goal: &TipGoal) -> Result<usize, CableError> {
        self.solve_goal_signed(goal).map(|(it, _)| it)
    }

    /// [`SpatialCable::solve_goal`], with the sign of the determinant of the last Newton
    /// matrix it factored (None when it factored none: the cable was on `goal` already).
    fn solve_goal_signed(&mut self, goal: &TipGoal) -> Result<(usize, Option<f64>), CableError> {
        let target = goal;
        let mut sign = None;
        let (r, _) = self.residual(target, false)?;
        let mut norm = r.amax();
        for it in 0..NEWTON_ITERATIONS {
            if norm <= 1e-14 {
                return Ok((it, sign));
            }
            // Newton that has not come near after a third of its budget will not: give the
            // caller (a continuation halving its step) its time back.
            if it >= NEWTON_ITERATIONS / 3 && norm > 1e-6 {
                return Err(CableError::NoConvergence {
                    iterations: it,
                    residual: norm,
                });
            }
            let (r, j) = self.residual(target, true)?;
            let Some(j) = j else {
                return Err(CableError::Singular);
            };
            let lu = j.lu();
            sign = Some(lu_sign(&lu));
            let Some(step) = lu.solve(&(-&r)) else {
                return Err(CableError::Singular);
            };
            if !step.iter().all(|v| v.is_finite()) {
                return Err(CableError::Singular);
            }
            let mut alpha = 1.0;
            loop {
                let mut trial = self.clone();
                trial.set_unknowns_moved(&step, alpha);
                match trial.residual(target, false) {
                    Ok((rt, _)) if rt.amax() < (1.0 - 1e-4 * alpha) * norm => {
                        *self = trial;
                        norm = rt.amax();
                        break;
                    }
                    Err(RodError::Deadline { t }) => return Err(RodError::Deadline { t }.into()),
                    _ if alpha > 1.0 / 64.0 => alpha *= 0.5,
                    _ if norm <= RESIDUAL_TOLERANCE => return Ok((it, sign)),
                    _ => {
                        return Err(CableError::NoConvergence {
                            iterations: it,
                            residual: norm,
                        })
                    }
                }
            }
            let small = alpha * step.amax()
                <= 1e-10 * (1.0 + self.a.iter().fold(0.0, |m: f64, v| m.max(v.abs())));
            if norm <= RESIDUAL_TOLERANCE && small {
                return Ok((it + 1, sign));
            }
        }
        if norm <= RESIDUAL_TOLERANCE {
            return Ok((NEWTON_ITERATIONS, sign));
        }
        Err(CableError::NoConvergence {
            iterations: NEWTON_ITERATIONS,
            residual: norm,
        })
    }

    /// Moves this cable, in equilibrium on `from`, to an equilibrium on `to` along the straight
    /// path of targets between them (positions on a line, orientations by slerp), each step
    /// solved by [`SpatialCable::solve`] from the last: halved where Newton fails, lengthened by
    /// half where it succeeds. Returns the Newton iterations; fails where the step falls below
    /// 1/1024 of the way (a fold of the branch), after 64 steps taken or refused, or on the
    /// deadline. The cable is left where the last step converged.
    pub fn carry(&mut self, from: &SpatialPose, to: &SpatialPose) -> Result<usize, CableError> {
        let (dp, dr) = from.distance_to(to);
        if dp <= 1e-9 && dr <= 1e-9 {
            return self.solve(to);
        }
        self.carry_goal(&TipGoal::Pose(*from), &TipGoal::Pose(*to))
    }

    /// [`SpatialCable::carry`] between two tip goals of one kind ([`TipGoal`]): a pinned
    /// tip's position on a line, a free tip's load on a line.
    pub fn carry_goal(&mut self, from: &TipGoal, to: &TipGoal) -> Result<usize, CableError> {
        const MIN_STEP: f64 = 1.0 / 1024.0;
        if from.between(to, 1.0).is_none() {
            return Err(CableError::Singular);
        }
        let (mut s, mut ds, mut iterations) = (0.0_f64, 0.25_f64, 0);
        // At most this many steps, taken or refused (a way of 1,024 smallest steps is a fold).
        let mut budget = 64;
        while s < 1.0 {
            budget -= 1;
            if budget == 0 {
                return Err(CableError::NoConvergence {
                    iterations,
                    residual: f64::INFINITY,
                });
            }
            let next = (s + ds).min(1.0);
            let Some(goal) = from.between(to, next) else {
                return Err(CableError::Singular);
            };
            let mut trial = self.clone();
            match trial.solve_goal(&goal) {
                Ok(it) => {
                    *self = trial;
                    iterations += it;
                    s = next;
                    ds *= 1.5;
                }
                Err(CableError::Rod(RodError::Deadline { t })) => {
                    return Err(CableError::Rod(RodError::Deadline { t }))
                }
                Err(_) if ds > MIN_STEP => ds *= 0.5,
                Err(e) => return Err(e),
            }
        }
        Ok(iterations)
    }

    /// The residual's max norm at `target` (rod lengths, radians).
    pub fn residual_at(&self, target: &SpatialPose) -> Result<f64, RodError> {
        self.residual_at_goal(&TipGoal::Pose(*target))
    }

    /// The residual's max norm with the tip held by `goal` (the moment rows scaled as in
    /// Newton).
    pub fn residual_at_goal(&self, goal: &TipGoal) -> Result<f64, RodError> {
        Ok(self.residual(goal, false)?.0.amax())
    }

    /// Stability by the orthonormalised conjugate-point scan (module docs): det J(t) > 0 on
    /// the grid. The margin is the single-shooting rod's, min over t ≥ 0.05 of
    /// det J(t) / [`super::det_leading_term`], formed in logarithms; the verdict is left
    /// undecided where det X_η is within 1e-12 of the product of its rows' norms (the bound on
    /// its rounding, Hadamard's inequality).
    pub fn stability(&self) -> Result<StabilityReport, RodError> {
        Ok(self.conjugate_scan()?.0)
    }

    /// The verdict of [`SpatialCable::stability`], the Jacobi fields at the tip X(1) in the
    /// orthonormalised basis (15 × 6) and the state at the tip.
    fn conjugate_scan(&self) -> Result<(StabilityReport, Basis, [f64; NB]), RodError> {
        let mut end_state = [0.0; NB];
        let mut basis = initial_basis();
        // det U = sign_u · e^{log_u} (module docs).
        let (mut sign_u, mut log_u) = (1.0, 0.0);
        let mut scan = Stream::new();
        let mut least_ratio = f64::INFINITY;
        let a_vec = self.params_in_base_frame();
        let (ci, a, load) = (self.stiffness.inv(), self.a, self.gravity.load());
        for k in 0..self.segments() {
            let (t0, t1) = (self.mesh[k], self.mesh[k + 1]);
            let mut ts: Vec<f64> = (GRID_FROM..=GRID)
                .map(|i| f64::from(i) / f64::from(GRID))
                .filter(|&t| t > t0 && t < t1)
                .collect();
            ts.push(t1);
            let mut at_end = basis;
            dop853::solve_dense(
                |t, s: &[f64; FULL], ds: &mut [f64; FULL]| {
                    heavy_ode::rhs::<FULL, COLUMNS>(&ci, &a, load, t, s, ds, true)
                },
                t0,
                self.start_state::<FULL>(k),
                &ts,
                &ode_options(),
                |_, t, s| {
                    let x = propagated(s, &basis);
                    at_end = x;
                    end_state.copy_from_slice(&s[..NB]);
                    if t < f64::from(GRID_FROM) / f64::from(GRID) - 1e-12 {
                        return ControlFlow::Continue(());
                    }
                    let pose = x.fixed_view::<6, 6>(0, 0).into_owned();
                    let det = pose.determinant();
                    let rows: f64 = (0..6).map(|i| pose.row(i).norm()).product();
                    let ratio = (det / rows).abs();
                    if rows > 0.0 && t >= super::stability::MARGIN_T_MIN - 1e-12 {
                        least_ratio = least_ratio.min(ratio);
                    } else if !(ratio > MARGIN_FLOOR) {
                        // Near the base det J(t) ~ t¹⁶ with no base moment (a pinned base):
                        // below its rounding its sign says nothing.
                        return ControlFlow::Continue(());
                    }
                    let lead = super::det_leading_term(&a_vec, t);
                    let sign = det.signum() * sign_u;
                    if lead > 0.0 && det != 0.0 {
                        let log_ratio = det.abs().ln() + log_u - lead.ln();
                        let g = sign * log_ratio.min(690.0).exp();
                        let _ = scan.sample(t, g, g);
                    } else {
                        let _ = scan.sample(t, if det == 0.0 { 0.0 } else { sign }, f64::NAN);
                    }
                    ControlFlow::Continue(())
                },
            )?;
            if k + 1 == self.segments() {
                let mut report = scan.exact_report();
                if report.stable && !(least_ratio > MARGIN_FLOOR) {
                    report.stable = false;
                    report.uncertain = true;
                }
                return Ok((report, at_end, end_state));
            }
            let qr = at_end.qr();
            let u = qr.r();
            for i in 0..6 {
                sign_u *= u[(i, i)].signum();
                log_u += u[(i, i)].abs().ln();
            }
            basis = qr.q();
        }
        unreachable!("a cable has at least one segment")
    }

    /// J(1) = ∂(tip body twist)/∂(the base's unknowns), rows (ω, v) as [`super::tip_and_jacobian`]'s:
    /// columns a_m (a clamped base) or the base's turn ε₀ (a pinned base, R₀ ← R₀ exp(ε₀)),
    /// then a_f. From the stability scan's Jacobi fields: X_η B⁻¹, with B the fields'
    /// coordinates in (δa, δφ₀) (the QR steps' product, never singular). None if it were.
    pub fn tip_jacobian(&self) -> Result<Option<SMatrix<f64, 6, 6>>, RodError> {
        let (_, x, _) = self.conjugate_scan()?;
        let b = x.fixed_view::<9, 9>(ROWS, 0).into_owned();
        let Some(b_inv) = b.try_inverse() else {
            return Ok(None);
        };
        let full = x.fixed_view::<6, 9>(0, 0) * b_inv;
        let first = if self.pinned_base { 6 } else { 0 };
        Ok(Some(SMatrix::<f64, 6, 6>::from_fn(|r, c| {
            if c < 3 {
                full[(r, first + c)]
            } else {
                full[(r, c)]
            }
        })))
    }

    /// a in the base's own frame (a pinned base is turned): what the leading term of det J(t)
    /// takes.
    fn params_in_base_frame(&self) -> SpatialParams {
        let to_base = self.nodes[0].rotation.inverse();
        let (am, af) = (
            to_base * Vector3::new(self.a[0], self.a[1], self.a[2]),
            to_base * Vector3::new(self.a[3], self.a[4], self.a[5]),
        );
        SpatialParams::new(am.x, am.y, am.z, af.x, af.y, af.z)
    }

    /// Stability with the tip held by `tip` and the base as this cable holds it (docs/ends.md,
    /// "3-D"): the rod clamped at both ends must be stable ([`SpatialCable::stability`]; a
    /// conjugate point makes the held rod unstable too, its variations being admissible), and
    /// the energy reduced to the ends' free coordinates must have a positive definite Hessian
    /// there. The ends' coordinates are ε₀ (the base's turn) and ε₁ = (ε_ω, ε_v) (the tip's
    /// body twist); the energy's gradient in them is the grippers' wrench (dE = −a_m · δφ₀ +
    /// M(1) · δφ₁ + n(1) · δp₁), so over the Jacobi fields from the base H = G D⁻¹ with
    /// D = ∂(ε₀, ε₁) and G = ∂(−R₀ᵀ a_m, R₁ᵀ M(1), R₁ᵀ n(1)). The free coordinates: a pinned
    /// base's turn (its spin about the tangent, a gauge, left out when the tip is pinned
    /// too), a pinned tip's ε_ω, a free tip's ε₁. By Haynsworth's inertia additivity the held
    /// rod's Morse index is the clamped one's plus H's. The verdict is undecided where H's
    /// least eigenvalue is within its asymmetry (its rounding) of zero. The margin is the
    /// clamped margin, capped by λ_min(H) / λ₀ with λ₀ the straight weightless rod's
    /// ([`held_stiffness_scale`]).
    pub fn held_stability(&self, tip: EndCondition) -> Result<StabilityReport, RodError> {
        let (clamped, x, end) = self.conjugate_scan()?;
        let both_clamped = tip == EndCondition::Clamped && !self.pinned_base;
        if both_clamped || !clamped.stable {
            return Ok(clamped);
        }
        let Some((least, error)) = self.end_hessian(&x, &end, tip) else {
            return Ok(StabilityReport {
                stable: false,
                uncertain: true,
                ..clamped
            });
        };
        let scale = held_stiffness_scale(&self.stiffness, self.pinned_base, tip);
        Ok(StabilityReport {
            stable: least > error,
            uncertain: least.abs() <= error,
            margin: clamped.margin.min(least / scale),
            first_conjugate_t: None,
        })
    }

    /// The least eigenvalue of the reduced Hessian on the ends' free coordinates
    /// ([`SpatialCable::held_stability`]) and its error bound (the asymmetry of H plus
    /// 1e-9 ‖H‖); None where D is singular.
    fn end_hessian(&self, x: &Basis, end: &[f64; NB], tip: EndCondition) -> Option<(f64, f64)> {
        let node = Node::of_state(end);
        let (r0, r1) = (self.nodes[0].rotation, node.rotation);
        let l = Vector3::from(self.gravity.load());
        let n1 = Vector3::new(self.a[3], self.a[4], self.a[5]) - l;
        // Rows: ε₀ (3), ε₁ (6); columns: the nine fields.
        let mut d = SMatrix::<f64, 9, 9>::zeros();
        let mut g = SMatrix::<f64, 9, 9>::zeros();
        for c in 0..9 {
            let row = |i: usize| x[(i, c)];
            let v3 = |i: usize| Vector3::new(row(i), row(i + 1), row(i + 2));
            let dp = r1 * v3(3);
            let (d_arm, dam, daf) = (v3(6), v3(9), v3(12));
            let dm = dam - d_arm.cross(&l) - dp.cross(&n1) - node.position.cross(&daf);
            let g0 = -(r0.inverse() * dam);
            let (g_m, g_n) = (r1.inverse() * dm, r1.inverse() * daf);
            for i in 0..3 {
                d[(i, c)] = row(COLUMNS + i);
                d[(3 + i, c)] = row(i);
                d[(6 + i, c)] = row(3 + i);
                g[(i, c)] = g0[i];
                g[(3 + i, c)] = g_m[i];
                g[(6 + i, c)] = g_n[i];
            }
        }
        let h = g * d.try_inverse()?;
        let mut free: Vec<usize> = Vec::new();
        if self.pinned_base {
            let gauge = tip == EndCondition::Pinned;
            free.extend(if gauge { 1..3 } else { 0..3 });
        }
        match tip {
            EndCondition::Pinned => free.extend(3..6),
            EndCondition::Free => free.extend(3..9),
            EndCondition::Clamped => {}
        }
        let h = h.select_rows(&free).select_columns(&free);
        let sym = (&h + h.transpose()) * 0.5;
        let asym = (&h - h.transpose()).norm() * 0.5;
        let error = asym + 1e-9 * sym.norm();
        let sym = match self.symmetry_field(&node, tip) {
            Some(v) => deflated(sym, &v.select_rows(&free), error),
            None => sym,
        };
        let least = sym.symmetric_eigenvalues().min();
        (least.is_finite() && error.is_finite()).then_some((least, error))
    }

    /// The ends' motion (ε₀, ε₁ as in [`SpatialCable::end_hessian`]) of a turn of the whole
    /// problem about an axis u through the base, where the problem has that symmetry: the
    /// rod turned by R ← Rot(u, φ) R Rot(e1, −φ) is again an equilibrium (isotropic bending)
    /// when gravity is along u (or absent), a clamped base's tangent is u (u = e1), and a
    /// pinned tip lies on the axis. Such rods form a family, and H is singular along it: a
    /// neutral direction of the family, not a loss of stability. None without the symmetry.
    fn symmetry_field(&self, end: &Node, tip: EndCondition) -> Option<nalgebra::DVector<f64>> {
        let gd = Vector3::from(self.gravity.direction());
        let p1 = end.position;
        let u = match (self.pinned_base, tip) {
            (false, _) => Vector3::x(),
            (true, EndCondition::Pinned) if !self.gravity.is_weightless() => gd,
            (true, EndCondition::Pinned) if p1.norm() > 0.0 => p1.normalize(),
            _ => return None,
        };
        let along = |v: &Vector3<f64>| v.cross(&u).norm() <= 1e-9 * v.norm().max(1.0);
        let tip_on_axis = tip == EndCondition::Free || along(&p1);
        if !(self.gravity.is_weightless() || along(&gd)) || !tip_on_axis {
            return None;
        }
        let e1 = Vector3::x();
        let (r0, r1) = (self.nodes[0].rotation, end.rotation);
        let mut w = nalgebra::DVector::zeros(9);
        let (b, t, v) = (
            r0.inverse() * u - e1,
            r1.inverse() * u - e1,
            r1.inverse() * u.cross(&p1),
        );
        for i in 0..3 {
            w[i] = b[i];
            w[3 + i] = t[i];
            w[6 + i] = v[i];
        }
        if self.pinned_base && tip == EndCondition::Pinned {
            // The gauge (a spin of the whole rod about its tangent: ε₀ = ε₁_ω = e1) is left
            // out of the free coordinates: take the field with no base spin.
            let spin = w[0];
            w[0] = 0.0;
            w[3] -= spin;
        }
        Some(w)
    }

    /// The state at the start of segment `k`; with `N` = the full state, unit columns.
    fn start_state<const N: usize>(&self, k: usize) -> [f64; N] {
        let node = &self.nodes[k];
        let mut y = [0.0; N];
        let q = node.rotation.quaternion();
        y[..4].copy_from_slice(&[q.w, q.i, q.j, q.k]);
        y[4..7].copy_from_slice(node.position.as_slice());
        y[8..11].copy_from_slice(node.moment_arm.as_slice());
        if N == FULL {
            // Row r of column r (η then δP rows share the layout NB + COLUMNS · r + c).
            for r in 0..ROWS {
                y[NB + COLUMNS * r + r] = 1.0;
            }
        }
        y
    }
}

/// The symmetric `h` restricted to the complement of `v` when `v` is (to `error`) a null
/// direction of it; `h` itself otherwise (or when `v` vanishes).
fn deflated(
    h: nalgebra::DMatrix<f64>,
    v: &nalgebra::DVector<f64>,
    error: f64,
) -> nalgebra::DMatrix<f64> {
    let norm = v.norm();
    if !(norm > 1e-12) || (&h * v).norm() > 10.0 * error * norm {
        return h;
    }
    let v = v / norm;
    let n = h.nrows();
    let projector = nalgebra::DMatrix::identity(n, n) - &v * v.transpose();
    let e = projector.symmetric_eigen();
    let keep: Vec<usize> = (0..n).filter(|&i| e.eigenvalues[i] > 0.5).collect();
    let z = e.eigenvectors.select_columns(&keep);
    z.transpose() * h * z
}

/// λ₀ of [`SpatialCable::held_stability`]: the least eigenvalue of the straight weightless
/// rod's reduced Hessian at its tip (stiffnesses c1 torsion, c2, c3 bending, unit length).
/// One end turning freely, the other clamped (a pinned tip, or a pinned base with a clamped
/// tip): the rotational stiffness of a beam clamped at its other end, 4 c in bending and c1 in
/// torsion. Both pinned: the two end rotations' bending stiffness c [[4, 2], [2, 4]], least
/// eigenvalue 2c, and c1 in torsion. Free tip: the cantilever's tip stiffness in (deflection,
/// rotation), c [[12, −6], [−6, 4]], least eigenvalue (8 − √52) c, and c1 in torsion
/// (inextensible: no axial term).
pub fn held_stiffness_scale(k: &Stiffness, pinned_base: bool, tip: EndCondition) -> f64 {
    let c = k.c2.min(k.c3);
    match (pinned_base, tip) {
        (true, EndCondition::Pinned) => (2.0 * c).min(k.c1),
        (_, EndCondition::Free) => ((8.0 - 52.0_f64.sqrt()) * c).min(k.c1),
        _ => (4.0 * c).min(k.c1),
    }
}

/// Jacobi fields in the stability scan's basis: rows η (6), δP (3), δa (6) and the base's
/// turn δφ₀ (3); columns the six fields of δa, then the three of δφ₀.
type Basis = SMatrix<f64, { COLUMNS + 3 }, 9>;

/// The scan's basis at the base: the fields of δa (the conjugate-point test's six, first, so
/// that the QR steps keep their span in the first six columns), then those of a turn of the
/// base (rows 15..18 carry it; what a pinned base's test needs,
/// [`SpatialCable::held_stability`]).
fn initial_basis() -> Basis {
    let mut basis = Basis::zeros();
    for c in 0..6 {
        basis[(ROWS + c, c)] = 1.0;
    }
    for c in 0..3 {
        basis[(c, 6 + c)] = 1.0;
        basis[(COLUMNS + c, 6 + c)] = 1.0;
    }
    basis
}

/// X(t) = Φ(t) X(t_k) for a segment's state `s` (its 15 columns) and the basis at its start.
fn propagated(s: &[f64; FULL], basis: &Basis) -> Basis {
    let phi = SMatrix::<f64, ROWS, COLUMNS>::from_fn(|r, c| s[NB + COLUMNS * r + c]);
    let mut x = *basis;
    x.fixed_view_mut::<ROWS, 9>(0, 0)
        .copy_from(&(phi * basis.fixed_view::<COLUMNS, 9>(0, 0)));
    x
}

/// The unknown moved by column `c` of segment `k`'s variations: its start node's correction
/// (none at the base), then a.
fn start_column(pinned_base: bool, k: usize, c: usize) -> Option<usize> {
    if c >= ROWS {
        // A pinned base's a_m is 0, not an unknown: its slots hold the base's turn.
        (!pinned_base || c >= ROWS + 3).then_some(c - ROWS)
    } else if k > 0 {
        Some(6 + ROWS * (k - 1) + c)
    } else {
        // The base node: only a pinned base's orientation moves.
        (pinned_base && c < 3).then_some(c)
    }
}

/// The rows "the last segment, `k`, ended at `e`, ends at `target`": minus its body error.
fn tip_rows(
    pinned_base: bool,
    k: usize,
    e: &[f64; FULL],
    target: &SpatialPose,
    r: &mut DVector<f64>,
    j: Option<&mut DMatrix<f64>>,
) {
    let (end, row) = (Node::of_state(e), ROWS * k);
    let err = SpatialPose {
        position: end.position,
        rotation: end.rotation,
    }
    .body_error_to(target);
    for i in 0..6 {
        r[row + i] = -err[i];
    }
    let Some(j) = j else { return };
    let ev = Vector3::new(err[3], err[4], err[5]);
    let col = |rr: usize, c: usize| e[NB + COLUMNS * rr + c];
    for c in 0..COLUMNS {
        let Some(jc) = start_column(pinned_base, k, c) else {
            continue;
        };
        let w = Vector3::new(col(0, c), col(1, c), col(2, c));
        let v = Vector3::new(col(3, c), col(4, c), col(5, c)) + w.cross(&ev);
        for i in 0..3 {
            j[(row + i, jc)] = w[i];
            j[(row + 3 + i, jc)] = v[i];
        }
    }
}

/// Cables the 3-D solvers returned, remembered so that the energy and stability of an
/// answer's `a` come from its node states (an f64 `a` alone does not reproduce the rod at
/// large w): the last [`REMEMBERED`] of the process.
static SOLVED: Mutex<Vec<SpatialCable>> = Mutex::new(Vec::new());
/// Cables remembered.
pub const REMEMBERED: usize = 256;

/// Remembers a cable a solver returns ([`recall`]).
pub(crate) fn remember(c: &SpatialCable) {
    if let Ok(mut v) = SOLVED.lock() {
        if v.iter()
            .any(|o| o.a == c.a && o.gravity == c.gravity && o.stiffness == c.stiffness)
        {
            return;
        }
        if v.len() >= REMEMBERED {
            v.remove(0);
        }
        v.push(c.clone());
    }
}

/// The cable a 3-D solve returned with base wrench exactly `a`, if remembered.
pub fn recall(
    a: &SpatialParams,
    stiffness: &Stiffness,
    gravity: &Gravity3,
) -> Option<SpatialCable> {
    let v = SOLVED.lock().ok()?;
    v.iter()
        .rev()
        .find(|c| c.params() == *a && c.gravity == *gravity && c.stiffness == *stiffness)
        .cloned()
}
