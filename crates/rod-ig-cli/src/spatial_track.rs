//! `rod-ig track3d`: the 3-D rod (with or without weight) follows its equilibrium branch as
//! the tip gripper moves, JSON lines in and out (`track`'s 3-D twin). No math here: the
//! solver crate's one `BranchFollower` on `Spatial` or `HeavySpatial`.

use crate::answer::MoveAnswer;
use crate::follower::{Follower, Model};
use crate::jsonl;
use crate::spatial_cmds::{stiffness, with_wrenches, PoseJson};
use rod_ig_core::solver::SolveOptions;
use rod_ig_core::spatial::heavy::Gravity3;
use rod_ig_core::spatial::{HeavySpatial, Spatial, SpatialParams, Stiffness};
use serde::Deserialize;
use serde_json::Value;

/// One `track3d` line.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Track3dRequest {
    /// The rod the gripper holds at the start (first line only, optional).
    a0: Option<[f64; 6]>,
    target: PoseJson,
    tolerance: Option<f64>,
    /// Wall-time budget of the line in ms (default 1000, at most 10000).
    deadline_ms: Option<f64>,
    /// Dimensionless weight w = ρgAL³/EI (the stream's: set by its first line, default 0).
    weight: Option<f64>,
    /// Direction of gravity in the base frame (the stream's, default [0, 0, -1]).
    gravity: Option<[f64; 3]>,
    /// (c1, c2, c3) (the stream's, default (1, 1, 1)).
    stiffness: Option<[f64; 3]>,
}

/// The follower of a stream: the weightless rod, or the rod with weight.
type Follower3d = Follower<6, Spatial, HeavySpatial>;

/// The model of stiffness `k` under gravity `g`.
fn model_of(k: Stiffness, g: Gravity3) -> Model<Spatial, HeavySpatial> {
    if g.is_weightless() {
        Model::Weightless(Spatial::with_stiffness(k))
    } else {
        Model::Heavy(HeavySpatial {
            stiffness: k,
            gravity: g,
        })
    }
}

/// The stream's rod model, fixed by its first line.
#[derive(Clone, Copy, PartialEq)]
struct StreamModel {
    stiffness: Stiffness,
    gravity: Gravity3,
}

/// The state of a `track3d` stream.
#[derive(Default)]
pub struct Tracking3d {
    follower: Option<Follower3d>,
    model: Option<StreamModel>,
}

fn params6(a: &SpatialParams) -> [f64; 6] {
    std::array::from_fn(|i| a[i])
}

impl Tracking3d {
    /// Answers one `track3d` line.
    pub fn line(&mut self, line: &str) -> Result<Value, String> {
        let request: Track3dRequest = jsonl::parse(line)?;
        let target = request.target.to_pose()?;
        let model = self.model_of(&request)?;
        let options: SolveOptions<SpatialParams> = jsonl::follow_options(
            request.tolerance,
            request.deadline_ms,
            !model.gravity.is_weightless(),
        )?;
        if let Some(a0) = request.a0 {
            if self.follower.is_some() {
                return Err(
                    "\"a0\" is only accepted on the first line (before any rod is held)".into(),
                );
            }
            let held = Follower3d::holding(
                model_of(model.stiffness, model.gravity),
                options,
                SpatialParams::from(a0),
            )
            .map_err(|e| format!("a0 cannot be held: {e}"))?;
            self.follower = Some(held);
        }
        self.model = Some(model);
        let follower = self.follower.get_or_insert_with(|| {
            Follower3d::new(model_of(model.stiffness, model.gravity), options)
        });
        let m = follower.follow(&target, options);
        let held = follower.rod();
        let answer = MoveAnswer::of(&m, held.as_ref(), params6, PoseJson::from_pose);
        let mut value = jsonl::to_value(&answer)?;
        with_wrenches(&mut value, &model.stiffness, &model.gravity);
        Ok(value)
    }

    /// The line's model: the stream's, which a later line may restate but not change (a
    /// change of weight or gravity at fixed grippers is not followed in 3-D yet).
    fn model_of(&self, request: &Track3dRequest) -> Result<StreamModel, String> {
        let k = match (request.stiffness, self.model) {
            (None, Some(m)) => m.stiffness,
            (c, _) => stiffness(c)?,
        };
        let g = match (request.weight, request.gravity, self.model) {
            (None, None, Some(m)) => m.gravity,
            (w, d, held) => {
                let held = held.map(|m| m.gravity);
                let weight = w.or(held.map(|g| g.weight())).unwrap_or(0.0);
                let direction = d
                    .or(held.map(|g| g.direction()))
                    .unwrap_or([0.0, 0.0, -1.0]);
                Gravity3::new(weight, direction).map_err(|e| e.to_string())?
            }
        };
        let model = StreamModel {
            stiffness: k,
            gravity: g,
        };
        match self.model {
            Some(m) if m != model && self.follower.is_some() => Err(
                "track3d: weight, gravity and stiffness are the stream's (set by its first \
                 line); changing them under a held 3-D rod is not supported yet"
                    .into(),
            ),
            _ => Ok(model),
        }
    }
}

/// `rod-ig track3d`: answers each line of `input` on `output`.
pub fn run<R: std::io::BufRead, W: std::io::Write>(
    input: R,
    output: W,
    warm_up: impl FnOnce(),
) -> Result<(), String> {
    // A rod with weight starts from the planar rods (their atlas, built as for `solve3d`).
    warm_up();
    let mut tracking = Tracking3d::default();
    jsonl::run(input, output, |line| tracking.line(line)).map_err(|e| e.to_string())
}
