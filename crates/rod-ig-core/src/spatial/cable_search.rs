//! The heavy 3-D rod's inverse geometry where the problem is planar (issue 51, item 5).
//!
//! With isotropic bending (c2 = c3), a target in the plane Π through the base tangent e1 and
//! gravity ĝ, its orientation a rotation about Π's normal n̂, the rod that stays in Π with no
//! twist is an equilibrium of the 3-D rod: it is the planar heavy rod (stiffness c = c2, weight
//! w / c) with R(t) = Rot(n̂, θ(t)), p = x e1 + y b2 (b2 = n̂ × e1), a_m = c κ(0) n̂ and
//! a_f = c (n_x e1 + n_y b2). So the planar search, its multiple shooting at large w and its
//! loop-free admission answer these targets — the cable held level among them, and the
//! symmetric targets (tip on the base's axis, identity orientation), where the weightless 3-D
//! rods form a one-parameter family (turned about e1) that no 3-D continuation can start
//! from. Each planar answer is lifted, polished by the 3-D multiple shooting
//! ([`super::cable`]) on the exact target, and admitted only if the 3-D stability test (in
//! and out of Π) passes.
//!
//! Any other target (isotropic bending) starts from the planar problem nearest to it (the
//! target projected on Π) and is reached by a continuation in the target with the 3-D multiple
//! shooting ([`PlanarReduction::nearest`]).

use super::cable::SpatialCable;
use super::heavy_ode::Gravity3;
use super::{SpatialParams, SpatialPose, Stiffness};
use crate::planar::heavy::cable::CableError;
use crate::planar::heavy::{cable_search, Gravity, HeavyPlanar};
use crate::planar::ig::SolveOptions as PlanarOptions;
use crate::solver::{
    Failure, Found, IgError, InverseGeometry, Solution, SolveOptions, Verified, Work,
};
use crate::{PlanarParams, PlanarPose, RodError};
use nalgebra::{SVector, Unit, UnitQuaternion, Vector3};

/// How far from Π a target may be and still start from the planar rods (rod lengths,
/// radians): the 3-D polish then moves the rod onto the exact target.
const PLANE_TOLERANCE: f64 = 1e-6;

/// The heavy 3-D rod: its stiffnesses and gravity.
pub(crate) type Rod<'a> = (&'a Stiffness, &'a Gravity3);

/// The plane of a planar 3-D problem (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PlanarReduction {
    normal: Vector3<f64>,
    in_plane: Vector3<f64>,
    /// Bending stiffness c = c2 = c3.
    c: f64,
    /// The target in Π's coordinates (x along e1, y along b2, θ about n̂).
    pub(crate) target: PlanarPose,
    /// Gravity in Π's coordinates, weight w / c.
    pub(crate) gravity: Gravity,
}

impl PlanarReduction {
    /// True when the target lies in Π (to [`PLANE_TOLERANCE`]): the planar rods reach it.
    pub(crate) fn is_exact_for(&self, target: &SpatialPose) -> bool {
        let (dp, dr) = target.distance_to(&self.lifted_target());
        dp <= PLANE_TOLERANCE && dr <= PLANE_TOLERANCE
    }

    /// The planar problem nearest to a 3-D one: Π through e1 and ĝ (or, with ĝ along e1,
    /// through e1 and the target), the target projected on Π (its position, and the angle of
    /// its tangent's projection). None when bending is anisotropic or there is no weight.
    pub(crate) fn nearest(target: &SpatialPose, k: &Stiffness, g: &Gravity3) -> Option<Self> {
        if !k.is_bending_isotropic() || g.is_weightless() {
            return None;
        }
        let e1 = Vector3::x();
        let gd = Vector3::from(g.direction());
        let p = target.position;
        let tangent = target.rotation * e1;
        let normal = [
            e1.cross(&gd),
            e1.cross(&p),
            e1.cross(&tangent),
            target.rotation.scaled_axis(),
            Vector3::z(),
        ]
        .into_iter()
        .find(|v| v.norm() > 1e-6 && v.dot(&e1).abs() <= PLANE_TOLERANCE * v.norm())?
        .normalize();
        if gd.dot(&normal).abs() > PLANE_TOLERANCE {
            return None;
        }
        let in_plane = normal.cross(&e1);
        let c = k.c2;
        let gravity = Gravity::new(g.weight() / c, [gd.dot(&e1), gd.dot(&in_plane)]).ok()?;
        Some(Self {
            normal,
            in_plane,
            c,
            target: PlanarPose::new(
                p.dot(&e1),
                p.dot(&in_plane),
                tangent.dot(&in_plane).atan2(tangent.dot(&e1)),
            ),
            gravity,
        })
    }

    /// The plane through e1 with unit normal `normal` (⊥ e1), for a rod of isotropic bending
    /// whose gravity lies in it (to [`PLANE_TOLERANCE`]); the target the planar `target`.
    /// None otherwise. How the 3-D rods with held ends start ([`super::held`]).
    pub(crate) fn through(
        normal: Vector3<f64>,
        k: &Stiffness,
        g: &Gravity3,
        target: PlanarPose,
    ) -> Option<Self> {
        let gd = Vector3::from(g.direction());
        if !k.is_bending_isotropic()
            || normal.dot(&Vector3::x()).abs() > PLANE_TOLERANCE
            || (!g.is_weightless() && gd.dot(&normal).abs() > PLANE_TOLERANCE)
        {
            return None;
        }
        let normal = normal.normalize();
        let in_plane = normal.cross(&Vector3::x());
        let gravity = Gravity::new(
            g.weight() / k.c2,
            [gd.dot(&Vector3::x()), gd.dot(&in_plane)],
        )
        .ok()?;
        Some(Self {
            normal,
            in_plane,
            c: k.c2,
            target,
            gravity,
        })
    }

    /// A point of Π's coordinates (x along e1, y along b2) in the base frame.
    pub(crate) fn lift_point(&self, x: f64, y: f64) -> Vector3<f64> {
        Vector3::x() * x + self.in_plane * y
    }

    /// Π's in-plane axis b2 = n̂ × e1.
    pub(crate) fn in_plane(&self) -> Vector3<f64> {
        self.in_plane
    }

    /// The planar target as a 3-D pose.
    pub(crate) fn lifted_target(&self) -> SpatialPose {
        lift_pose(self.normal, self.in_plane, &self.target)
    }

    /// The 3-D base wrench of the planar rod `a` (module docs).
    pub(crate) fn lift_params(&self, a: &PlanarParams) -> SpatialParams {
        let m = self.normal * (self.c * a[0]);
        let f = (Vector3::x() * a[1] + self.in_plane * a[2]) * self.c;
        SpatialParams::new(m.x, m.y, m.z, f.x, f.y, f.z)
    }

    pub(crate) fn lift_node(&self, node: &[f64; 4]) -> (UnitQuaternion<f64>, Vector3<f64>) {
        let pose = lift_pose(
            self.normal,
            self.in_plane,
            &PlanarPose::new(node[0], node[1], node[2]),
        );
        (pose.rotation, pose.position)
    }
}

fn lift_pose(normal: Vector3<f64>, in_plane: Vector3<f64>, pose: &PlanarPose) -> SpatialPose {
    SpatialPose {
        position: Vector3::x() * pose.x + in_plane * pose.y,
        rotation: UnitQuaternion::from_axis_angle(&Unit::new_unchecked(normal), pose.theta),
    }
}

/// Share of the time left that the planar search of [`all`] may spend before its rods are
/// lifted to 3-D.
const PLANAR_SHARE: f64 = 0.6;

fn planar_options(options: &SolveOptions<SVector<f64, 6>>) -> PlanarOptions {
    PlanarOptions {
        method: options.method,
        alpha: options.alpha,
        max_iterations: options.max_iterations,
        tolerance: options.tolerance,
        initial_guess: None,
        objective: options.objective,
        deadline: options.deadline,
        max_starts: options.max_starts,
        max_turns: options.max_turns,
    }
}

/// The 3-D cable of a planar answer `a`: the planar cable's nodes lifted when the planar
/// search solved it by multiple shooting, else integrated from the base (single shooting
/// keeps its digits there).
fn lifted_cable(
    rod: Rod<'_>,
    reduction: &PlanarReduction,
    a: &PlanarParams,
) -> Result<SpatialCable, RodError> {
    let a3 = reduction.lift_params(a);
    match cable_search::recall(a, &reduction.gravity) {
        Some(planar) => {
            let poses: Vec<_> = planar
                .nodes()
                .iter()
                .map(|n| reduction.lift_node(n))
                .collect();
            SpatialCable::from_poses(&a3, rod.0, rod.1, planar.mesh().to_vec(), &poses)
        }
        None => SpatialCable::from_params(&a3, rod.0, rod.1),
    }
}

/// The planar answer `s` as a 3-D solution on `target`: polished there by the 3-D multiple
/// shooting, admitted by the 3-D stability test.
fn lifted_solution(
    rod: Rod<'_>,
    reduction: &PlanarReduction,
    s: &Solution<PlanarParams, PlanarPose>,
    target: &SpatialPose,
) -> Option<Solution<SpatialParams, SpatialPose>> {
    let mut cable = lifted_cable(rod, reduction, &s.a).ok()?;
    let polish = cable.carry(&reduction.lifted_target(), target).ok()? as u32;
    let work = Work {
        iterations: s.iterations + polish,
        evaluations: s.evaluations + polish,
        starts: s.starts,
    };
    let mut out = admitted(&cable, target, work).ok()?;
    out.complete = s.complete;
    Some(out)
}

/// A cable solved on `target` as the solvers' answer: admitted by the 3-D stability test
/// (`Err(None)` where it fails), evaluated, and remembered ([`super::cable::recall`]).
fn admitted(
    cable: &SpatialCable,
    target: &SpatialPose,
    work: Work,
) -> Result<Solution<SpatialParams, SpatialPose>, Option<RodError>> {
    let stability = cable.stability()?;
    if !stability.stable {
        return Err(None);
    }
    let tip = cable.tip()?;
    let (_, energy) = cable.energies()?;
    super::cable::remember(cable);
    Ok(Solution::new(
        cable.params(),
        Verified {
            tip,
            errors: tip.distance_to(target),
            energy,
            margin: stability.margin,
        },
        work,
    ))
}

/// The planar search's first rod, lifted (module docs); None when it finds none that is
/// stable in 3-D.
pub(crate) fn first(
    rod: Rod<'_>,
    reduction: &PlanarReduction,
    target: &SpatialPose,
    options: &SolveOptions<SVector<f64, 6>>,
) -> Option<Solution<SpatialParams, SpatialPose>> {
    let planar = HeavyPlanar::new(reduction.gravity);
    // The first rod, whatever the caller's objective: a least-energy planar search runs to
    // its deadline and leaves the lift none (a least-energy solve3d at w = 500 answered on
    // its deadline's edge, or nothing); the caller's least energy ranges over [`all`].
    let opts = PlanarOptions {
        objective: crate::solver::Objective::FirstFound,
        ..planar_options(options)
    };
    if let Ok(s) = planar.robust(&reduction.target, &opts) {
        if let Some(out) = lifted_solution(rod, reduction, &s, target) {
            return Some(out);
        }
    }
    // The first planar rod may buckle out of Π: the others, least energy first.
    all(rod, reduction, target, options)
        .solutions
        .into_iter()
        .min_by(|a, b| a.energy.total_cmp(&b.energy))
}

/// Every planar rod the planar search finds that is stable in 3-D, lifted.
pub(crate) fn all(
    rod: Rod<'_>,
    reduction: &PlanarReduction,
    target: &SpatialPose,
    options: &SolveOptions<SVector<f64, 6>>,
) -> Found<SpatialParams, SpatialPose> {
    let planar = HeavyPlanar::new(reduction.gravity);
    let found = {
        // The planar search may run to the deadline (least energy, `all`): the lifts of what
        // it found get the rest of the time (after it, they fail on the expired deadline).
        let _share = crate::deadline::share_of_remaining(PLANAR_SHARE);
        planar.robust_all(&reduction.target, &planar_options(options))
    };
    Found {
        solutions: found
            .solutions
            .iter()
            .filter_map(|s| lifted_solution(rod, reduction, s, target))
            .collect(),
        iterations: found.iterations,
        evaluations: found.evaluations,
        starts: found.starts,
    }
}

/// The rod through `target` reached by the 3-D multiple shooting from the caller's `a0` at the
/// full weight (its nodes integrated from a0: a start wherever single shooting from a0 keeps a
/// few digits, and from an a0 good to ~1e-12 at any weight), admitted by the 3-D stability
/// test. How `robust` keeps a good guess and how `newton` runs above w = 200.
pub(crate) fn from_guess(
    rod: Rod<'_>,
    a0: &SpatialParams,
    target: &SpatialPose,
) -> Result<Solution<SpatialParams, SpatialPose>, Failure<SpatialParams>> {
    let fail = |reason: IgError, iterations: u32| Failure {
        reason,
        iterations,
        residual: f64::INFINITY,
        last_a: Some(*a0),
        starts: 1,
        elapsed_us: 0.0,
    };
    let evaluation = |e: RodError| IgError::Evaluation {
        iteration: 0,
        detail: e.to_string(),
    };
    let mut cable =
        SpatialCable::from_params(a0, rod.0, rod.1).map_err(|e| fail(evaluation(e), 0))?;
    let iterations = match cable.solve(target) {
        Ok(it) => it as u32,
        Err(CableError::Rod(RodError::Deadline { .. })) => {
            return Err(fail(IgError::Deadline { iteration: 0 }, 0))
        }
        Err(e) => return Err(fail(evaluation(RodError::Overflow(e.to_string())), 0)),
    };
    let work = Work {
        iterations,
        evaluations: iterations,
        starts: 1,
    };
    admitted(&cable, target, work).map_err(|e| match e {
        Some(e) => fail(evaluation(e), iterations),
        None => fail(
            IgError::LeftStableSet {
                iteration: iterations,
            },
            iterations,
        ),
    })
}

/// One corrector step of the branch follower on a long 3-D cable's node states
/// ([`crate::solver::RodModel::branch_step`]): the rod of `cable`'s branch with its tip at
/// `goal` within `tolerance`, with its tip and J(1), when one step reaches it
/// ([`SpatialCable::branch_to`]); None otherwise. The rod reached is remembered, so that the
/// follower's evaluations of its `a` use its node states.
pub(crate) fn branch_step(
    cable: &SpatialCable,
    goal: &SpatialPose,
    tolerance: f64,
) -> Option<(SpatialParams, SpatialPose, nalgebra::SMatrix<f64, 6, 6>)> {
    use super::cable::TipGoal;
    let here = TipGoal::Pose(cable.tip().ok()?);
    let next = cable.branch_to(&here, &TipGoal::Pose(*goal)).ok()??;
    let tip = next.tip().ok()?;
    let (pe, oe) = tip.distance_to(goal);
    if pe > tolerance || oe > tolerance {
        return None;
    }
    let jacobian = next.tip_jacobian().ok()??;
    super::cable::remember(&next);
    Some((next.params(), tip, jacobian))
}

/// The held rod `a` under `from` carried to `rod`'s gravity with the tip gripper fixed at
/// `gripper`, on its node states ([`SpatialCable::carry_load`]): the cable a solver returned
/// for `a`, or, at a weight single shooting keeps its digits, the one `a` integrates to,
/// corrected on `gripper`. The rod returned passed the 3-D stability test; fails where the
/// branch folds (the rod would snap), where it ends unstable, or on the deadline.
pub(crate) fn carry(
    rod: Rod<'_>,
    a: &SpatialParams,
    from: &Gravity3,
    gripper: &SpatialPose,
    options: &SolveOptions<SVector<f64, 6>>,
) -> Result<Solution<SpatialParams, SpatialPose>, Failure<SpatialParams>> {
    use super::cable::TipGoal;
    let _deadline = crate::deadline::scope(options.deadline);
    let failed = |detail: String| {
        let reason = if crate::deadline::expired() {
            IgError::Deadline { iteration: 0 }
        } else {
            IgError::NoStableSolution {
                starts: 1,
                last: Some(Box::new(IgError::Evaluation {
                    iteration: 0,
                    detail,
                })),
            }
        };
        Failure {
            starts: 1,
            last_a: Some(*a),
            ..Failure::early(reason)
        }
    };
    let known = super::cable::recall(a, rod.0, from).or_else(|| {
        if from.weight() > cable_search::LONG_CABLE_WEIGHT {
            return None;
        }
        let mut c = SpatialCable::from_params(a, rod.0, from).ok()?;
        c.solve(gripper).ok()?;
        Some(c)
    });
    let Some(mut cable) = known else {
        return Err(failed(
            "the held rod's node states are not known (an `a` a solver returned at this \
             weight, or one at weight <= 200, is needed)"
                .into(),
        ));
    };
    let steps = cable
        .carry_load(rod.1, &TipGoal::Pose(*gripper))
        .map_err(|e| failed(e.to_string()))?;
    let work = Work {
        iterations: steps,
        evaluations: steps,
        starts: 1,
    };
    admitted(&cable, gripper, work).map_err(|e| match e {
        None => failed("the carried rod is unstable".into()),
        Some(e) => failed(e.to_string()),
    })
}
