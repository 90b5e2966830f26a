//! The 3-D rod with pinned or free ends (issue 52; docs/ends.md, "3-D"): a clamped base with a
//! pinned or free tip, a pinned base with a pinned tip (a cable between two hooks) or a
//! clamped one ([`equilibria_to_pose`]).
//!
//! The equations are the long cable's multiple shooting ([`super::cable`]) with the tip's six
//! rows chosen by its condition ([`TipGoal`]): a pinned tip holds its position and has no
//! moment, a free tip has no moment and no force (the base carries the weight); a pinned
//! base's orientation is an unknown in a_m's place. Stability is
//! [`SpatialCable::held_stability`]: the rod clamped at both ends stable, and the energy
//! reduced to the ends' free coordinates convex there.
//!
//! The search starts where the problem is planar: with isotropic bending and gravity in the
//! plane Π through the base tangent e1 (a pinned base: the chord) and ĝ, the planar held rods
//! of [`crate::planar::heavy::held`] (stiffness c, weight w / c) are 3-D equilibria. Each is
//! lifted, polished by the 3-D Newton and admitted by the 3-D test (out-of-plane buckling
//! included). A pinned tip off Π starts from its projection on Π and is carried there along a
//! line of positions. Without weight Π is the plane through e1 and the target.
//! Not built: anisotropic bending (c2 ≠ c3: no plane is invariant) and a free tip's point
//! load.

use super::cable::{SpatialCable, TipGoal};
use super::cable_search::PlanarReduction;
use super::heavy_ode::Gravity3;
use super::{SpatialParams, SpatialPose, Stiffness};
use crate::ends::{EndCondition, HeldEnds};
use crate::planar::heavy::cable::{CableError, SHAPE_CHECK_SAMPLES};
use crate::planar::heavy::held::{self as planar_held, HeldError, HeldSolution};
use crate::planar::ig::SolveOptions;
use crate::wrench::{GripperWrenches, SpatialWrench};
use crate::{PlanarPose, RodError, StabilityReport};
use nalgebra::{UnitQuaternion, Vector3};

/// How far (rod lengths) a pinned tip's target may be from Π and still be solved in Π.
const IN_PLANE: f64 = 1e-9;

/// One 3-D equilibrium with held ends.
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialHeldSolution {
    /// a = (base moment, base force) in the base frame (a_f = w ĝ for a free tip).
    pub a: SpatialParams,
    /// The base's orientation: the identity for a clamped base; a pinned base's own (its
    /// tangent R₀ e1 is where the rod leaves the hook).
    pub base_rotation: UnitQuaternion<f64>,
    /// The tip pose.
    pub tip: SpatialPose,
    /// Total energy (elastic + gravitational).
    pub energy: f64,
    /// Elastic energy.
    pub elastic_energy: f64,
    /// Stability with the tip's natural conditions ([`SpatialCable::held_stability`]).
    pub stability: StabilityReport,
    /// Full turns of the planar rod it was lifted from (0: loop-free).
    pub turns: u32,
    /// The planar rod it was lifted from crosses itself.
    pub self_intersects: bool,
    /// The equilibrium's node states.
    pub cable: SpatialCable,
}

impl SpatialHeldSolution {
    /// The cable solved with its tip held by `tip` as an answer: energies and stability.
    pub fn of(
        cable: SpatialCable,
        tip: EndCondition,
        turns: u32,
        self_intersects: bool,
    ) -> Result<Self, RodError> {
        let (elastic_energy, energy) = cable.energies()?;
        Ok(Self {
            a: cable.params(),
            base_rotation: cable.base_rotation(),
            tip: cable.tip()?,
            energy,
            elastic_energy,
            stability: cable.held_stability(tip)?,
            turns,
            self_intersects,
            cable,
        })
    }

    /// The wrenches the rod exerts on its grippers ([`crate::wrench`]): zero moment at a
    /// pinned tip, no wrench at a free one.
    pub fn wrenches(&self) -> Result<GripperWrenches<SpatialWrench>, RodError> {
        self.cable.wrenches()
    }
}

/// What a 3-D search with held ends found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpatialHeldSearch {
    /// The admitted (stable, within `max_turns`) equilibria, least energy first.
    pub solutions: Vec<SpatialHeldSolution>,
    /// Equilibria found and not admitted (unstable in 3-D, or in the plane).
    pub rejected: usize,
    /// Starts tried (the planar rods lifted).
    pub starts: u32,
    /// The deadline passed before every start was tried.
    pub cut_short: bool,
}

impl SpatialHeldSearch {
    /// Why the search found no admitted equilibrium.
    pub fn not_found(&self, ends: HeldEnds) -> HeldError {
        HeldError::NotFound {
            base: ends.base(),
            tip: ends.tip(),
            starts: self.starts,
            cut: if self.cut_short {
                ", cut short by the deadline"
            } else {
                ""
            },
            last: String::new(),
        }
    }
}

/// Held ends of the 3-D rod need isotropic bending (the search starts from a plane).
fn check_bending(k: &Stiffness) -> Result<(), HeldError> {
    if !k.is_bending_isotropic() {
        return Err(HeldError::Target {
            field: "stiffness",
            why: "pinned and free tips of the 3-D rod need isotropic bending (c2 = c3)".into(),
        });
    }
    Ok(())
}

/// A pinned tip's target is a reachable position; a free tip has none.
fn check_target(tip: EndCondition, target: Option<&Vector3<f64>>) -> Result<(), HeldError> {
    match (tip, target) {
        (EndCondition::Free, Some(_)) => {
            return Err(HeldError::Target {
                field: "target",
                why: "a free tip has no target: the cable hangs from its base".into(),
            })
        }
        (EndCondition::Pinned, None) => {
            return Err(HeldError::Target {
                field: "target",
                why: "a pinned tip needs its position".into(),
            })
        }
        (EndCondition::Pinned, Some(p))
            if !(p.iter().all(|v| v.is_finite()) && p.norm() <= 1.0) =>
        {
            return Err(HeldError::Target {
                field: "target",
                why: format!(
                    "unreachable: the tip is {:.6} from the base, the rod is 1 long",
                    p.norm()
                ),
            })
        }
        _ => {}
    }
    Ok(())
}

/// Where the search runs: the frame F in which the planar problem is posed (the identity for
/// a clamped base, whose tangent e1 lies in Π; for a pinned base a turn taking e1 to the
/// chord, as the base's angle is free), the plane Π (its reduction, in F's coordinates, with
/// gravity turned into them), and the target's distance from Π.
struct SearchFrame {
    frame: UnitQuaternion<f64>,
    reduction: PlanarReduction,
    off: f64,
}

impl SearchFrame {
    /// The frame of a search (module docs): Π through e1 and ĝ for a clamped base, through
    /// the chord and ĝ for a pinned one (or, without weight or with ĝ along them, through the
    /// target, else any).
    fn of(
        ends: HeldEnds,
        k: &Stiffness,
        g: &Gravity3,
        target: Option<&Vector3<f64>>,
    ) -> Option<Self> {
        let gd = Vector3::from(g.direction());
        let axis = match (ends.base(), target) {
            (EndCondition::Pinned, Some(p)) if p.norm() > 1e-9 => p.normalize(),
            _ => Vector3::x(),
        };
        let frame = UnitQuaternion::rotation_between(&Vector3::x(), &axis).unwrap_or_else(|| {
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI)
        });
        let candidates = [
            (!g.is_weightless()).then(|| axis.cross(&gd)),
            target.map(|p| axis.cross(p)),
            Some(axis.cross(&Vector3::z())),
            Some(axis.cross(&Vector3::y())),
        ];
        let normal = candidates
            .into_iter()
            .flatten()
            .find(|n| n.norm() > 1e-6)?
            .normalize();
        let local = frame.inverse();
        let gravity = Gravity3::new(g.weight(), (local * gd).into()).ok()?;
        let reduction =
            PlanarReduction::through(local * normal, k, &gravity, PlanarPose::new(0.0, 0.0, 0.0))?;
        let off = target.map_or(0.0, |p| p.dot(&normal).abs());
        Some(Self {
            frame,
            reduction,
            off,
        })
    }

    /// The target in Π's coordinates: its projection (a pinned tip off Π is carried there
    /// after).
    fn planar_target(&self, target: &Vector3<f64>) -> PlanarPose {
        let p = self.frame.inverse() * target;
        PlanarPose::new(p.x, p.dot(&self.reduction.in_plane()), 0.0)
    }
}

/// The stable 3-D equilibria of the rod of stiffnesses `k` under `gravity`, held by `ends`
/// (clamped base; pinned tip at `target`, or free tip with `target` None), least energy
/// first, within `options.deadline` and admitting at most `options.max_turns` turns (module
/// docs).
pub fn equilibria(
    ends: HeldEnds,
    k: &Stiffness,
    gravity: &Gravity3,
    target: Option<&Vector3<f64>>,
    options: &SolveOptions,
) -> Result<SpatialHeldSearch, HeldError> {
    check_bending(k)?;
    let tip = ends.tip();
    if tip == EndCondition::Clamped {
        return Err(HeldError::Target {
            field: "tip_condition",
            why: "a clamped tip's target is a pose: equilibria_to_pose (pinned base), or the \
                  clamped solver"
                .into(),
        });
    }
    check_target(tip, target)?;
    let _deadline = crate::deadline::scope(options.deadline);
    let Some(frame) = SearchFrame::of(ends, k, gravity, target) else {
        return Err(HeldError::Target {
            field: "gravity",
            why: "no plane through the base holds gravity and the target".into(),
        });
    };
    let planar_target = target.map(|p| frame.planar_target(p));
    let planar = {
        let _share = crate::deadline::share_of_remaining(0.6);
        planar_held::equilibria(
            ends,
            &frame.reduction.gravity,
            planar_target.as_ref(),
            options,
        )?
    };
    let goal = match target {
        Some(p) => TipGoal::Position(*p),
        None => TipGoal::Free {
            tip_load: Vector3::zeros(),
        },
    };
    let mut out = SpatialHeldSearch {
        rejected: planar.equilibria.len() - planar.solutions.len(),
        cut_short: planar.cut_short,
        ..SpatialHeldSearch::default()
    };
    for s in &planar.solutions {
        if crate::deadline::expired() {
            out.cut_short = true;
            break;
        }
        out.starts += 1;
        match lifted(&frame, s, &goal, k, gravity) {
            Ok(Some(solution)) if solution.stability.stable => out.solutions.push(solution),
            _ => out.rejected += 1,
        }
    }
    out.solutions.sort_by(|a, b| a.energy.total_cmp(&b.energy));
    Ok(out)
}

/// The stable 3-D equilibria of the rod pinned at its base (the origin) and clamped at its
/// tip at `target`, least energy first: the same cable as one clamped by the tip's gripper
/// and pinned at the origin, read from its other end. That one is found by [`equilibria`]
/// in the tip gripper's frame turned half a turn about z (so that the rod leaves it along
/// +x), each answer read back (arc length s → 1 − s, tangent and force reversed: the base
/// force is −n(1) of the reversed rod) and polished on `target`.
pub fn equilibria_to_pose(
    k: &Stiffness,
    gravity: &Gravity3,
    target: &SpatialPose,
    options: &SolveOptions,
) -> Result<SpatialHeldSearch, HeldError> {
    check_bending(k)?;
    let frame = target.rotation * half_turn();
    let local = frame.inverse();
    let hook = local * (-target.position);
    let gravity_local = Gravity3::new(
        gravity.weight(),
        (local * Vector3::from(gravity.direction())).into(),
    )
    .map_err(|e| HeldError::Target {
        field: "gravity",
        why: e.to_string(),
    })?;
    let _deadline = crate::deadline::scope(options.deadline);
    let reversed_ends =
        HeldEnds::new(EndCondition::Clamped, EndCondition::Pinned).map_err(|e| {
            HeldError::Target {
                field: "tip_condition",
                why: e.to_string(),
            }
        })?;
    let found = {
        let _share = crate::deadline::share_of_remaining(0.8);
        equilibria(reversed_ends, k, &gravity_local, Some(&hook), options)?
    };
    let mut out = SpatialHeldSearch {
        rejected: found.rejected,
        starts: found.starts,
        cut_short: found.cut_short,
        ..SpatialHeldSearch::default()
    };
    for s in &found.solutions {
        match read_back(s, &gravity_local, frame, target, k, gravity) {
            Ok(Some(solution)) if solution.stability.stable => out.solutions.push(solution),
            Err(RodError::Deadline { .. }) => {
                out.cut_short = true;
                break;
            }
            _ => out.rejected += 1,
        }
    }
    out.solutions.sort_by(|a, b| a.energy.total_cmp(&b.energy));
    Ok(out)
}

/// Half a turn about z: x → −x, y → −y (a tangent reversed, the material frame kept right-handed).
fn half_turn() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI)
}

/// The reversed rod `s` (clamped in `frame` under `gravity_local`, pinned at the origin) read
/// from its other end ([`equilibria_to_pose`]): pinned at the origin, clamped at `target`.
fn read_back(
    s: &SpatialHeldSolution,
    gravity_local: &Gravity3,
    frame: UnitQuaternion<f64>,
    target: &SpatialPose,
    k: &Stiffness,
    gravity: &Gravity3,
) -> Result<Option<SpatialHeldSolution>, RodError> {
    let cable = &s.cable;
    let (tip, _) = cable.tip_and_moment_arm()?;
    let nodes = cable.node_poses();
    let m = cable.segments();
    let flip = half_turn();
    let map =
        |r: UnitQuaternion<f64>, p: Vector3<f64>| (frame * r * flip, target.position + frame * p);
    let mut poses = vec![map(tip.rotation, tip.position)];
    poses.extend((1..m).map(|j| nodes[m - j]).map(|(r, p)| map(r, p)));
    let mesh: Vec<f64> = (0..=m).map(|j| 1.0 - cable.mesh()[m - j]).collect();
    let n1 = Vector3::new(s.a[3], s.a[4], s.a[5]) - Vector3::from(gravity_local.load());
    let f = -(frame * n1);
    let a = SpatialParams::new(0.0, 0.0, 0.0, f.x, f.y, f.z);
    let mut back = SpatialCable::pinned_from_poses(&a, k, gravity, mesh, &poses)?;
    match back.solve_goal(&TipGoal::Pose(*target)) {
        Ok(_) => {}
        Err(CableError::Rod(e @ RodError::Deadline { .. })) => return Err(e),
        Err(_) => return Ok(None),
    }
    SpatialHeldSolution::of(back, EndCondition::Clamped, s.turns, s.self_intersects).map(Some)
}

/// The planar held rod `s` lifted to 3-D (in the search's frame, then turned by it), solved
/// on `goal` (carried there along a line of positions when the target is off Π) and
/// evaluated; None where Newton fails.
fn lifted(
    frame: &SearchFrame,
    s: &HeldSolution,
    goal: &TipGoal,
    k: &Stiffness,
    gravity: &Gravity3,
) -> Result<Option<SpatialHeldSolution>, RodError> {
    let (f, reduction) = (frame.frame, &frame.reduction);
    let local = reduction.lift_params(&s.a);
    let (am, af) = (
        f * Vector3::new(local[0], local[1], local[2]),
        f * Vector3::new(local[3], local[4], local[5]),
    );
    let a = SpatialParams::new(am.x, am.y, am.z, af.x, af.y, af.z);
    let poses: Vec<_> = s
        .cable
        .nodes()
        .iter()
        .map(|n| {
            let (r, p) = reduction.lift_node(n);
            (f * r, f * p)
        })
        .collect();
    let mesh = s.cable.mesh().to_vec();
    let pinned_base = s.cable.ends().base() == EndCondition::Pinned;
    let mut cable = if pinned_base {
        SpatialCable::pinned_from_poses(&a, k, gravity, mesh, &poses)?
    } else {
        SpatialCable::from_poses(&a, k, gravity, mesh, &poses)?
    };
    let solved = match goal {
        TipGoal::Position(_) if frame.off > IN_PLANE => {
            let start = TipGoal::Position(f * reduction.lift_point(s.tip.x, s.tip.y));
            cable.carry_goal(&start, goal)
        }
        _ => cable.solve_goal(goal),
    };
    match solved {
        Ok(_) => {}
        Err(CableError::Rod(e @ RodError::Deadline { .. })) => return Err(e),
        Err(_) => return Ok(None),
    }
    let tip = match goal {
        TipGoal::Free { .. } => EndCondition::Free,
        _ => EndCondition::Pinned,
    };
    let mut out = SpatialHeldSolution::of(cable, tip, s.turns, s.self_intersects)?;
    if let Some(verdict) = straight_verdict(&out.a, k, gravity, s.cable.ends()) {
        out.stability = verdict;
    }
    Ok(Some(out))
}

/// The verdict on a straight rod along the clamped base's tangent e1 (a_m = 0, a_f and
/// gravity along e1, or no weight), where J(1) is singular (the rod is inextensible) and the
/// 3-D test undecided: its second variation splits into two equal bending problems, in a
/// plane through e1 and across it (isotropic bending), and torsion, which holds nothing
/// (c1 > 0). So the planar held rod's verdict (stiffness c, weight w / c) is the 3-D one.
/// None for any other rod.
fn straight_verdict(
    a: &SpatialParams,
    k: &Stiffness,
    gravity: &Gravity3,
    ends: HeldEnds,
) -> Option<StabilityReport> {
    let gd = Vector3::from(gravity.direction());
    let across = |v: Vector3<f64>| v.y.abs().max(v.z.abs());
    let force = Vector3::new(a[3], a[4], a[5]);
    let straight = ends.base() == EndCondition::Clamped
        && a[0] == 0.0
        && a[1] == 0.0
        && a[2] == 0.0
        && across(force) == 0.0
        && (gravity.is_weightless() || across(gd) == 0.0);
    if !straight {
        return None;
    }
    let c = k.c2;
    let along = if gravity.is_weightless() { 1.0 } else { gd.x };
    let planar_gravity =
        crate::planar::heavy::Gravity::new(gravity.weight() / c, [along, 0.0]).ok()?;
    let planar = crate::PlanarParams::new(0.0, force.x / c, 0.0);
    let e = planar_held::evaluate(0.0, &planar, &planar_gravity, ends, [0.0; 2]).ok()?;
    Some(StabilityReport {
        stable: e.stable(),
        margin: e.solution.stability.normalised(),
        first_conjugate_t: None,
        uncertain: e.uncertain(),
    })
}

/// The forward map of the 3-D rod held by `ends` with base wrench `a` (no search): the cable
/// integrated from the base ([`SpatialCable::from_params`]; exact where single shooting keeps
/// its digits, w ≲ 300), a pinned base turned to `base_rotation` (ignored for a clamped base),
/// its energies, wrenches and the stability with the natural conditions. Refused, naming the
/// field: a moment at a pinned base (a_m ≠ 0), a free tip's base force other than w ĝ (it
/// holds no force).
pub fn evaluate(
    a: &SpatialParams,
    k: &Stiffness,
    gravity: &Gravity3,
    ends: HeldEnds,
    base_rotation: UnitQuaternion<f64>,
) -> Result<SpatialHeldSolution, HeldError> {
    check_bending(k)?;
    let refuse = |why: String| HeldError::Target { field: "a", why };
    if ends.tip() == EndCondition::Free {
        let l = gravity.load();
        if (0..3).any(|i| (a[3 + i] - l[i]).abs() > 1e-9 * (1.0 + gravity.weight())) {
            return Err(refuse(format!(
                "a free tip holds no force: (a4, a5, a6) must be w ĝ = ({}, {}, {})",
                l[0], l[1], l[2]
            )));
        }
    }
    let pinned_base = ends.base() == EndCondition::Pinned;
    if pinned_base && (0..3).any(|i| a[i] != 0.0) {
        return Err(refuse(
            "a pinned base holds no moment: (a1, a2, a3) must be 0".into(),
        ));
    }
    let rod = |e: RodError| refuse(e.to_string());
    let cable = if pinned_base {
        SpatialCable::pinned_from_params(a, k, gravity, base_rotation)
    } else {
        SpatialCable::from_params(a, k, gravity)
    }
    .map_err(rod)?;
    let ts: Vec<f64> = (0..=SHAPE_CHECK_SAMPLES)
        .map(|i| i as f64 / SHAPE_CHECK_SAMPLES as f64)
        .collect();
    let turns = winding(&cable.poses_at(&ts).map_err(rod)?);
    let mut out = SpatialHeldSolution::of(cable, ends.tip(), turns, false).map_err(rod)?;
    if let Some(verdict) = straight_verdict(a, k, gravity, ends) {
        out.stability = verdict;
    }
    Ok(out)
}

/// Full turns of the tangent (its total turning over 2π, rounded down): a 3-D rod's loops.
fn winding(shape: &[SpatialPose]) -> u32 {
    let total: f64 = shape
        .windows(2)
        .map(|w| (w[0].rotation * Vector3::x()).angle(&(w[1].rotation * Vector3::x())))
        .sum();
    (total / std::f64::consts::TAU).floor() as u32
}
