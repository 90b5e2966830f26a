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
//! - **the tree** ([`cable_tree`]): cables in equilibrium, each held at a gripper pose, grown
//!   by gripper moves of at most 0.1 (|Δp| + 0.3·|Δθ|) with the cable following its branch by
//!   continuation on its node states (never across a fold);
//! - **admission** of every edge's midpoint and end: stable by the second variation on the
//!   constraints' tangent space with normalised margin μ/μ₀ ≥ [`MIN_MARGIN`] (μ₀ the straight
//!   weightless rod's, so that the margin does not shrink with w:
//!   [`crate::planar::heavy::cable::SecondVariation::normalised`]), loop-free, clear of the
//!   obstacles.
//!
//! The plan lists the tree's path from the start to the goal: gripper poses ≤ 0.1 apart, each
//! rod's `a` (the cables are remembered, so that the library's evaluations of these `a` use
//! their node states) and the least margin over the rods and midpoints checked.

use super::{body_collides, Plan, PlanError, PlanRequest, BODY_SAMPLES, MIN_MARGIN};
use crate::planar::heavy::cable::Cable;
use crate::planar::heavy::cable_search::{self, LONG_CABLE_WEIGHT};
use crate::planar::heavy::cable_tree::{self, NotReached, TreeState};
use crate::planar::heavy::Gravity;

/// True when `gravity` makes the rod a long cable, planned by this module.
pub fn is_long_cable(gravity: &Gravity) -> bool {
    gravity.weight() > LONG_CABLE_WEIGHT
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
    let admit = |c: &Cable| {
        let m = margin_of(c);
        (m >= MIN_MARGIN && collides(c, request) == Some(false)).then_some(m)
    };
    match cable_tree::path_to(start, margin, &request.goal, admit) {
        Ok(path) => Ok(assemble(&path, request.start)),
        Err(NotReached { edges }) => Err(PlanError::Deadline {
            edges_checked: edges,
        }),
    }
}

/// The plan along `path` (its cables remembered).
fn assemble(path: &[TreeState], start: crate::PlanarParams) -> Plan {
    let mut plan = Plan {
        rods: Vec::with_capacity(path.len()),
        gripper: Vec::with_capacity(path.len()),
        min_margin: f64::INFINITY,
    };
    for (i, s) in path.iter().enumerate() {
        cable_search::remember(&s.cable);
        // The start is the caller's rod as given (its cable may be that rod corrected).
        plan.rods
            .push(if i == 0 { start } else { s.cable.params() });
        plan.gripper.push(s.pose);
        plan.min_margin = plan.min_margin.min(s.margin);
    }
    plan
}
