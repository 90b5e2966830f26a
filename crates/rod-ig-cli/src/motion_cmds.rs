//! `rod-ig track` and `rod-ig plan`: quasi-static motion of the planar rod, JSON lines in and
//! out, optional SVG pictures of the rod sequence. No math here.

use crate::answer::MoveAnswer;
use crate::follower::{Follower, LoadChange, Model};
use crate::jsonl;
use crate::svg::{Obstacle as DrawnObstacle, SequenceKind, SequenceRod};
use rod_ig_core::plan::{self, Obstacle, PlanRequest, Planner};
use rod_ig_core::planar::heavy::{self, Gravity, HeavyPlanar};
use rod_ig_core::planar::ig::SolveOptions;
use rod_ig_core::planar::PlanarClosedForm;
use rod_ig_core::solver::{BranchEvent, Move};
use rod_ig_core::{PlanarParams, PlanarPose};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// What a change of gravity did to the held rod.
type GravityChange = LoadChange<PlanarParams, PlanarPose>;

/// Samples per drawn rod.
const DRAW_SAMPLES: usize = 60;

/// One `rod-ig track` line.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TrackRequest {
    /// The rod the gripper holds at the start (first line only, optional).
    a0: Option<[f64; 3]>,
    target: PlanarPose,
    tolerance: Option<f64>,
    deadline_ms: Option<f64>,
    /// Dimensionless weight from this line on (default: the stream's, at first 0).
    weight: Option<f64>,
    /// Direction of gravity from this line on (default: the stream's, at first [0, -1]).
    gravity: Option<[f64; 2]>,
    /// "clamped" (the default) here; pinned and free ends go to `held_cmds::HeldTrack`.
    #[allow(dead_code)] // read by `held_cmds::held_ends_of`
    base_condition: Option<Value>,
    #[allow(dead_code)] // read by `held_cmds::held_ends_of`
    tip_condition: Option<Value>,
}

/// The branch follower of a stream: the weightless closed forms until a line gives weight.
type PlanarFollower = Follower<3, PlanarClosedForm, HeavyPlanar>;

/// The model under gravity `g`.
fn model_of(g: Gravity) -> Model<PlanarClosedForm, HeavyPlanar> {
    if g.is_weightless() {
        Model::Weightless(PlanarClosedForm)
    } else {
        Model::Heavy(HeavyPlanar::new(g))
    }
}

/// Most rods kept for a `track --svg` picture: past it, every other rod along the motion is
/// dropped (starts, critical and snapped rods are kept), so memory stays flat over any
/// stream and the picture still spans it.
pub const MAX_DRAWN_RODS: usize = 1000;

/// The state of a `track` stream: the follower and, for `--svg`, the rods so far.
#[derive(Default)]
pub struct Tracking {
    follower: Option<PlanarFollower>,
    /// The stream's rod when its lines hold it by pinned or free ends.
    held: crate::held_cmds::HeldTrack,
    /// The stream's gravity (a line with `weight` or `gravity` changes it for the next lines).
    gravity: Gravity,
    /// Whether rods are kept for a picture (`--svg`).
    draws: bool,
    /// Rods for the picture (at most about [`MAX_DRAWN_RODS`]).
    pub drawn: Vec<SequenceRod>,
    /// Keep one in `stride` of the rods along the motion (doubles each time the list thins).
    stride: usize,
    /// Rods along the motion seen since the last one kept.
    skipped: usize,
}

impl Tracking {
    /// A stream's state; `draws`: keep rods for a picture.
    pub fn new(draws: bool) -> Self {
        Self {
            draws,
            stride: 1,
            ..Self::default()
        }
    }

    /// Keeps rod `a` for the picture (only with `--svg`), thinning the rods along the motion
    /// to stay within [`MAX_DRAWN_RODS`].
    fn draw(&mut self, a: &PlanarParams, gravity: &Gravity, kind: SequenceKind) {
        if !self.draws {
            return;
        }
        if matches!(kind, SequenceKind::Step) {
            self.skipped += 1;
            if self.skipped < self.stride {
                return;
            }
            self.skipped = 0;
        }
        self.drawn.push(SequenceRod {
            poses: shape(a, gravity),
            kind,
        });
        if self.drawn.len() >= MAX_DRAWN_RODS {
            let mut step = 0usize;
            self.drawn.retain(|r| {
                step += usize::from(matches!(r.kind, SequenceKind::Step));
                !matches!(r.kind, SequenceKind::Step) || step % 2 == 1
            });
            self.stride *= 2;
        }
        if self.drawn.len() >= MAX_DRAWN_RODS {
            // A stream of snaps alone: every other rod of any kind.
            let mut i = 0usize;
            self.drawn.retain(|_| {
                i += 1;
                i % 2 == 1
            });
        }
    }
}

fn params3(a: &PlanarParams) -> [f64; 3] {
    [a[0], a[1], a[2]]
}

fn shape(a: &PlanarParams, g: &Gravity) -> Vec<PlanarPose> {
    heavy::shape(a, g, DRAW_SAMPLES).unwrap_or_default()
}

/// Carries the rod `follower` holds from gravity `from` to `to`, the gripper fixed
/// ([`crate::follower::change_load`]).
fn change_gravity(
    follower: &PlanarFollower,
    from: &Gravity,
    to: &Gravity,
    options: SolveOptions,
) -> Result<(PlanarFollower, GravityChange), String> {
    crate::follower::change_load(
        follower,
        (model_of(*to), HeavyPlanar::new(*to)),
        options,
        |a, gripper| {
            heavy::carry(a, from, to, gripper, &options)
                .map(|s| s.a)
                .map_err(|f| f.termination())
        },
        |a| heavy::energy(a, to).map(|e| e.0).unwrap_or(f64::NAN),
    )
}

impl Tracking {
    /// Answers one `track` line.
    pub fn line(&mut self, line: &str) -> Result<Value, String> {
        let value: Value = jsonl::parse(line)?;
        if let Some(ends) = crate::held_cmds::held_ends_of(&value)? {
            return self.held.line(line, ends);
        }
        let request: TrackRequest = jsonl::parse(line)?;
        let gravity = self.requested_gravity(&request)?;
        let options = jsonl::follow_options(
            request.tolerance,
            request.deadline_ms,
            !gravity.is_weightless(),
        )?;
        let change = self.hold(&request, gravity, options)?;
        let follower = self
            .follower
            .get_or_insert_with(|| PlanarFollower::new(model_of(gravity), options));
        let m = follower.follow(&request.target, options);
        let held_a = follower.rod();
        let answer = self.answer(&m, change, held_a, &gravity);
        let mut value = jsonl::to_value(&answer)?;
        jsonl::with_fields_of_a(&mut value, |a| match <[f64; 3]>::try_from(a) {
            Ok(a) => crate::planar_cmds::wrench_fields(&PlanarParams::from(a), &gravity),
            Err(_) => Vec::new(),
        });
        Ok(value)
    }

    /// The gravity of a line: the stream's, changed by the line's `weight` and `gravity`.
    fn requested_gravity(&self, request: &TrackRequest) -> Result<Gravity, String> {
        if request.weight.is_none() && request.gravity.is_none() {
            return Ok(self.gravity);
        }
        crate::planar_cmds::gravity_of(
            Some(request.weight.unwrap_or(self.gravity.weight())),
            Some(request.gravity.unwrap_or(self.gravity.direction())),
        )
    }

    /// Takes the line's `a0` (first line only) and carries the held rod to the line's gravity.
    fn hold(
        &mut self,
        request: &TrackRequest,
        gravity: Gravity,
        options: SolveOptions,
    ) -> Result<Option<GravityChange>, String> {
        if let Some(a0) = request.a0 {
            // Only before the stream holds a rod: a first line that was refused does not
            // lock the start out.
            if self.follower.is_some() {
                return Err(
                    "\"a0\" is only accepted on the first line (before any rod is held)".into(),
                );
            }
            let a0 = PlanarParams::from(a0);
            let follower = PlanarFollower::holding(model_of(gravity), options, a0)
                .map_err(|e| format!("a0 cannot be held: {e}"))?;
            self.draw(&a0, &gravity, SequenceKind::Start);
            self.follower = Some(follower);
            self.gravity = gravity;
        }
        let mut change = None;
        if gravity != self.gravity {
            if let Some(f) = &self.follower {
                let (f, c) = change_gravity(f, &self.gravity, &gravity, options)?;
                self.follower = Some(f);
                change = Some(c);
            } else {
                self.follower = None;
            }
            self.gravity = gravity;
        }
        Ok(change)
    }

    /// The answer to a move, with the snap of a change of gravity when the move had none, and
    /// the rods for the picture.
    fn answer(
        &mut self,
        m: &Move<PlanarParams, PlanarPose>,
        change: Option<GravityChange>,
        held_a: Option<PlanarParams>,
        gravity: &Gravity,
    ) -> MoveAnswer<[f64; 3], PlanarPose> {
        let gravity = *gravity;
        let mut answer = MoveAnswer::of(m, held_a.as_ref(), params3, |t| *t);
        if let BranchEvent::Snap { critical_a, .. } = m.event {
            self.draw(&critical_a, &gravity, SequenceKind::Critical);
        } else if let Some(change) = change {
            change.mark(&mut answer, params3, |t| *t);
        }
        if let Ok(s) = &m.result {
            let kind = if matches!(m.event, BranchEvent::Snap { .. }) {
                SequenceKind::Snapped
            } else {
                SequenceKind::Step
            };
            self.draw(&s.a, &gravity, kind);
        }
        answer
    }
}

/// One `rod-ig plan` line.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlanLine {
    start: [f64; 3],
    goal: PlanarPose,
    #[serde(default)]
    obstacles: Vec<Obstacle>,
    deadline_ms: Option<f64>,
    /// Dimensionless weight w = ρgAL³/EI (default 0).
    weight: Option<f64>,
    /// Direction of gravity in the base frame (default [0, -1]).
    gravity: Option<[f64; 2]>,
}

/// A `plan` answer.
#[derive(Serialize)]
struct PlanAnswer {
    success: bool,
    rods: Vec<[f64; 3]>,
    gripper: Vec<PlanarPose>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
    /// Smallest stability margin along the plan (rods and midpoints).
    #[serde(skip_serializing_if = "Option::is_none")]
    min_margin: Option<f64>,
    elapsed_ms: f64,
}

/// The state of a `plan` stream: one roadmap reused across queries, and the last plan's rods
/// for `--svg`.
#[derive(Default)]
pub struct Planning {
    planner: Planner,
    /// Rods and obstacles of the last plan, for the picture.
    pub drawn: Vec<SequenceRod>,
    /// Obstacles of the last plan.
    pub obstacles: Vec<DrawnObstacle>,
}

impl Planning {
    /// Answers one `plan` line.
    pub fn line(&mut self, line: &str) -> Result<Value, String> {
        let request: PlanLine = jsonl::parse(line)?;
        let deadline = match request.deadline_ms {
            Some(ms) => jsonl::deadline_from_ms(ms)?,
            None => plan::DEFAULT_PLAN_DEADLINE,
        };
        let gravity = crate::planar_cmds::gravity_of(request.weight, request.gravity)?;
        let query = PlanRequest {
            start: PlanarParams::from(request.start),
            goal: request.goal,
            obstacles: request.obstacles,
            deadline,
            gravity,
        };
        let t0 = std::time::Instant::now();
        let result = self.planner.plan(&query);
        let elapsed_ms = t0.elapsed().as_secs_f64() * 1e3;
        let answer = match result {
            Ok(p) => {
                self.drawn = p
                    .rods
                    .iter()
                    .enumerate()
                    .map(|(i, a)| SequenceRod {
                        poses: shape(a, &gravity),
                        kind: if i == 0 {
                            SequenceKind::Start
                        } else {
                            SequenceKind::Step
                        },
                    })
                    .collect();
                self.obstacles = query.obstacles.iter().map(DrawnObstacle::from).collect();
                PlanAnswer {
                    success: true,
                    rods: p.rods.iter().map(params3).collect(),
                    gripper: p.gripper,
                    reason: None,
                    min_margin: Some(p.min_margin),
                    elapsed_ms,
                }
            }
            Err(e) => PlanAnswer {
                success: false,
                rods: Vec::new(),
                gripper: Vec::new(),
                reason: Some(e.to_string()),
                min_margin: None,
                elapsed_ms,
            },
        };
        jsonl::to_value(&answer)
    }
}
