//! Planning stable gripper paths for the planar rod, in the rod's parameter space.
//!
//! The base wrench a = (a3, a4, a5) is one global chart of the rod's equilibria (Bretl &
//! McCarthy, IJRR 2014): a path of stable rods a(s) is a quasi-static motion the gripper can
//! execute by moving along Υ(a(s)), with the rod staying on its branch. So the planner searches
//! a roadmap over stable rods (Sintov et al., RA-L 2020: roadmaps in a-space) instead of gripper
//! poses:
//!
//! - **nodes**: stable rods of the inverse-geometry atlas (an even subset, [`ROADMAP_NODES`]),
//!   built once per [`Planner`] and reused across queries;
//! - **edges**: straight segments in a-space to the [`NEIGHBOURS`] nearest nodes, checked
//!   **lazily** (only when a shortest path uses them): every rod on the segment at spacing
//!   ≤ [`CHECK_SPACING`]·(1 + |a|) must be stable with margin ≥ [`MIN_MARGIN`] (docs/math.md §5,
//!   normalised g_min); stability results are kept across queries, collisions per query;
//! - **query**: the start rod and every stable rod reaching the goal pose ([`solve_all`]) join
//!   the roadmap; the direct segment start → goal rod is tried first; then A* over the roadmap,
//!   invalidating edges that fail their check, until a checked path or none is left.
//!
//! The plan returned lists rods at spacing ≤ 2·[`CHECK_SPACING`]·(1 + |a|) = 0.1 (1 + |a|);
//! the checked rods between them are its midpoints. Obstacles (discs, polygons) must not touch
//! the rod's body, sampled at [`BODY_SAMPLES`] points.
//!
//! A rod with weight (`PlanRequest::gravity`, [`crate::planar::heavy`]) is planned the same
//! way: its margins, bodies, tips and goal rods are the heavy rod's, the roadmap nodes the same
//! rods of the atlas (a node that is not a stable heavy rod fails its edges' checks), and the
//! edge verdicts kept across queries are dropped when the weight or its direction changes.
//! Long cables (w > 200) are planned in the gripper's pose space on their node states instead
//! (module `cable`: an f64 `a` no longer fixes the rod there).
//!
//! [`solve_all`]: crate::planar::ig::solve_all

mod cable;

use crate::planar;
use crate::planar::heavy::{self, Gravity, HeavyPlanar};
use crate::planar::ig::{self, SolveOptions};
use crate::{PlanarParams, PlanarPose};
use serde::{Deserialize, Serialize};
use std::collections::{BinaryHeap, HashMap, HashSet};
use std::time::Duration;
use thiserror::Error;

/// Roadmap nodes taken from the atlas (evenly strided).
pub const ROADMAP_NODES: usize = 3000;
/// Edges per node: its nearest roadmap neighbours in a-space.
pub const NEIGHBOURS: usize = 12;
/// Spacing of the stability checks along an edge, relative to 1 + |a|: half the spacing of
/// the returned rods (issue 12: |Δa| ≤ 0.1 (1 + |a|)), so that every midpoint is checked.
pub const CHECK_SPACING: f64 = 0.05;
/// Smallest normalised stability margin g_min accepted along a plan: well above the
/// verdict's rounding bound, so that every rod of a plan is stable with a margin.
pub const MIN_MARGIN: f64 = 1e-3;
/// Points at which the rod's body is tested against the obstacles.
pub const BODY_SAMPLES: usize = 48;
/// Default planning budget (`rod-ig plan`, the node's service).
pub const DEFAULT_PLAN_DEADLINE: Duration = Duration::from_millis(500);
/// Most stability checks along one edge: a longer edge (a start rod far from every roadmap
/// node, such as a coil of 10⁶ turns) is not used, so that no edge is sized past this.
pub const MAX_EDGE_SAMPLES: usize = 4096;
/// Most obstacles in one request (refused above: the collision test of every rod checked
/// scales with them).
pub const MAX_OBSTACLES: usize = 10_000;
/// Most polygon vertices in one request, over every polygon.
pub const MAX_VERTICES: usize = 100_000;
/// Largest obstacle coordinate and disc radius accepted, in rod lengths. The rod lies within
/// the unit disc, so 1e6 already covers "everything"; the bound keeps every product of the
/// geometry (≤ 4e12) far from overflow (issue 24: a 1e200 triangle was silently ignored).
pub const MAX_OBSTACLE_COORDINATE: f64 = 1e6;
/// Goal tolerance: the last rod's tip is within this of the goal pose.
pub const GOAL_TOLERANCE: f64 = 1e-7;

/// A planar obstacle the rod's body must not touch (base frame, rod lengths).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Obstacle {
    /// A disc.
    Disc {
        /// Centre (x, y).
        center: [f64; 2],
        /// Radius (> 0).
        radius: f64,
    },
    /// A simple polygon, vertices in order.
    Polygon {
        /// At least three (x, y) vertices.
        points: Vec<[f64; 2]>,
    },
}

/// One planning query.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanRequest {
    /// The rod the gripper holds now (must be stable).
    pub start: PlanarParams,
    /// Where the tip gripper must end.
    pub goal: PlanarPose,
    /// What the rod's body must not touch.
    pub obstacles: Vec<Obstacle>,
    /// Wall-time budget.
    pub deadline: Duration,
    /// The rod's weight and gravity's direction ([`Gravity::NONE`]: the weightless rod).
    pub gravity: Gravity,
}

/// A plan: rods from the start to a rod whose tip is the goal, and the gripper poses.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Stable rods, `rods[0]` the start, consecutive ones within 0.1 (1 + |a|).
    pub rods: Vec<PlanarParams>,
    /// Tip (gripper) pose of each rod.
    pub gripper: Vec<PlanarPose>,
    /// Smallest stability margin among the rods and the midpoints checked.
    pub min_margin: f64,
}

/// Why no plan was returned.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum PlanError {
    /// The start rod, the goal pose or an obstacle is not usable.
    #[error("invalid request: {0}")]
    Invalid(String),
    /// The start rod is not stable with the required margin (unstable, or stable but too
    /// close to the stability boundary by the normalised margin, as strongly tensioned rods
    /// are).
    #[error(
        "the start rod is not stable with a margin (normalised margin {margin:e} < \
         {MIN_MARGIN:e}: unstable, or too close to the stability boundary)"
    )]
    StartUnstable {
        /// Its margin.
        margin: f64,
    },
    /// The start rod touches an obstacle.
    #[error("the start rod touches an obstacle")]
    StartCollides,
    /// No stable rod reaches the goal pose.
    #[error("the goal is unreachable: {0}")]
    GoalUnreachable(String),
    /// Every stable rod reaching the goal touches an obstacle or lacks margin.
    #[error("every stable rod reaching the goal ({rods}) touches an obstacle or lacks margin")]
    GoalBlocked {
        /// Stable goal rods found.
        rods: usize,
    },
    /// The roadmap holds no checked path.
    #[error("no stable, collision-free path found ({edges_checked} edges checked)")]
    NoPath {
        /// Edges checked.
        edges_checked: usize,
    },
    /// The deadline passed.
    #[error("deadline reached after {edges_checked} edges checked")]
    Deadline {
        /// Edges checked.
        edges_checked: usize,
    },
}

/// A roadmap planner over stable rods, reused across queries (module docs).
#[derive(Debug, Default)]
pub struct Planner {
    nodes: Vec<PlanarParams>,
    /// Stability verdicts of edges (node pairs, smaller index first): true = stable.
    edge_stable: HashMap<(usize, usize), bool>,
    /// The weight those verdicts hold for.
    gravity: Gravity,
}

/// A node of one query's graph: a roadmap node or one of the query's own rods.
type NodeId = usize;

impl Planner {
    /// An empty planner; the roadmap is built on the first query.
    pub fn new() -> Self {
        Self::default()
    }

    /// Builds the roadmap from the atlas if needed; false when the deadline in force passed
    /// before the atlas was ready.
    fn ensure_roadmap(&mut self) -> bool {
        if !self.nodes.is_empty() {
            return true;
        }
        let Some(atlas) = ig::atlas::get(ig::atlas::Tier::Box) else {
            return false;
        };
        let n = atlas.len();
        let stride = (n / ROADMAP_NODES).max(1);
        self.nodes = (0..n)
            .step_by(stride)
            .map(|k| atlas.seed_params(k))
            .collect();
        true
    }

    /// Number of roadmap nodes (0 before the first query).
    pub fn roadmap_size(&self) -> usize {
        self.nodes.len()
    }

    /// Plans a stable, collision-free motion from `request.start` to a rod whose tip is
    /// `request.goal` (module docs).
    pub fn plan(&mut self, request: &PlanRequest) -> Result<Plan, PlanError> {
        check_request(request)?;
        // The roadmap comes from the atlas, built once per process in steps charged to the
        // deadline of the query that needs it.
        let _deadline = crate::deadline::scope(request.deadline);
        if cable::is_long_cable(&request.gravity) {
            return cable::plan(request);
        }
        if !self.ensure_roadmap() {
            return Err(PlanError::Deadline { edges_checked: 0 });
        }
        let g = request.gravity;
        if g != self.gravity {
            self.edge_stable.clear();
            self.gravity = g;
        }
        let start = request.start;
        let margin = margin_of(&start, &g);
        if margin < MIN_MARGIN {
            return Err(PlanError::StartUnstable { margin });
        }
        match collides(&start, &g, &request.obstacles) {
            Some(false) => {}
            Some(true) => return Err(PlanError::StartCollides),
            None => return Err(PlanError::Deadline { edges_checked: 0 }),
        }
        let options = SolveOptions {
            tolerance: GOAL_TOLERANCE,
            deadline: request.deadline.min(crate::planar::ig::MAX_DEADLINE),
            ..SolveOptions::default()
        };
        let mut goals = goal_rods(&request.goal, &g, &options)?;
        let found = goals.len();
        goals.retain(|a| {
            margin_of(a, &g) >= MIN_MARGIN && collides(a, &g, &request.obstacles) == Some(false)
        });
        if crate::deadline::expired() {
            return Err(PlanError::Deadline { edges_checked: 0 });
        }
        if goals.is_empty() {
            return Err(PlanError::GoalBlocked { rods: found });
        }
        let mut query = Query::new(self, start, goals, request);
        query.run()
    }
}

/// Every stable rod found whose tip is `goal` (weightless: `ig::solve_all`; with weight, the
/// model's search for all of them); refused with the search's reason when there is none.
fn goal_rods(
    goal: &PlanarPose,
    g: &Gravity,
    options: &SolveOptions,
) -> Result<Vec<PlanarParams>, PlanError> {
    let rods: Vec<PlanarParams> = if g.is_weightless() {
        ig::solve_all(goal, options).iter().map(|s| s.a).collect()
    } else {
        let model = HeavyPlanar::new(*g);
        crate::solver::solve_every(&model, goal, options)
            .solutions
            .iter()
            .map(|s| s.a)
            .collect()
    };
    if !rods.is_empty() {
        return Ok(rods);
    }
    let failure = if g.is_weightless() {
        ig::solve(goal, options).err()
    } else {
        crate::solver::solve(&HeavyPlanar::new(*g), goal, options).err()
    };
    Err(PlanError::GoalUnreachable(failure.map_or_else(
        || "no stable solution".into(),
        |f| f.reason.to_string(),
    )))
}

fn check_request(request: &PlanRequest) -> Result<(), PlanError> {
    if request.start.iter().any(|v| !v.is_finite()) {
        return Err(PlanError::Invalid("start rod is not finite".into()));
    }
    ig::check_target(&request.goal).map_err(|e| PlanError::GoalUnreachable(e.to_string()))?;
    if request.deadline.is_zero() || request.deadline > crate::planar::ig::MAX_DEADLINE {
        return Err(PlanError::Invalid(format!(
            "deadline {:?} is not in (0, {:?}]",
            request.deadline,
            crate::planar::ig::MAX_DEADLINE
        )));
    }
    if request.obstacles.len() > MAX_OBSTACLES {
        return Err(PlanError::Invalid(format!(
            "{} obstacles: at most {MAX_OBSTACLES} are accepted",
            request.obstacles.len()
        )));
    }
    let vertices: usize = request
        .obstacles
        .iter()
        .map(|o| match o {
            Obstacle::Polygon { points } => points.len(),
            Obstacle::Disc { .. } => 0,
        })
        .sum();
    if vertices > MAX_VERTICES {
        return Err(PlanError::Invalid(format!(
            "{vertices} polygon vertices: at most {MAX_VERTICES} are accepted"
        )));
    }
    request.obstacles.iter().try_for_each(check_obstacle)
}

/// Checks an obstacle: coordinates within ±[`MAX_OBSTACLE_COORDINATE`], disc radius in
/// (0, [`MAX_OBSTACLE_COORDINATE`]], polygons with at least 3 vertices.
fn check_obstacle(o: &Obstacle) -> Result<(), PlanError> {
    let in_range = |v: &f64| v.abs() <= MAX_OBSTACLE_COORDINATE;
    match o {
        Obstacle::Disc { center, radius } => {
            if !(center.iter().all(in_range) && *radius > 0.0 && in_range(radius)) {
                return Err(PlanError::Invalid(format!(
                    "disc {center:?} radius {radius}: the centre's coordinates must be within \
                     ±{MAX_OBSTACLE_COORDINATE:e} and the radius in (0, {MAX_OBSTACLE_COORDINATE:e}] \
                     (rod lengths)"
                )));
            }
        }
        Obstacle::Polygon { points } => {
            if points.len() < 3 {
                return Err(PlanError::Invalid(
                    "a polygon needs at least 3 vertices".into(),
                ));
            }
            if let Some(p) = points.iter().find(|p| !p.iter().all(in_range)) {
                return Err(PlanError::Invalid(format!(
                    "polygon vertex {p:?}: coordinates must be finite and within \
                     ±{MAX_OBSTACLE_COORDINATE:e} (rod lengths)"
                )));
            }
        }
    }
    Ok(())
}

/// The normalised stability margin of `a` under `g` (−∞ when it cannot be evaluated or the
/// verdict is not "stable").
fn margin_of(a: &PlanarParams, g: &Gravity) -> f64 {
    crate::deadline::charge(crate::deadline::units::STABILITY_REPORT);
    let report = if g.is_weightless() {
        planar::stability(a)
    } else {
        heavy::stability(a, g)
    };
    match report {
        Ok(r) if r.stable => r.margin,
        _ => f64::NEG_INFINITY,
    }
}

/// True when the rod's body touches an obstacle; `None` when the deadline passed first (the
/// tests are charged to [`crate::deadline`], a few obstacles at a time).
fn collides(a: &PlanarParams, g: &Gravity, obstacles: &[Obstacle]) -> Option<bool> {
    if obstacles.is_empty() {
        return Some(false);
    }
    // Weightless, `heavy::shape` is the closed forms' `PlanarRod::shape`.
    let Ok(body) = heavy::shape(a, g, BODY_SAMPLES) else {
        return Some(true);
    };
    body_collides(&body, obstacles)
}

/// True when the polyline `body` touches an obstacle; `None` when the deadline passed first.
fn body_collides(body: &[PlanarPose], obstacles: &[Obstacle]) -> Option<bool> {
    let mut tests = 0u64;
    for o in obstacles {
        if body.windows(2).any(|w| segment_touches(&w[0], &w[1], o)) {
            return Some(true);
        }
        // A polygon costs one test per edge and segment.
        tests += match o {
            Obstacle::Disc { .. } => body.len() as u64,
            Obstacle::Polygon { points } => (body.len() * points.len()) as u64,
        };
        let units = tests / crate::deadline::units::DISC_TESTS_PER_UNIT;
        if units > 0 {
            tests %= crate::deadline::units::DISC_TESTS_PER_UNIT;
            if crate::deadline::charge(units) {
                return None;
            }
        }
    }
    Some(false)
}

fn segment_touches(p: &PlanarPose, q: &PlanarPose, o: &Obstacle) -> bool {
    let (px, py, qx, qy) = (p.x, p.y, q.x, q.y);
    match o {
        Obstacle::Disc { center, radius } => {
            let (dx, dy) = (qx - px, qy - py);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 0.0 {
                (((center[0] - px) * dx + (center[1] - py) * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (cx, cy) = (px + t * dx - center[0], py + t * dy - center[1]);
            cx.hypot(cy) <= *radius
        }
        Obstacle::Polygon { points } => {
            let n = points.len();
            let crosses = (0..n).any(|i| {
                let (a, b) = (points[i], points[(i + 1) % n]);
                segments_intersect([px, py], [qx, qy], a, b)
            });
            crosses || inside(points, px, py)
        }
    }
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// True when the closed segments [p, q] and [a, b] meet (touching and collinear overlap
/// included: an obstacle's edge along the rod counts as a contact). Compares the signs of the
/// orientations, never their products, which underflow to 0 for tiny obstacles.
fn segments_intersect(p: [f64; 2], q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> bool {
    let opposite = |u: f64, v: f64| (u <= 0.0 && v >= 0.0) || (u >= 0.0 && v <= 0.0);
    let (d1, d2) = (cross(a, b, p), cross(a, b, q));
    let (d3, d4) = (cross(p, q, a), cross(p, q, b));
    if d1 == 0.0 && d2 == 0.0 && d3 == 0.0 && d4 == 0.0 {
        // Collinear: they meet iff their extents overlap on both axes.
        let overlap =
            |i: usize| p[i].min(q[i]) <= a[i].max(b[i]) && a[i].min(b[i]) <= p[i].max(q[i]);
        return overlap(0) && overlap(1);
    }
    opposite(d1, d2) && opposite(d3, d4)
}

/// Even–odd rule.
fn inside(points: &[[f64; 2]], x: f64, y: f64) -> bool {
    let n = points.len();
    let mut c = false;
    for i in 0..n {
        let (a, b) = (points[i], points[(i + n - 1) % n]);
        if (a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0] {
            c = !c;
        }
    }
    c
}

/// Distance of the origin to the segment [a, b] (the smallest |a(s)| along it).
fn min_norm(a: &PlanarParams, b: &PlanarParams) -> f64 {
    let d = b - a;
    let t = if d.norm_squared() > 0.0 {
        (-a.dot(&d) / d.norm_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + t * d).norm()
}

/// The rods checked along the edge a → b (a excluded, b included), at spacing
/// ≤ CHECK_SPACING (1 + |a(s)|); `None` for an edge of more than [`MAX_EDGE_SAMPLES`].
fn edge_samples(a: &PlanarParams, b: &PlanarParams) -> Option<impl Iterator<Item = PlanarParams>> {
    let spacing = CHECK_SPACING * (1.0 + min_norm(a, b));
    let n = ((b - a).norm() / spacing).ceil().max(1.0);
    if n.is_nan() || n > MAX_EDGE_SAMPLES as f64 {
        return None;
    }
    let n = n as usize;
    // Even, so that the returned rods (every other sample) end exactly at b.
    let n = n + n % 2;
    let (a, b) = (*a, *b);
    Some((1..=n).map(move |i| a + (b - a) * (i as f64 / n as f64)))
}

/// One query: the roadmap plus the query's start (id = nodes.len()) and goal rods.
struct Query<'p> {
    planner: &'p mut Planner,
    start: PlanarParams,
    goals: Vec<PlanarParams>,
    obstacles: &'p [Obstacle],
    /// Edges that failed this query (collision) or for good (stability).
    blocked: HashSet<(NodeId, NodeId)>,
    neighbours: HashMap<NodeId, Vec<NodeId>>,
    edges_checked: usize,
}

impl<'p> Query<'p> {
    fn new(
        planner: &'p mut Planner,
        start: PlanarParams,
        goals: Vec<PlanarParams>,
        request: &'p PlanRequest,
    ) -> Self {
        Self {
            planner,
            start,
            goals,
            obstacles: &request.obstacles,
            blocked: HashSet::new(),
            neighbours: HashMap::new(),
            edges_checked: 0,
        }
    }

    fn n_roadmap(&self) -> usize {
        self.planner.nodes.len()
    }

    fn start_id(&self) -> NodeId {
        self.n_roadmap()
    }

    fn is_goal(&self, id: NodeId) -> bool {
        id > self.start_id()
    }

    fn node(&self, id: NodeId) -> PlanarParams {
        let n = self.n_roadmap();
        if id < n {
            self.planner.nodes[id]
        } else if id == n {
            self.start
        } else {
            self.goals[id - n - 1]
        }
    }

    fn expired(&self) -> bool {
        crate::deadline::expired()
    }

    /// The nearest roadmap nodes of `id`, and for every node near a goal (or the start) that
    /// goal (or start): query nodes join the roadmap symmetrically.
    fn neighbours(&mut self, id: NodeId) -> Vec<NodeId> {
        if let Some(v) = self.neighbours.get(&id) {
            return v.clone();
        }
        let a = self.node(id);
        let mut d: Vec<(f64, NodeId)> = (0..self.n_roadmap())
            .filter(|&k| k != id)
            .map(|k| ((self.planner.nodes[k] - a).norm() / (1.0 + a.norm()), k))
            .collect();
        let k = NEIGHBOURS.min(d.len());
        if k > 0 {
            d.select_nth_unstable_by(k - 1, |p, q| p.0.total_cmp(&q.0));
        }
        let mut out: Vec<NodeId> = d[..k].iter().map(|p| p.1).collect();
        // Query nodes: connect to each other directly, and any roadmap node that lists a
        // query node among its nearest also reaches it.
        let total = self.n_roadmap() + 1 + self.goals.len();
        for q in self.start_id()..total {
            if q == id {
                continue;
            }
            let b = self.node(q);
            let dq = (b - a).norm() / (1.0 + a.norm());
            let near = id >= self.start_id() || d[..k].iter().any(|p| dq <= p.0);
            if near {
                out.push(q);
            }
        }
        self.neighbours.insert(id, out.clone());
        out
    }

    /// A* from the start to any goal over edges not blocked; the node path.
    fn shortest_path(&mut self) -> Option<Vec<NodeId>> {
        #[derive(PartialEq)]
        struct Item(f64, NodeId);
        impl Eq for Item {}
        impl Ord for Item {
            fn cmp(&self, o: &Self) -> std::cmp::Ordering {
                o.0.total_cmp(&self.0)
            }
        }
        impl PartialOrd for Item {
            fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
                Some(self.cmp(o))
            }
        }
        let goals: Vec<PlanarParams> = self.goals.clone();
        let h = |a: &PlanarParams| {
            goals
                .iter()
                .map(|g| (g - a).norm())
                .fold(f64::INFINITY, f64::min)
        };
        let s = self.start_id();
        let mut g: HashMap<NodeId, f64> = HashMap::from([(s, 0.0)]);
        let mut parent: HashMap<NodeId, NodeId> = HashMap::new();
        let mut open = BinaryHeap::from([Item(h(&self.start), s)]);
        let mut closed = HashSet::new();
        while let Some(Item(_, u)) = open.pop() {
            if self.is_goal(u) {
                let mut path = vec![u];
                while let Some(&p) = parent.get(path.last()?) {
                    path.push(p);
                }
                path.reverse();
                return Some(path);
            }
            if !closed.insert(u) || self.expired() {
                continue;
            }
            let au = self.node(u);
            for v in self.neighbours(u) {
                if self.blocked.contains(&key(u, v)) || closed.contains(&v) {
                    continue;
                }
                let av = self.node(v);
                let cost = g[&u] + (av - au).norm();
                if g.get(&v).is_none_or(|&old| cost < old) {
                    g.insert(v, cost);
                    parent.insert(v, u);
                    open.push(Item(cost + h(&av), v));
                }
            }
        }
        None
    }

    /// Checks the edge u → v: stable with margin at every sample (kept across queries for
    /// roadmap pairs) and collision-free (this query). Returns the samples' smallest margin.
    fn check_edge(&mut self, u: NodeId, v: NodeId) -> Option<f64> {
        self.edges_checked += 1;
        let (a, b) = (self.node(u), self.node(v));
        let roadmap_pair = u < self.n_roadmap() && v < self.n_roadmap();
        if roadmap_pair && self.planner.edge_stable.get(&key(u, v)) == Some(&false) {
            return None;
        }
        let samples = edge_samples(&a, &b)?;
        let mut min_margin = f64::INFINITY;
        for r in samples {
            // Long edges (a start far from the roadmap) hold thousands of samples: each is
            // charged to the deadline, and an edge cut short is not cached as unstable.
            if self.expired() {
                return None;
            }
            let m = margin_of(&r, &self.planner.gravity);
            min_margin = min_margin.min(m);
            if m < MIN_MARGIN {
                if roadmap_pair {
                    self.planner.edge_stable.insert(key(u, v), false);
                }
                return None;
            }
        }
        if roadmap_pair {
            self.planner.edge_stable.insert(key(u, v), true);
        }
        for r in edge_samples(&a, &b)? {
            if collides(&r, &self.planner.gravity, self.obstacles) != Some(false) {
                return None;
            }
        }
        Some(min_margin)
    }

    fn run(&mut self) -> Result<Plan, PlanError> {
        loop {
            if self.expired() {
                return Err(PlanError::Deadline {
                    edges_checked: self.edges_checked,
                });
            }
            let Some(path) = self.shortest_path() else {
                if self.expired() {
                    return Err(PlanError::Deadline {
                        edges_checked: self.edges_checked,
                    });
                }
                return Err(PlanError::NoPath {
                    edges_checked: self.edges_checked,
                });
            };
            let mut min_margin = margin_of(&self.start, &self.planner.gravity);
            let mut ok = true;
            for w in path.windows(2) {
                match self.check_edge(w[0], w[1]) {
                    Some(m) => min_margin = min_margin.min(m),
                    None => {
                        self.blocked.insert(key(w[0], w[1]));
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                return Ok(self.assemble(&path, min_margin));
            }
        }
    }

    /// The plan's rods: every other checked sample of each edge (the others are midpoints).
    fn assemble(&self, path: &[NodeId], min_margin: f64) -> Plan {
        let mut rods = vec![self.start];
        for w in path.windows(2) {
            // Every edge of a path was checked, so its samples are bounded.
            if let Some(samples) = edge_samples(&self.node(w[0]), &self.node(w[1])) {
                rods.extend(samples.skip(1).step_by(2));
            }
        }
        let g = &self.planner.gravity;
        let gripper = rods
            .iter()
            .map(|a| heavy::tip(a, g).unwrap_or(PlanarPose::new(f64::NAN, f64::NAN, f64::NAN)))
            .collect();
        Plan {
            rods,
            gripper,
            min_margin,
        }
    }
}

fn key(u: NodeId, v: NodeId) -> (NodeId, NodeId) {
    (u.min(v), u.max(v))
}

#[cfg(test)]
mod tests {
    //! The obstacle geometry on polygons and discs from 1e-300 to the coordinate bound, and
    //! degenerate ones (issue 24: products of huge coordinates overflowed, tiny ones underflow).
    use super::*;
    use crate::planar::PlanarRod;
    use proptest::prelude::*;

    /// A rod drawn from the stable, moderately bent set (the shapes the planner sees).
    /// `collides` with no deadline in force (it always answers).
    fn touches(a: &PlanarParams, obstacles: &[Obstacle]) -> bool {
        collides(a, &Gravity::NONE, obstacles).expect("no deadline in force")
    }

    fn rod() -> impl Strategy<Value = PlanarParams> {
        (-6.0..6.0f64, -30.0..30.0f64, -30.0..30.0f64)
            .prop_map(|(a, b, c)| PlanarParams::new(a, b, c))
    }

    /// A log-uniform scale in [1e-300, MAX_OBSTACLE_COORDINATE / 2] (the triangles below
    /// reach 2× their scale).
    fn scale() -> impl Strategy<Value = f64> {
        (-300.0..(MAX_OBSTACLE_COORDINATE / 2.0).log10()).prop_map(|e: f64| 10f64.powf(e))
    }

    fn triangle(c: [f64; 2], s: f64) -> Obstacle {
        Obstacle::Polygon {
            points: vec![
                [c[0] + s, c[1] + s],
                [c[0] - s, c[1] + s],
                [c[0], c[1] - 2.0 * s],
            ],
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Every obstacle containing the base point (0, 0), which every rod passes through,
        /// touches every rod: tiny triangles and discs around the base, and triangles as large
        /// as the bound allows.
        #[test]
        fn obstacles_around_the_base_touch_every_rod(a in rod(), s in scale()) {
            prop_assume!(PlanarRod::new(&a).is_ok());
            prop_assert!(touches(&a, &[triangle([0.0, 0.0], s)]), "triangle of scale {s:e}");
            let disc = Obstacle::Disc { center: [s / 2.0, 0.0], radius: s };
            prop_assert!(touches(&a, &[disc]), "disc of radius {s:e}");
            prop_assert!(check_obstacle(&triangle([0.0, 0.0], s)).is_ok());
        }

        /// Obstacles beyond the unit disc (where no rod reaches) touch none, whatever their
        /// size, down to 1e-300.
        #[test]
        fn obstacles_out_of_reach_touch_no_rod(a in rod(), s in scale(), angle in 0.0..std::f64::consts::TAU) {
            prop_assume!(PlanarRod::new(&a).is_ok());
            let s = s.min(0.4);
            let c = [1.5 * angle.cos(), 1.5 * angle.sin()];
            prop_assert!(!touches(&a, &[triangle(c, s / 2.0)]), "triangle at {c:?} of scale {s:e}");
            let disc = Obstacle::Disc { center: c, radius: s };
            prop_assert!(!touches(&a, &[disc]));
        }

        /// A degenerate polygon (three collinear points: a wall of zero area) across the
        /// rod's chord is touched: the body runs from x = 0 to the tip's x, so it crosses
        /// x = tip.x / 2 somewhere within |y| ≤ 1.
        #[test]
        fn a_zero_area_wall_across_the_rod_is_touched(a in rod(), h in 1.0..MAX_OBSTACLE_COORDINATE) {
            let Ok(r) = PlanarRod::new(&a) else { return Ok(()) };
            let tip = r.tip();
            prop_assume!(tip.x.abs() > 0.05);
            let x = tip.x / 2.0;
            let wall = Obstacle::Polygon { points: vec![[x, -h], [x, 0.0], [x, h]] };
            prop_assert!(touches(&a, &[wall]), "wall at x = {x}, tip {tip:?}");
        }

        /// Coordinates beyond the bound, or not finite, are refused with the bound named.
        #[test]
        fn coordinates_beyond_the_bound_are_refused(e in 6.01..308.0f64, sign in prop::bool::ANY) {
            let v = if sign { 10f64.powf(e) } else { -(10f64.powf(e)) };
            let p = Obstacle::Polygon { points: vec![[0.0, 0.0], [v, 0.0], [0.0, 1.0]] };
            match check_obstacle(&p) {
                Err(PlanError::Invalid(why)) => prop_assert!(why.contains("1e6")),
                other => prop_assert!(false, "{v:e} accepted: {other:?}"),
            }
            let d = Obstacle::Disc { center: [v, 0.0], radius: 1.0 };
            prop_assert!(check_obstacle(&d).is_err());
        }
    }

    #[test]
    fn collinear_segments_meet_only_where_they_overlap() {
        assert!(segments_intersect(
            [0.0, 0.0],
            [1.0, 0.0],
            [0.5, 0.0],
            [2.0, 0.0]
        ));
        assert!(!segments_intersect(
            [0.0, 0.0],
            [1.0, 0.0],
            [1.5, 0.0],
            [2.0, 0.0]
        ));
        assert!(segments_intersect(
            [0.0, 0.0],
            [1.0, 1.0],
            [1e-300, 1e-300],
            [2e-300, 2e-300]
        ));
        for bad in [f64::NAN, f64::INFINITY, 1e200] {
            let p = Obstacle::Polygon {
                points: vec![[0.0, 0.0], [bad, 0.0], [0.0, 1.0]],
            };
            assert!(check_obstacle(&p).is_err());
        }
    }
}
