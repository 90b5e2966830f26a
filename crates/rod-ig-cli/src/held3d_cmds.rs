//! `rod-ig solve3d` and `forward3d` with pinned or free ends (`base_condition`,
//! `tip_condition`): JSON in, JSON out; the search is `rod_ig_core::spatial::held`.

use crate::held_cmds::{held_ends_of, HeldAnswer, DEFAULT_HELD_DEADLINE};
use crate::jsonl::{self, ObjectiveName};
use crate::planar_cmds::MAX_TURNS;
use crate::spatial_cmds::{stiffness, PoseJson};
use nalgebra::{UnitQuaternion, Vector3};
use rod_ig_core::ends::{EndCondition, HeldEnds};
use rod_ig_core::planar::ig::SolveOptions;
use rod_ig_core::spatial::heavy::Gravity3;
use rod_ig_core::spatial::held::{self, SpatialHeldSearch, SpatialHeldSolution};
use rod_ig_core::spatial::{SpatialParams, SpatialPose};
use rod_ig_core::wrench::SpatialWrench;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::time::Instant;

/// The ends a 3-D request names when either is not clamped.
fn ends_of(line: &str) -> Result<Option<HeldEnds>, String> {
    held_ends_of(&jsonl::parse::<Value>(line)?)
}

/// Answers one `solve3d` line: with a pinned or free tip here, else the clamped solver
/// ([`crate::spatial_cmds::solve3d_line`], `verbose`: its events on stderr).
pub fn solve3d_line(line: &str, verbose: bool) -> Result<Value, String> {
    match ends_of(line)? {
        Some(ends) => solve3d_held(line, ends),
        None => crate::spatial_cmds::solve3d_line(line, verbose),
    }
}

/// Answers one `forward3d` line: with a pinned or free tip here, else the clamped rod's.
pub fn forward3d_line(line: &str) -> Result<Value, String> {
    match ends_of(line)? {
        Some(ends) => forward3d_held(line, ends),
        None => crate::spatial_cmds::forward3d_line(line),
    }
}

/// A held tip's target: a pinned tip's position (its orientation is free: a quaternion is
/// refused with the reason), or a clamped tip's pose (a pinned base).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PositionJson {
    position: [f64; 3],
    quaternion: Option<[f64; 4]>,
}

/// One `solve3d` request with a pinned or free tip.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Held3dRequest {
    target: Option<PositionJson>,
    #[allow(dead_code)] // read by `ends_of`
    base_condition: Option<Value>,
    #[allow(dead_code)] // read by `ends_of`
    tip_condition: Option<Value>,
    /// "least_energy" or "first": both answer the least-energy rod found.
    #[allow(dead_code)]
    objective: Option<ObjectiveName>,
    #[serde(default)]
    all: bool,
    deadline_ms: Option<f64>,
    weight: Option<f64>,
    gravity: Option<[f64; 3]>,
    stiffness: Option<[f64; 3]>,
    max_turns: Option<u32>,
}

/// One rod of a 3-D held answer.
#[derive(Serialize)]
struct Held3dRod {
    a: [f64; 6],
    /// A pinned base's orientation (x, y, z, w): the rod leaves the hook along its x axis.
    #[serde(skip_serializing_if = "Option::is_none")]
    base_quaternion: Option<[f64; 4]>,
    tip: PoseJson,
    stable: bool,
    energy: f64,
    elastic_energy: f64,
    /// The clamped margin, capped by the reduced Hessian's λ_min / λ₀ (docs/ends.md).
    stability_margin: f64,
    stability_uncertain: bool,
    turns: u32,
    base_wrench: SpatialWrench,
    tip_wrench: SpatialWrench,
    /// Distance from the tip to a pinned tip's target.
    #[serde(skip_serializing_if = "Option::is_none")]
    position_error: Option<f64>,
}

fn rod_of(s: &SpatialHeldSolution, target: Option<&Vector3<f64>>) -> Result<Held3dRod, String> {
    let w = s.wrenches().map_err(|e| e.to_string())?;
    Ok(Held3dRod {
        a: std::array::from_fn(|i| s.a[i]),
        base_quaternion: s.cable.is_base_pinned().then(|| {
            SpatialPose {
                position: Vector3::zeros(),
                rotation: s.base_rotation,
            }
            .quaternion_xyzw()
        }),
        tip: PoseJson::from_pose(&s.tip),
        stable: s.stability.stable,
        energy: s.energy,
        elastic_energy: s.elastic_energy,
        stability_margin: s.stability.margin,
        stability_uncertain: s.stability.uncertain,
        turns: s.turns,
        base_wrench: w.base,
        tip_wrench: w.tip,
        position_error: target.map(|t| (s.tip.position - t).norm()),
    })
}

fn gravity3(weight: Option<f64>, gravity: Option<[f64; 3]>) -> Result<Gravity3, String> {
    Gravity3::new(weight.unwrap_or(0.0), gravity.unwrap_or([0.0, 0.0, -1.0]))
        .map_err(|e| e.to_string())
}

/// Answers one `solve3d` line with pinned or free ends: a pinned tip's position, a free tip
/// (no target), or a pinned base with a clamped tip's pose.
pub fn solve3d_held(line: &str, ends: HeldEnds) -> Result<Value, String> {
    let started = Instant::now();
    let request: Held3dRequest = jsonl::parse(line)?;
    let max_turns = request.max_turns.unwrap_or(0);
    if max_turns > MAX_TURNS {
        return Err(format!(
            "max_turns must be in [0, {MAX_TURNS}] (got {max_turns})"
        ));
    }
    let options = SolveOptions {
        deadline: match request.deadline_ms {
            Some(ms) => jsonl::deadline_from_ms(ms)?,
            None => DEFAULT_HELD_DEADLINE,
        },
        max_turns,
        ..SolveOptions::default()
    };
    let k = stiffness(request.stiffness)?;
    let g = gravity3(request.weight, request.gravity)?;
    let (found, position) =
        match (request.target, ends.tip()) {
            (
                Some(PositionJson {
                    quaternion: Some(_),
                    ..
                }),
                EndCondition::Pinned,
            ) => return Err(
                "target: a pinned tip's target is {\"position\"} (it turns freely: no quaternion)"
                    .into(),
            ),
            (
                Some(PositionJson {
                    position,
                    quaternion: Some(q),
                }),
                EndCondition::Clamped,
            ) => {
                let pose = SpatialPose::from_xyzw(Vector3::from(position), q)
                    .map_err(|e| format!("target: {e}"))?;
                let found = held::equilibria_to_pose(&k, &g, &pose, &options);
                (found, Some(pose.position))
            }
            (_, EndCondition::Clamped) => {
                return Err("target: a clamped tip needs {\"position\", \"quaternion\"}".into())
            }
            (t, _) => {
                let p = t.map(|t| Vector3::from(t.position));
                (held::equilibria(ends, &k, &g, p.as_ref(), &options), p)
            }
        };
    let found = found.map_err(|e| e.to_string())?;
    jsonl::to_value(&answer_of(
        ends,
        &found,
        position.as_ref(),
        request.all,
        started,
    )?)
}

fn answer_of(
    ends: HeldEnds,
    found: &SpatialHeldSearch,
    target: Option<&Vector3<f64>>,
    all: bool,
    started: Instant,
) -> Result<HeldAnswer<Held3dRod>, String> {
    let solutions = match all {
        true => Some(
            found
                .solutions
                .iter()
                .map(|s| rod_of(s, target))
                .collect::<Result<Vec<_>, _>>()?,
        ),
        false => None,
    };
    Ok(HeldAnswer::new(
        ends,
        found
            .solutions
            .first()
            .map(|s| rod_of(s, target))
            .transpose()?,
        solutions,
        found.rejected,
        found.starts,
        found.cut_short,
        || found.not_found(ends).to_string(),
        started,
    ))
}

/// One `forward3d` request with a pinned or free tip.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HeldForward3dRequest {
    /// (a_m, a_f); a free tip's a_f must be w ĝ, a pinned base's a_m 0.
    a: [f64; 6],
    /// A pinned base's orientation (x, y, z, w; default the identity).
    base_quaternion: Option<[f64; 4]>,
    #[allow(dead_code)] // read by `ends_of`
    base_condition: Option<Value>,
    #[allow(dead_code)] // read by `ends_of`
    tip_condition: Option<Value>,
    weight: Option<f64>,
    gravity: Option<[f64; 3]>,
    stiffness: Option<[f64; 3]>,
    deadline_ms: Option<f64>,
}

/// Answers one `forward3d` line whose tip is pinned or free: the rod integrated from the
/// base, with the tip's natural conditions in its verdict.
pub fn forward3d_held(line: &str, ends: HeldEnds) -> Result<Value, String> {
    let request: HeldForward3dRequest = jsonl::parse(line)?;
    let deadline = match request.deadline_ms {
        Some(ms) => jsonl::deadline_from_ms(ms)?,
        None => rod_ig_core::solver::DEFAULT_DEADLINE_3D,
    };
    let _deadline = rod_ig_core::deadline::scope(deadline);
    let base = match request.base_quaternion {
        Some(q) => {
            SpatialPose::from_xyzw(Vector3::zeros(), q)
                .map_err(|e| format!("base_quaternion: {e}"))?
                .rotation
        }
        None => UnitQuaternion::identity(),
    };
    let k = stiffness(request.stiffness)?;
    let g = gravity3(request.weight, request.gravity)?;
    let s = held::evaluate(&SpatialParams::from(request.a), &k, &g, ends, base)
        .map_err(|e| e.to_string())?;
    let jacobian = s.cable.tip_jacobian().map_err(|e| e.to_string())?;
    let mut value = jsonl::to_value(&rod_of(&s, None)?)?;
    if let Value::Object(map) = &mut value {
        map.insert("base_condition".into(), ends.base().name().into());
        map.insert("tip_condition".into(), ends.tip().name().into());
        // Rows ω, v of the tip's body twist; columns a_m (a pinned base: its turn), a_f.
        let rows: Option<Vec<[f64; 6]>> =
            jacobian.map(|j| (0..6).map(|r| std::array::from_fn(|c| j[(r, c)])).collect());
        map.insert("jacobian".into(), jsonl::to_value(&rows)?);
    }
    Ok(value)
}
