//! Planning a long cable's motion (w above [`LONG_CABLE_WEIGHT`]: issue 51, item 4).
//!
//! The a-space roadmap of the parent module does not carry over to long cables: an f64 `a`
//! no longer fixes the rod there (single shooting amplifies its rounding like e^{c√w}), a
//! straight segment in a between two hanging cables passes through rods whose tips jump by
//! rod lengths, and the conjugate-point margin of single shooting shrinks with w (the hanging
//! rod at w = 1,000 has normalised margin 9.3e-4 though its second variation's least
//! eigenvalue is 582). So a long cable is planned in the gripper's pose space, on its node
//! states:
//!
//! - **states**: cables in equilibrium ([`Cable`]), each held at a gripper pose;
//! - **edges**: the gripper moved on a straight line (x, y, θ) of length ≤ [`STEP`] (in the
//!   metric |Δp| + [`ANGLE_WEIGHT`]·|Δθ|), the cable following its branch by continuation on
//!   its node states ([`Cable::move_within`]: it keeps the sign of the Newton matrix's
//!   determinant, so it never crosses a fold). The edge's midpoint and end are checked:
//!   stable by the second variation on the constraints' tangent space with normalised margin
//!   μ/μ₀ ≥ [`MIN_MARGIN`] (μ₀ the straight weightless rod's, so that the margin does not
//!   shrink with w: [`crate::planar::heavy::cable::SecondVariation::normalised`]), loop-free,
//!   clear of the obstacles;
//! - **search**: a rapidly-exploring tree from the start cable, every third extension toward
//!   the goal pose (the first ones straight at it), until an extension lands on the goal or
//!   the deadline passes.
//!
//! The plan lists the tree's path: gripper poses ≤ [`STEP`] apart, each rod's `a` (the cables
//! are remembered, so that the library's evaluations of these `a` use their node states) and
//! the least margin over the rods and midpoints checked.

use super::{body_collides, Plan, PlanError, PlanRequest, BODY_SAMPLES, MIN_MARGIN};
use crate::planar::heavy::cable::{lift_near, Cable, FollowLimits};
use crate::planar::heavy::cable_search::{self, LONG_CABLE_WEIGHT};
use crate::planar::heavy::Gravity;
use crate::rng::SplitMix64;
use crate::PlanarPose;

/// Longest gripper move of one edge (|Δp| + [`ANGLE_WEIGHT`]·|Δθ|, rod lengths).
pub const STEP: f64 = 0.1;
/// Rod lengths per radian of the gripper's turn in the pose metric.
pub const ANGLE_WEIGHT: f64 = 0.3;
/// Every this many extensions, the tree grows toward the goal (the others toward a random pose).
const GOAL_EVERY: u32 = 3;
/// Gripper positions sampled within this radius of the base (the rod's reach is 1).
const REACH: f64 = 0.95;
/// Continuation steps of one half-edge at most.
const MAX_EDGE_STEPS: u32 = 64;

/// True when `gravity` makes the rod a long cable, planned by this module.
pub fn is_long_cable(gravity: &Gravity) -> bool {
    gravity.weight() > LONG_CABLE_WEIGHT
}

/// A state of the tree: a cable held at `pose`, and where it came from.
struct State {
    cable: Cable,
    pose: PlanarPose,
    parent: Option<usize>,
    /// Least margin on the edge from the parent (its midpoint and this state).
    margin: f64,
}

/// The gripper-pose distance of the module docs.
fn distance(p: &PlanarPose, q: &PlanarPose) -> f64 {
    (p.x - q.x).hypot(p.y - q.y) + ANGLE_WEIGHT * (p.theta - q.theta).abs()
}

/// The pose `s` of the way from `p` to `q`.
fn between(p: &PlanarPose, q: &PlanarPose, s: f64) -> PlanarPose {
    PlanarPose::new(
        p.x + s * (q.x - p.x),
        p.y + s * (q.y - p.y),
        p.theta + s * (q.theta - p.theta),
    )
}

/// The cable of the start rod `a`: the one a solver returned, else the rod `a` integrates to,
/// corrected onto the tip it reaches (exact where single shooting keeps its digits).
fn start_cable(a: &crate::PlanarParams, g: &Gravity) -> Result<Cable, PlanError> {
    if let Some(c) = cable_search::recall(a, g) {
        return Ok(c);
    }
    let invalid = |e: String| PlanError::Invalid(format!("the start rod: {e}"));
    let mut c = Cable::from_params(a, g).map_err(|e| invalid(e.to_string()))?;
    let tip = c.tip().map_err(|e| invalid(e.to_string()))?;
    c.solve(&tip).map_err(|e| invalid(e.to_string()))?;
    Ok(c)
}

/// The normalised margin of `cable` (−∞ unless it is stable and loop-free).
fn margin_of(cable: &Cable) -> f64 {
    crate::deadline::charge(crate::deadline::units::STABILITY_REPORT);
    let loop_free = matches!(cable.turns(), Ok(0)) && matches!(cable.self_intersects(), Ok(false));
    match cable.second_variation() {
        Ok(sv) if sv.stable() && loop_free => sv.normalised(),
        _ => f64::NEG_INFINITY,
    }
}

/// `Some(true)` when `cable`'s body touches an obstacle (`None` on the deadline).
fn collides(cable: &Cable, request: &PlanRequest) -> Option<bool> {
    if request.obstacles.is_empty() {
        return Some(false);
    }
    match cable.shape(BODY_SAMPLES) {
        Ok(body) => body_collides(&body, &request.obstacles),
        Err(_) => Some(true),
    }
}

/// `cable` moved on its branch to `pose`, checked (stable with margin, loop-free, clear of the
/// obstacles): the cable and its margin.
fn moved(cable: &Cable, pose: &PlanarPose, request: &PlanRequest) -> Option<(Cable, f64)> {
    let mut c = cable.clone();
    let limits = FollowLimits {
        max_steps: MAX_EDGE_STEPS,
        max_theta_spread: std::f64::consts::TAU,
    };
    c.move_within(pose, &limits).ok()?;
    let margin = margin_of(&c);
    (margin >= MIN_MARGIN && collides(&c, request) == Some(false)).then_some((c, margin))
}

/// Plans a long cable's motion (module docs).
pub(super) fn plan(request: &PlanRequest) -> Result<Plan, PlanError> {
    let g = request.gravity;
    let start = start_cable(&request.start, &g)?;
    let margin = margin_of(&start);
    if margin < MIN_MARGIN {
        return Err(PlanError::StartUnstable { margin });
    }
    match collides(&start, request) {
        Some(false) => {}
        Some(true) => return Err(PlanError::StartCollides),
        None => return Err(PlanError::Deadline { edges_checked: 0 }),
    }
    let pose = start
        .tip()
        .map_err(|e| PlanError::Invalid(format!("the start rod: {e}")))?;
    // The goal on the start's turn: the tree's poses are compared with it as they are.
    let goal = lift_near(&request.goal, pose.theta);
    let mut tree = vec![State {
        cable: start,
        pose,
        parent: None,
        margin,
    }];
    let mut rng = SplitMix64::new(0x5eed_cab1e);
    let (mut edges, mut extensions) = (0usize, 0u32);
    loop {
        if crate::deadline::expired() {
            return Err(PlanError::Deadline {
                edges_checked: edges,
            });
        }
        // Straight at the goal until that fails once, then every GOAL_EVERY-th extension.
        let toward_goal = edges == extensions as usize || extensions % GOAL_EVERY == 0;
        extensions += 1;
        let sample = if toward_goal {
            goal
        } else {
            random_pose(&mut rng, &goal)
        };
        let near = nearest(&tree, &sample);
        let from = tree[near].pose;
        let d = distance(&from, &sample);
        let to = if d <= STEP {
            sample
        } else {
            between(&from, &sample, STEP / d)
        };
        let Some((mid, m_mid)) = moved(&tree[near].cable, &between(&from, &to, 0.5), request)
        else {
            continue;
        };
        let Some((end, m_end)) = moved(&mid, &to, request) else {
            continue;
        };
        edges += 1;
        tree.push(State {
            cable: end,
            pose: to,
            parent: Some(near),
            margin: m_mid.min(m_end),
        });
        if distance(&to, &goal) == 0.0 {
            return Ok(assemble(&tree, request.start));
        }
    }
}

/// A gripper pose drawn in the reach (its orientation within 2 rad of the goal's).
fn random_pose(rng: &mut SplitMix64, goal: &PlanarPose) -> PlanarPose {
    loop {
        let (x, y) = (rng.range(-REACH, REACH), rng.range(-REACH, REACH));
        if x.hypot(y) <= REACH {
            return PlanarPose::new(x, y, goal.theta + rng.range(-2.0, 2.0));
        }
    }
}

/// The state of `tree` nearest `pose`.
fn nearest(tree: &[State], pose: &PlanarPose) -> usize {
    (0..tree.len())
        .min_by(|&i, &j| distance(&tree[i].pose, pose).total_cmp(&distance(&tree[j].pose, pose)))
        .unwrap_or(0)
}

/// The plan along the tree's path from its root to its last state; its cables remembered.
fn assemble(tree: &[State], start: crate::PlanarParams) -> Plan {
    let mut path = vec![tree.len() - 1];
    while let Some(p) = tree[path[path.len() - 1]].parent {
        path.push(p);
    }
    path.reverse();
    let mut plan = Plan {
        rods: Vec::with_capacity(path.len()),
        gripper: Vec::with_capacity(path.len()),
        min_margin: f64::INFINITY,
    };
    for &i in &path {
        let s = &tree[i];
        cable_search::remember(&s.cable);
        // The start is the caller's rod as given (its cable may be that rod corrected).
        plan.rods
            .push(if i == 0 { start } else { s.cable.params() });
        plan.gripper.push(s.pose);
        plan.min_margin = plan.min_margin.min(s.margin);
    }
    plan
}
