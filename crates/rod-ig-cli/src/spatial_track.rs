//! `rod-ig track3d`: the 3-D rod (with or without weight) follows its equilibrium branch as
//! the tip gripper moves, JSON lines in and out (`track`'s 3-D twin). No math here: the
//! solver crate's one `BranchFollower` on `Spatial` or `HeavySpatial`.

use crate::answer::MoveAnswer;
use crate::follower::{change_load, Follower, LoadChange, Model};
use crate::jsonl;
use crate::spatial_cmds::{stiffness, with_wrenches, PoseJson};
use rod_ig_core::solver::SolveOptions;
use rod_ig_core::spatial::heavy::{self, Gravity3};
use rod_ig_core::spatial::{HeavySpatial, Spatial, SpatialParams, SpatialPose, Stiffness};
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
        let change = self.carry_to(model, options)?;
        let follower = self.follower.get_or_insert_with(|| {
            Follower3d::new(model_of(model.stiffness, model.gravity), options)
        });
        let m = follower.follow(&target, options);
        let held = follower.rod();
        let mut answer = MoveAnswer::of(&m, held.as_ref(), params6, PoseJson::from_pose);
        if let Some(change) = change {
            change.mark(&mut answer, params6, PoseJson::from_pose);
        }
        let mut value = jsonl::to_value(&answer)?;
        with_wrenches(&mut value, &model.stiffness, &model.gravity);
        Ok(value)
    }

    /// The line's model: the stream's, with the line's weight and gravity (a change carries
    /// the held rod: [`Tracking3d::carry_to`]); the stiffness is the stream's.
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
            Some(m) if m.stiffness != model.stiffness && self.follower.is_some() => Err(
                "track3d: the stiffness is the stream's (set by its first line); changing it \
                 under a held 3-D rod is not supported"
                    .into(),
            ),
            _ => Ok(model),
        }
    }

    /// Makes `model` the stream's: a change of weight or gravity at fixed grippers carries
    /// the held rod ([`crate::follower::change_load`] with
    /// [`rod_ig_core::spatial::carry`]).
    fn carry_to(
        &mut self,
        model: StreamModel,
        options: SolveOptions<SpatialParams>,
    ) -> Result<Option<LoadChange<SpatialParams, SpatialPose>>, String> {
        let before = self.model.replace(model);
        let (Some(from), Some(follower)) = (before, &self.follower) else {
            return Ok(None);
        };
        if from == model {
            return Ok(None);
        }
        let heavy = |m: StreamModel| HeavySpatial {
            stiffness: m.stiffness,
            gravity: m.gravity,
        };
        let (f, change) = change_load(
            follower,
            (model_of(model.stiffness, model.gravity), heavy(model)),
            options,
            |a, gripper| {
                rod_ig_core::spatial::carry(a, &heavy(from), &heavy(model), gripper, &options)
                    .map(|s| s.a)
                    .map_err(|f| f.termination())
            },
            |a| {
                heavy::evaluate(a, &model.stiffness, &model.gravity)
                    .map(|e| e.energy)
                    .unwrap_or(f64::NAN)
            },
        )?;
        self.follower = Some(f);
        Ok(Some(change))
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
