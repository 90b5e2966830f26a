//! A tree of long cables in the gripper's pose space (issue 51): cables in equilibrium, each
//! held at a gripper pose, grown by moving the gripper on straight lines while the cable
//! follows its branch by continuation on its node states ([`Cable::move_within`]: never across
//! a fold). What reaches a pose this way can be executed by a robot, and it reaches poses that
//! no single continuation does (around folds). Used by the long-cable planner
//! ([`crate::plan`]) and as the long-cable search's last stage.
//!
//! - **edges**: the gripper moved on a line (x, y, θ) of length ≤ [`STEP`] in the metric
//!   |Δp| + [`ANGLE_WEIGHT`]·|Δθ|; the edge's midpoint and end must pass the caller's `admit`
//!   (which returns the rod's margin, or None);
//! - **growth**: a rapidly-exploring tree from the root, straight at the goal until that fails
//!   once, then every third extension toward the goal and the others toward a pose
//!   drawn in the reach (a fixed seed: the same tree on every call), until an extension lands
//!   on the goal or the deadline passes.

use super::cable::{lift_near, Cable, FollowLimits};
use crate::rng::SplitMix64;
use crate::PlanarPose;

/// Longest gripper move of one edge (|Δp| + [`ANGLE_WEIGHT`]·|Δθ|, rod lengths).
pub const STEP: f64 = 0.1;
/// Rod lengths per radian of the gripper's turn in the pose metric.
pub const ANGLE_WEIGHT: f64 = 0.3;
/// Every this many extensions, the tree grows toward the goal.
const GOAL_EVERY: u32 = 3;
/// Gripper positions drawn within this radius of the base (the rod's reach is 1).
const REACH: f64 = 0.95;
/// Continuation steps of one half-edge at most.
const MAX_EDGE_STEPS: u32 = 64;

/// One state of a path: a cable held at `pose`, and the least margin `admit` gave on the edge
/// that reached it (its midpoint and itself; the root's own for the root).
#[derive(Clone, Debug)]
pub struct TreeState {
    /// The cable in equilibrium.
    pub cable: Cable,
    /// Where the gripper holds it (θ on the root's turn).
    pub pose: PlanarPose,
    /// Least margin on the edge that reached it.
    pub margin: f64,
    parent: Option<usize>,
}

/// The tree found no path to the goal before the deadline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotReached {
    /// Edges that passed their checks.
    pub edges: usize,
}

/// The gripper-pose distance of the module docs.
pub fn distance(p: &PlanarPose, q: &PlanarPose) -> f64 {
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

/// `cable` moved on its branch to `pose` and admitted: the cable and its margin.
fn moved(
    cable: &Cable,
    pose: &PlanarPose,
    admit: &mut impl FnMut(&Cable) -> Option<f64>,
) -> Option<(Cable, f64)> {
    let mut c = cable.clone();
    let limits = FollowLimits {
        max_steps: MAX_EDGE_STEPS,
        max_theta_spread: std::f64::consts::TAU,
    };
    c.move_within(pose, &limits).ok()?;
    let margin = admit(&c)?;
    Some((c, margin))
}

/// Grows the tree from `root` (admitted by the caller, margin `root_margin`) until a state
/// holds the cable at `goal` (θ lifted to the root's turn): the path root → goal.
pub fn path_to(
    root: Cable,
    root_margin: f64,
    goal: &PlanarPose,
    mut admit: impl FnMut(&Cable) -> Option<f64>,
) -> Result<Vec<TreeState>, NotReached> {
    let pose = root.tip().map_err(|_| NotReached { edges: 0 })?;
    let goal = lift_near(goal, pose.theta);
    let mut tree = vec![TreeState {
        cable: root,
        pose,
        margin: root_margin,
        parent: None,
    }];
    let mut rng = SplitMix64::new(0x5eed_cab1e);
    let (mut edges, mut extensions) = (0usize, 0u32);
    while !crate::deadline::expired() {
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
        let Some((mid, m_mid)) = moved(&tree[near].cable, &between(&from, &to, 0.5), &mut admit)
        else {
            continue;
        };
        let Some((end, m_end)) = moved(&mid, &to, &mut admit) else {
            continue;
        };
        edges += 1;
        tree.push(TreeState {
            cable: end,
            pose: to,
            margin: m_mid.min(m_end),
            parent: Some(near),
        });
        if distance(&to, &goal) == 0.0 {
            return Ok(path_of(tree));
        }
    }
    Err(NotReached { edges })
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
fn nearest(tree: &[TreeState], pose: &PlanarPose) -> usize {
    (0..tree.len())
        .min_by(|&i, &j| distance(&tree[i].pose, pose).total_cmp(&distance(&tree[j].pose, pose)))
        .unwrap_or(0)
}

/// The states from the root to the tree's last one.
fn path_of(tree: Vec<TreeState>) -> Vec<TreeState> {
    let mut path = vec![tree.len() - 1];
    while let Some(p) = tree[path[path.len() - 1]].parent {
        path.push(p);
    }
    path.reverse();
    let mut states: Vec<Option<TreeState>> = tree.into_iter().map(Some).collect();
    path.into_iter().filter_map(|i| states[i].take()).collect()
}
