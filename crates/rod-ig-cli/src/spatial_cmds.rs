//! `rod-ig forward3d` and `rod-ig solve3d`: the 3-D twins of `forward` and `solve`.
//! Poses are {"position": [x, y, z], "quaternion": [qx, qy, qz, qw]} (scalar last, qw ≥ 0).

use crate::answer::answer;
use crate::jsonl::{self, Knobs, MethodName, ObjectiveName};
use nalgebra::Vector3;
use rod_ig_core::solver::SolveOptions;
use rod_ig_core::spatial::heavy::{self as heavy3, Gravity3};
use rod_ig_core::spatial::HeavySpatial;
use rod_ig_core::spatial::Spatial;
use rod_ig_core::spatial::{self, SpatialParams, SpatialPose, StabilityOptions, Stiffness};
use rod_ig_core::wrench::SpatialWrench;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// A pose as it travels in JSON.
#[derive(Serialize, Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub(crate) struct PoseJson {
    position: [f64; 3],
    /// (x, y, z, w), any nonzero norm on input; unit with w ≥ 0 on output.
    quaternion: [f64; 4],
}

impl PoseJson {
    pub(crate) fn from_pose(p: &SpatialPose) -> Self {
        PoseJson {
            position: [p.position.x, p.position.y, p.position.z],
            quaternion: p.quaternion_xyzw(),
        }
    }

    pub(crate) fn to_pose(self) -> Result<SpatialPose, String> {
        SpatialPose::from_xyzw(Vector3::from(self.position), self.quaternion)
            .map_err(|e| format!("target: {e}"))
    }
}

pub(crate) fn stiffness(c: Option<[f64; 3]>) -> Result<Stiffness, String> {
    let k = match c {
        Some([c1, c2, c3]) => Stiffness { c1, c2, c3 },
        None => Stiffness::default(),
    };
    k.validate().map_err(|e| format!("stiffness: {e}"))?;
    Ok(k)
}

/// One `forward3d` request.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Forward3dRequest {
    a: [f64; 6],
    /// (c1, c2, c3): torsion and the two bending stiffnesses; default (1, 1, 1).
    stiffness: Option<[f64; 3]>,
    /// Relative tolerance of the integration (default 1e-8).
    rtol: Option<f64>,
    /// Dimensionless weight w = ρgAL³/EI (default 0).
    weight: Option<f64>,
    /// Direction of gravity in the base frame (default [0, 0, -1]).
    gravity: Option<[f64; 3]>,
    /// Wall-time budget of the evaluation in ms (default 1000, at most 10000).
    deadline_ms: Option<f64>,
}

#[derive(Serialize)]
struct Forward3dAnswer {
    tip: PoseJson,
    /// J(1, a): column j = q⁻¹ ∂q/∂a_j as a body twist, rows (ω1, ω2, ω3, v1, v2, v3).
    jacobian: [[f64; 6]; 6],
    stable: bool,
    energy: f64,
    stability_margin: f64,
    /// With weight: the elastic part of `energy` (elastic + gravitational).
    #[serde(skip_serializing_if = "Option::is_none")]
    elastic_energy: Option<f64>,
    /// With weight: the verdict is undecided (`stable` is false then): above weight 200 the
    /// tip of this f64 `a` is not determined by single shooting (`condition` > 1e9), unless
    /// the rod is one `solve3d` returned in this process.
    #[serde(skip_serializing_if = "Option::is_none")]
    stability_uncertain: Option<bool>,
    /// With weight: ‖J(1)‖∞ · max(1, ‖a‖∞), the tip's sensitivity to a relative rounding of
    /// a (the tip is uncertain by about condition × 1.1e-16).
    #[serde(skip_serializing_if = "Option::is_none")]
    condition: Option<f64>,
    /// The wrench the rod exerts on the base gripper, in the base frame (`rod_ig_core::wrench`).
    base_wrench: SpatialWrench,
    /// The wrench the rod exerts on the tip gripper, in the tip frame.
    tip_wrench: SpatialWrench,
}

/// `forward3d` with a `weight`: the heavy 3-D rod (`spatial::heavy`, rtol 1e-10).
fn forward3d_heavy(
    request: &Forward3dRequest,
    k: &Stiffness,
    weight: f64,
) -> Result<Value, String> {
    if request.rtol.is_some() {
        return Err("rtol is fixed (1e-10) for the rod with weight".into());
    }
    let g = Gravity3::new(weight, request.gravity.unwrap_or([0.0, 0.0, -1.0]))
        .map_err(|e| e.to_string())?;
    let a = SpatialParams::from(request.a);
    let e = heavy3::evaluate(&a, k, &g).map_err(|e| e.to_string())?;
    let w = heavy3::wrenches(&a, k, &g).map_err(|e| e.to_string())?;
    jsonl::to_value(&Forward3dAnswer {
        tip: PoseJson::from_pose(&e.tip),
        jacobian: std::array::from_fn(|r| std::array::from_fn(|c| e.jacobian[(r, c)])),
        stable: e.stability.stable,
        energy: e.energy,
        stability_margin: e.stability.margin,
        elastic_energy: Some(e.elastic_energy),
        stability_uncertain: Some(e.stability.uncertain),
        condition: Some(e.condition),
        base_wrench: w.base,
        tip_wrench: w.tip,
    })
}

/// Answers one `forward3d` line, within its deadline.
pub fn forward3d_line(line: &str) -> Result<Value, String> {
    let request: Forward3dRequest = jsonl::parse(line)?;
    let deadline = match request.deadline_ms {
        Some(ms) => jsonl::deadline_from_ms(ms)?,
        None => rod_ig_core::solver::DEFAULT_DEADLINE_3D,
    };
    if deadline > rod_ig_core::solver::MAX_DEADLINE {
        return Err(format!(
            "deadline_ms must be at most {} ms",
            rod_ig_core::solver::MAX_DEADLINE.as_millis()
        ));
    }
    let _deadline = rod_ig_core::deadline::scope(deadline);
    forward3d_within(&request)
}

fn forward3d_within(request: &Forward3dRequest) -> Result<Value, String> {
    let k = stiffness(request.stiffness)?;
    if let Some(w) = request.weight.or(request.gravity.map(|_| 0.0)) {
        return forward3d_heavy(request, &k, w);
    }
    let mut opts = StabilityOptions::production();
    if let Some(rtol) = request.rtol {
        if !(rtol.is_finite() && (1e-14..=1e-3).contains(&rtol)) {
            return Err(format!("rtol must be in [1e-14, 1e-3], got {rtol}"));
        }
        opts.rtol = rtol;
    }
    let a = SpatialParams::from(request.a);
    let e = spatial::evaluate(&a, &k, &opts).map_err(|e| e.to_string())?;
    // Without weight the world wrench is conserved: the tip's follows from the tip pose.
    let (moment, force) = (
        Vector3::new(a[0], a[1], a[2]),
        Vector3::new(a[3], a[4], a[5]),
    );
    let w = rod_ig_core::wrench::spatial(&a, &e.tip, force, moment);
    jsonl::to_value(&Forward3dAnswer {
        tip: PoseJson::from_pose(&e.tip),
        jacobian: std::array::from_fn(|r| std::array::from_fn(|c| e.jacobian[(r, c)])),
        stable: e.stability.stable,
        energy: e.energy,
        stability_margin: e.stability.margin,
        elastic_energy: None,
        stability_uncertain: None,
        condition: None,
        base_wrench: w.base,
        tip_wrench: w.tip,
    })
}

/// One `solve3d` request.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Solve3dRequest {
    target: PoseJson,
    a0: Option<[f64; 6]>,
    #[serde(default)]
    method: MethodName,
    alpha: Option<f64>,
    max_iterations: Option<u32>,
    tolerance: Option<f64>,
    #[serde(default)]
    objective: ObjectiveName,
    /// When true, also list every distinct stable solution found (`solutions`).
    #[serde(default)]
    all: bool,
    stiffness: Option<[f64; 3]>,
    /// Wall-time budget of the request in ms (default 1000, at most 10000).
    deadline_ms: Option<f64>,
    /// Dimensionless weight w (default 0).
    weight: Option<f64>,
    /// Direction of gravity in the base frame (default [0, 0, -1]).
    gravity: Option<[f64; 3]>,
}

/// Answers one `solve3d` line (`verbose`: the solver's events on stderr).
pub fn solve3d_line(line: &str, verbose: bool) -> Result<Value, String> {
    let request: Solve3dRequest = jsonl::parse(line)?;
    let target = request.target.to_pose()?;
    let model = Spatial::with_stiffness(stiffness(request.stiffness)?);
    let knobs = Knobs {
        method: request.method,
        objective: request.objective,
        alpha: request.alpha,
        max_iterations: request.max_iterations,
        tolerance: request.tolerance,
        deadline_ms: request.deadline_ms,
        a0: request.a0.map(SpatialParams::from),
    };
    let options = jsonl::solve_options(knobs, SolveOptions::default())?;
    if let Some(w) = request.weight.or(request.gravity.map(|_| 0.0)) {
        let gravity = Gravity3::new(w, request.gravity.unwrap_or([0.0, 0.0, -1.0]))
            .map_err(|e| e.to_string())?;
        let heavy = HeavySpatial {
            stiffness: model.stiffness,
            gravity,
        };
        let mut value = jsonl::to_value(&answer(
            &heavy,
            &target,
            &options,
            request.all,
            verbose,
            |a| std::array::from_fn::<f64, 6, _>(|i| a[i]),
            PoseJson::from_pose,
        ))?;
        with_wrenches(&mut value, &model.stiffness, &gravity);
        return Ok(value);
    }
    let mut value = jsonl::to_value(&answer(
        &model,
        &target,
        &options,
        request.all,
        verbose,
        |a| std::array::from_fn::<f64, 6, _>(|i| a[i]),
        PoseJson::from_pose,
    ))?;
    with_wrenches(&mut value, &model.stiffness, &Gravity3::NONE);
    Ok(value)
}

/// Adds the gripper wrenches (`base_wrench`, `tip_wrench`) to a `solve3d` answer and its
/// `solutions`.
pub(crate) fn with_wrenches(value: &mut Value, k: &Stiffness, g: &Gravity3) {
    jsonl::with_fields_of_a(value, |a| match <[f64; 6]>::try_from(a) {
        Ok(a) => jsonl::wrench_fields(heavy3::wrenches(&SpatialParams::from(a), k, g).ok()),
        Err(_) => Vec::new(),
    });
}
