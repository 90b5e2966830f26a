//! Conversions between ROS messages (metres, quaternions) and the solver's normalised world
//! (unit rod length): planar (x, y, angle about z) or, for non-planar targets with the
//! parameter `solve_3d`, 3-D poses. No rod mechanics here: only unit scaling by the rod length
//! L ([`to_normalised`] / [`to_metres`]) and the bending stiffness EI, and quaternion ↔ yaw.

use rod_ig_core::planar::heavy::Gravity;
use rod_ig_core::spatial::heavy::Gravity3;
use thiserror::Error;

use crate::messages::{
    ColorRgba, Header, Marker, Path, Point, Pose, PoseStamped, Quaternion, RodSolution, Vector3,
    Wrench,
};
use crate::params::Params;
use crate::solver::{Failed, PlanarPose, Solved, Solved3d, SpatialParams, SpatialPose};
use rod_ig_core::solver::Solution;

/// Why a target pose cannot be solved for (answered with success = false).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TargetError {
    /// NaN or infinite coordinate.
    #[error("target pose has a non-finite {0}")]
    NonFinite(&'static str),
    /// Quaternion of (near) zero norm.
    #[error("target orientation is not a rotation (quaternion norm {0:.3e})")]
    ZeroQuaternion(f64),
    /// z beyond `planar_tolerance`.
    #[error("target is not planar: z = {z} m (the rod lies in the base's x-y plane, accepted |z| <= {tol} m)")]
    OffPlane {
        /// z (m).
        z: f64,
        /// Accepted |z| (m).
        tol: f64,
    },
    /// Rotation not about z.
    #[error("target rotation is not about z: tilt out of the x-y plane {tilt:.3e} rad (accepted <= {tol} rad)")]
    Tilted {
        /// Angle between the rotated z axis and z (rad).
        tilt: f64,
        /// Accepted tilt (rad).
        tol: f64,
    },
    /// Farther from the base than the rod is long.
    #[error("target out of reach: {distance} m from the base, must be less than the rod length {length} m")]
    OutOfReach {
        /// Base–target distance (m).
        distance: f64,
        /// Rod length (m).
        length: f64,
    },
    /// The weight parameters cannot be used (see [`gravity_of`]).
    #[error("{0}")]
    Weight(String),
    /// The end-condition parameters cannot be used together, or the target is not planar
    /// while an end is pinned or free (see [`ends_of`]).
    #[error("{0}")]
    Ends(String),
    /// Gravity leaves the rod's plane by more than `planar_tolerance`: the planar rod with
    /// weight hangs in a vertical plane (the 3-D rod's with `solve_3d`).
    #[error("gravity leaves the rod's plane by {tilt:.3e} rad (gravity z = {gz} m/s^2; accepted <= planar_tolerance = {tol} rad): the planar rod with weight hangs in a vertical plane; with solve_3d:=true the 3-D rod with weight serves every target")]
    GravityOutOfPlane {
        /// Angle between gravity and the rod's plane (rad).
        tilt: f64,
        /// Gravity's z component (m/s²).
        gz: f64,
        /// Accepted tilt (rad).
        tol: f64,
    },
    /// The target's frame could not be transformed into `base_frame` (`use_tf`).
    #[error(
        "cannot transform the target from frame {frame:?} to {base:?} within {timeout} s: {why}"
    )]
    Frame {
        /// The target's frame.
        frame: String,
        /// `base_frame`.
        base: String,
        /// `tf_timeout` (s).
        timeout: f64,
        /// What TF said.
        why: String,
    },
}

impl TargetError {
    /// The bounded key the diagnostics count this refusal by: "unreachable" as the solver
    /// says it, "non_planar", "invalid_input" (non-finite, not a rotation) or "tf_lookup".
    pub fn key(&self) -> &'static str {
        match self {
            Self::Frame { .. } => "tf_lookup",
            Self::OutOfReach { .. } => "unreachable",
            Self::OffPlane { .. } | Self::Tilted { .. } => "non_planar",
            Self::NonFinite(_)
            | Self::ZeroQuaternion(_)
            | Self::Weight(_)
            | Self::Ends(_)
            | Self::GravityOutOfPlane { .. } => "invalid_input",
        }
    }

    /// The target is valid except that it is not planar (z or tilt beyond
    /// `planar_tolerance`), or gravity is not in the rod's plane: the 3-D solver can take it
    /// when `solve_3d` is set.
    pub fn is_non_planar(&self) -> bool {
        matches!(
            self,
            Self::OffPlane { .. } | Self::Tilted { .. } | Self::GravityOutOfPlane { .. }
        )
    }
}

/// The end conditions of the parameters `base_condition` and `tip_condition` (a pinned base
/// with a free tip holds nothing: refused with the reason).
pub fn ends_of(params: &Params) -> Result<rod_ig_core::ends::HeldEnds, TargetError> {
    rod_ig_core::ends::HeldEnds::new(params.base_condition, params.tip_condition)
        .map_err(|e| TargetError::Ends(e.to_string()))
}

/// A non-planar target (`e`) while an end is pinned or free and `solve_3d` is off: refused,
/// with the parameter that takes it.
pub fn planar_ends_only(e: TargetError, params: &Params) -> TargetError {
    TargetError::Ends(format!(
        "{e}; pinned and free ends (base_condition {}, tip_condition {}) off the plane need \
         solve_3d",
        params.base_condition, params.tip_condition
    ))
}

/// The rod's weight from the parameters, in the base frame: the dimensionless
/// w = ρA |g| L³ / EI (`linear_density`, `gravity`, `rod_length`, `bending_stiffness`) and
/// gravity's direction; None when `linear_density` is 0. Refused with a reason when EI or
/// gravity is missing.
fn weight_of(params: &Params) -> Result<Option<(f64, [f64; 3])>, TargetError> {
    let refuse = |why: String| Err(TargetError::Weight(why));
    if params.linear_density == 0.0 {
        return Ok(None);
    }
    if params.bending_stiffness <= 0.0 {
        return refuse("linear_density > 0 needs bending_stiffness (EI, N m^2) > 0 for the rod's dimensionless weight".into());
    }
    let [gx, gy, gz] = params.gravity;
    let g = (gx * gx + gy * gy + gz * gz).sqrt();
    if g <= 0.0 || !g.is_finite() {
        return refuse("linear_density > 0 needs the gravity parameter (m/s^2 in the base frame, e.g. [0.0, -9.81, 0.0])".into());
    }
    let l = params.rod_length;
    Ok(Some((
        params.linear_density * g * l * l * l / params.bending_stiffness,
        params.gravity,
    )))
}

fn out_of_domain(w: f64, e: impl std::fmt::Display) -> TargetError {
    TargetError::Weight(format!(
        "the rod's dimensionless weight w = rho*A*g*L^3/EI = {w:e}: {e}"
    ))
}

/// The planar rod's weight (`weight_of`) along the direction of gravity in the rod's plane
/// (the base frame's x-y plane). Also refused when gravity leaves the rod's plane by more than
/// `planar_tolerance` (rad): such a rod is the 3-D rod's ([`gravity_3d_of`], `solve_3d`), or
/// when w exceeds the solver's domain.
pub fn gravity_of(params: &Params) -> Result<Gravity, TargetError> {
    let Some((w, [gx, gy, gz])) = weight_of(params)? else {
        return Ok(Gravity::NONE);
    };
    let tilt = (gz / (gx * gx + gy * gy + gz * gz).sqrt()).abs().asin();
    if tilt > params.planar_tolerance {
        return Err(TargetError::GravityOutOfPlane {
            tilt,
            gz,
            tol: params.planar_tolerance,
        });
    }
    Gravity::new(w, [gx, gy]).map_err(|e| out_of_domain(w, e))
}

/// The 3-D rod's weight (`weight_of`): w along gravity's direction in the base frame, which
/// may leave the rod's plane. Refused when w exceeds the solver's domain.
pub fn gravity_3d_of(params: &Params) -> Result<Gravity3, TargetError> {
    match weight_of(params)? {
        None => Ok(Gravity3::NONE),
        Some((w, g)) => Gravity3::new(w, g).map_err(|e| out_of_domain(w, e)),
    }
}

/// A position in metres as normalised coordinates (divided by the rod length).
pub fn to_normalised(p: &Point, rod_length: f64) -> [f64; 3] {
    [p.x / rod_length, p.y / rod_length, p.z / rod_length]
}

/// Normalised coordinates as a position in metres (multiplied by the rod length).
pub fn to_metres(v: [f64; 3], rod_length: f64) -> Point {
    Point {
        x: v[0] * rod_length,
        y: v[1] * rod_length,
        z: v[2] * rod_length,
    }
}

/// The quaternion of a rotation by `theta` about z.
pub fn yaw_to_quaternion(theta: f64) -> Quaternion {
    let h = 0.5 * theta;
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: h.sin(),
        w: h.cos(),
    }
}

/// Decomposes a quaternion (any non-zero norm) into (yaw about z, tilt): tilt is the angle
/// between the rotated z axis and z, 0 for a pure rotation about z; yaw is then the angle of
/// the rotated x axis in the x-y plane, in (−π, π].
pub fn quaternion_to_yaw(q: &Quaternion) -> Result<(f64, f64), TargetError> {
    let n = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
    if n.is_nan() || n <= 1e-9 {
        return Err(TargetError::ZeroQuaternion(n));
    }
    let (x, y, z, w) = (q.x / n, q.y / n, q.z / n, q.w / n);
    // R[2][2] = 1 − 2(x² + y²) = cos(tilt).
    let s = (x * x + y * y).sqrt().min(1.0);
    let tilt = 2.0 * s.asin();
    // Rotated x axis: (1 − 2(y² + z²), 2(xy + wz)).
    let yaw = (2.0 * (x * y + w * z)).atan2(1.0 - 2.0 * (y * y + z * z));
    Ok((yaw, tilt))
}

/// Checks a target pose (tip gripper in the base gripper's frame, metres) and returns it in
/// the solver's normalised units: (x / L, y / L, yaw).
pub fn target_to_planar(pose: &Pose, params: &Params) -> Result<PlanarPose, TargetError> {
    check_finite(pose)?;
    let p = &pose.position;
    let q = &pose.orientation;
    let tol = params.planar_tolerance;
    if p.z.abs() > tol {
        return Err(TargetError::OffPlane { z: p.z, tol });
    }
    let (yaw, tilt) = quaternion_to_yaw(q)?;
    if tilt > tol {
        return Err(TargetError::Tilted { tilt, tol });
    }
    let l = params.rod_length;
    let distance = p.x.hypot(p.y);
    // At exactly L only the straight rod fits, and it is not a stable equilibrium.
    if distance >= l {
        return Err(TargetError::OutOfReach {
            distance,
            length: l,
        });
    }
    let [x, y, _] = to_normalised(p, l);
    Ok(PlanarPose::new(x, y, yaw))
}

/// Checks a target pose for the 3-D solver and returns it normalised: position / L and the
/// orientation (any non-zero quaternion norm; normalised). Rejects non-finite values, a zero
/// quaternion and targets at least L from the base.
pub fn target_to_spatial(pose: &Pose, params: &Params) -> Result<SpatialPose, TargetError> {
    check_finite(pose)?;
    let p = &pose.position;
    let q = &pose.orientation;
    let n = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
    if n.is_nan() || n <= 1e-9 {
        return Err(TargetError::ZeroQuaternion(n));
    }
    let l = params.rod_length;
    let distance = (p.x * p.x + p.y * p.y + p.z * p.z).sqrt();
    if distance >= l {
        return Err(TargetError::OutOfReach {
            distance,
            length: l,
        });
    }
    SpatialPose::from_xyzw(to_normalised(p, l).into(), [q.x, q.y, q.z, q.w])
        .map_err(|_| TargetError::ZeroQuaternion(n))
}

fn check_finite(pose: &Pose) -> Result<(), TargetError> {
    let p = &pose.position;
    let q = &pose.orientation;
    for (name, v) in [
        ("position.x", p.x),
        ("position.y", p.y),
        ("position.z", p.z),
    ] {
        if !v.is_finite() {
            return Err(TargetError::NonFinite(name));
        }
    }
    for (name, v) in [
        ("orientation.x", q.x),
        ("orientation.y", q.y),
        ("orientation.z", q.z),
        ("orientation.w", q.w),
    ] {
        if !v.is_finite() {
            return Err(TargetError::NonFinite(name));
        }
    }
    Ok(())
}

/// The frame of published messages: the target's frame_id, or `base_frame` when empty.
pub fn output_header(target: &Header, params: &Params) -> Header {
    Header {
        stamp: target.stamp,
        frame_id: if target.frame_id.is_empty() {
            params.base_frame.clone()
        } else {
            target.frame_id.clone()
        },
    }
}

/// A normalised planar pose as a ROS pose in metres.
pub fn planar_to_pose(q: &PlanarPose, rod_length: f64) -> Pose {
    Pose {
        position: to_metres([q.x, q.y, 0.0], rod_length),
        orientation: yaw_to_quaternion(q.theta),
    }
}

/// A normalised 3-D pose as a ROS pose in metres (quaternion with w ≥ 0).
pub fn spatial_to_pose(q: &SpatialPose, rod_length: f64) -> Pose {
    let [x, y, z, w] = q.quaternion_xyzw();
    Pose {
        position: to_metres([q.position.x, q.position.y, q.position.z], rod_length),
        orientation: Quaternion { x, y, z, w },
    }
}

/// A sample of the rod's shape (planar or 3-D, normalised) that can be drawn in metres.
pub trait ShapeSample {
    /// The sample as a ROS pose in metres (orientation: body x = tangent).
    fn to_pose(&self, rod_length: f64) -> Pose;
}

impl ShapeSample for PlanarPose {
    fn to_pose(&self, rod_length: f64) -> Pose {
        planar_to_pose(self, rod_length)
    }
}

impl ShapeSample for SpatialPose {
    fn to_pose(&self, rod_length: f64) -> Pose {
        spatial_to_pose(self, rod_length)
    }
}

/// The rod's shape as a `nav_msgs/Path`: one pose per sample, orientation = tangent.
pub fn shape_to_path<S: ShapeSample>(shape: &[S], header: &Header, rod_length: f64) -> Path {
    Path {
        header: header.clone(),
        poses: shape
            .iter()
            .map(|q| PoseStamped {
                header: header.clone(),
                pose: q.to_pose(rod_length),
            })
            .collect(),
    }
}

/// The rod's shape as an RViz line strip (green when stable, orange when not).
pub fn shape_to_marker<S: ShapeSample>(
    shape: &[S],
    header: &Header,
    params: &Params,
    stable: bool,
) -> Marker {
    let l = params.rod_length;
    Marker {
        header: header.clone(),
        ns: "rod".into(),
        id: 0,
        marker_type: Marker::LINE_STRIP,
        action: Marker::ADD,
        pose: Pose::default(),
        scale: Vector3 {
            x: params.marker_width,
            y: 0.0,
            z: 0.0,
        },
        color: if stable {
            ColorRgba {
                r: 0.1,
                g: 0.8,
                b: 0.2,
                a: 1.0,
            }
        } else {
            ColorRgba {
                r: 1.0,
                g: 0.5,
                b: 0.0,
                a: 1.0,
            }
        },
        points: shape.iter().map(|q| q.to_pose(l).position).collect(),
        ..Marker::default()
    }
}

/// Several rods as one RViz LINE_LIST (`rod/plan_rods`): consecutive samples of each rod as
/// segments, in metres.
pub fn rods_to_marker(shapes: &[Vec<PlanarPose>], header: &Header, params: &Params) -> Marker {
    let l = params.rod_length;
    let points = shapes
        .iter()
        .flat_map(|shape| {
            shape
                .windows(2)
                .flat_map(|w| [w[0].to_pose(l).position, w[1].to_pose(l).position])
        })
        .collect();
    Marker {
        header: header.clone(),
        ns: "plan".into(),
        id: 0,
        marker_type: Marker::LINE_LIST,
        action: Marker::ADD,
        pose: Pose::default(),
        scale: Vector3 {
            x: 0.5 * params.marker_width,
            y: 0.0,
            z: 0.0,
        },
        color: ColorRgba {
            r: 0.2,
            g: 0.4,
            b: 1.0,
            a: 0.8,
        },
        points,
        ..Marker::default()
    }
}

/// Base wrench in physical units: force = (a4, a5)·EI/L², torque z = a3·EI/L.
pub fn base_wrench(a: &[f64; 3], rod_length: f64, bending_stiffness: f64) -> Wrench {
    let ei = bending_stiffness;
    let l = rod_length;
    Wrench {
        force: Vector3 {
            x: a[1] * ei / (l * l),
            y: a[2] * ei / (l * l),
            z: 0.0,
        },
        torque: Vector3 {
            x: 0.0,
            y: 0.0,
            z: a[0] * ei / l,
        },
    }
}

/// Base wrench of a 3-D solution in physical units, base frame:
/// force = (a4, a5, a6)·EI/L², torque = (a1, a2, a3)·EI/L.
pub fn base_wrench_3d(a: &SpatialParams, rod_length: f64, bending_stiffness: f64) -> Wrench {
    let ei = bending_stiffness;
    let l = rod_length;
    Wrench {
        force: Vector3 {
            x: a[3] * ei / (l * l),
            y: a[4] * ei / (l * l),
            z: a[5] * ei / (l * l),
        },
        torque: Vector3 {
            x: a[0] * ei / l,
            y: a[1] * ei / l,
            z: a[2] * ei / l,
        },
    }
}

/// A normalised wrench (force xyz, moment xyz) in physical units: force ×EI/L², moment ×EI/L.
pub fn scaled_wrench(w: &[f64; 6], rod_length: f64, bending_stiffness: f64) -> Wrench {
    let (f, m) = (
        bending_stiffness / (rod_length * rod_length),
        bending_stiffness / rod_length,
    );
    Wrench {
        force: Vector3 {
            x: w[0] * f,
            y: w[1] * f,
            z: w[2] * f,
        },
        torque: Vector3 {
            x: w[3] * m,
            y: w[4] * m,
            z: w[5] * m,
        },
    }
}

/// The model-dependent parts of a converged RodSolution (the rest comes from the solver's
/// one `Solution` type, whichever model produced it).
struct ModelParts {
    what: &'static str,
    /// (a3, a4, a5).
    a: [f64; 3],
    /// (a1..a6) for the 3-D solver, zeros for the planar one.
    a_spatial: [f64; 6],
    spatial: bool,
    /// The base wrench in SI units for EI = `bending_stiffness`.
    wrench: Wrench,
    /// The tip wrench in SI units, tip frame.
    tip_wrench: Wrench,
    /// The reached tip, metres.
    tip: Pose,
    /// Branch event ("" when not followed) and the critical gripper pose after a snap (m).
    event: &'static str,
    critical: Option<Pose>,
    /// The dimensionless weight and the elastic part of the solution's energy.
    weight: f64,
    elastic_energy: f64,
    /// θ(0): 0 unless the base is pinned.
    base_angle: f64,
    /// Full turns of the planar tangent along the shape (0 in 3-D).
    turns: u32,
}

/// Scales a converged answer to physical units (rod length L, bending stiffness EI).
fn converged_message<P, X>(
    s: &Solution<P, X>,
    c: ModelParts,
    header: &Header,
    params: &Params,
    solve_time: f64,
) -> RodSolution {
    let l = params.rod_length;
    let ei = params.bending_stiffness;
    let wrench_valid = ei > 0.0;
    RodSolution {
        header: header.clone(),
        success: true,
        message: format!(
            "{} in {} iterations, {}",
            c.what,
            s.iterations,
            if s.stable { "stable" } else { "UNSTABLE" }
        ),
        a: c.a,
        stable: s.stable,
        stability_margin: s.stability_margin,
        iterations: s.iterations,
        position_error: s.position_error * l,
        orientation_error: s.orientation_error,
        residual: s.residual,
        elastic_energy: c.elastic_energy,
        elastic_energy_joules: if wrench_valid {
            c.elastic_energy * ei / l
        } else {
            f64::NAN
        },
        wrench_valid,
        base_wrench: if wrench_valid {
            c.wrench
        } else {
            Wrench::default()
        },
        tip: c.tip,
        rod_length: l,
        solve_time,
        spatial: c.spatial,
        a_spatial: c.a_spatial,
        event: c.event.to_string(),
        critical_pose: c.critical.unwrap_or_else(nan_pose),
        weight: c.weight,
        total_energy: s.energy,
        tip_wrench: if wrench_valid {
            c.tip_wrench
        } else {
            Wrench::default()
        },
        base_condition: params.base_condition.name().into(),
        tip_condition: params.tip_condition.name().into(),
        base_angle: c.base_angle,
        turns: c.turns,
    }
}

/// The pose of "no pose": every component NaN (RodSolution.critical_pose without a snap).
fn nan_pose() -> Pose {
    let nan = f64::NAN;
    Pose {
        position: Point {
            x: nan,
            y: nan,
            z: nan,
        },
        orientation: Quaternion {
            x: nan,
            y: nan,
            z: nan,
            w: nan,
        },
    }
}

/// The RodSolution of a converged 3-D solve: `spatial` = true, `a_spatial` = (a1..a6),
/// `a` = its planar components (a3, a4, a5), `tip` the reached 3-D pose, `weight` and the
/// energies as the planar rod's.
pub fn solution_message_3d(
    s: &Solved3d,
    header: &Header,
    params: &Params,
    solve_time: f64,
) -> RodSolution {
    let (weight, elastic_energy, tip_wrench) = (s.weight, s.elastic_energy, s.tip_wrench);
    let s = &s.solution;
    let (l, ei) = (params.rod_length, params.bending_stiffness);
    let a_spatial: [f64; 6] = std::array::from_fn(|i| s.a[i]);
    let parts = ModelParts {
        what: "3-D solver converged",
        a: [a_spatial[2], a_spatial[3], a_spatial[4]],
        a_spatial,
        spatial: true,
        wrench: base_wrench_3d(&s.a, l, ei),
        tip_wrench: scaled_wrench(&tip_wrench, l, ei),
        tip: spatial_to_pose(&s.tip, l),
        event: "",
        critical: None,
        weight,
        elastic_energy,
        base_angle: 0.0,
        turns: 0,
    };
    converged_message(s, parts, header, params, solve_time)
}

/// The RodSolution of a converged (planar) solve.
pub fn solution_message(
    solved: &Solved,
    header: &Header,
    params: &Params,
    solve_time: f64,
) -> RodSolution {
    let s = &solved.solution;
    let (l, ei) = (params.rod_length, params.bending_stiffness);
    let a = [s.a[0], s.a[1], s.a[2]];
    let parts = ModelParts {
        what: if ends_of(params).is_ok_and(|e| !e.both_clamped()) {
            "held-ends search converged"
        } else {
            "converged"
        },
        a,
        a_spatial: [0.0; 6],
        spatial: false,
        wrench: base_wrench(&a, l, ei),
        tip_wrench: scaled_wrench(&solved.tip_wrench, l, ei),
        tip: planar_to_pose(&s.tip, l),
        event: solved.event,
        critical: solved.critical.map(|c| planar_to_pose(&c, l)),
        weight: solved.weight,
        elastic_energy: solved.elastic_energy,
        base_angle: solved.base_angle,
        turns: rod_ig_core::planar::heavy::cable::turns_of(&solved.shape),
    };
    converged_message(s, parts, header, params, solve_time)
}

/// The RodSolution of a rejected target or a failed solve (success = false). `spatial` is
/// true when the 3-D solver failed; `a_spatial` is then its last iterate (NaN without one),
/// zeros otherwise.
pub fn failure_message(
    message: String,
    failed: Option<&Failed>,
    header: &Header,
    params: &Params,
    solve_time: f64,
) -> RodSolution {
    let nan = f64::NAN;
    let a = failed
        .and_then(|f| f.last_a)
        .map(|a| [a[0], a[1], a[2]])
        .unwrap_or([nan; 3]);
    let spatial = failed.is_some_and(|f| f.spatial);
    let a_spatial = match failed.and_then(|f| f.last_a_spatial.as_deref()) {
        Some(a) => std::array::from_fn(|i| a[i]),
        None if spatial => [nan; 6],
        None => [0.0; 6],
    };
    RodSolution {
        header: header.clone(),
        success: false,
        message,
        a,
        stable: false,
        stability_margin: nan,
        iterations: failed.map_or(0, |f| f.iterations),
        position_error: nan,
        orientation_error: nan,
        residual: failed.map_or(nan, |f| f.residual),
        elastic_energy: nan,
        elastic_energy_joules: nan,
        wrench_valid: false,
        base_wrench: Wrench::default(),
        tip: nan_pose(),
        rod_length: params.rod_length,
        solve_time,
        spatial,
        a_spatial,
        event: failed.map_or("", |f| f.event).to_string(),
        critical_pose: nan_pose(),
        weight: gravity_3d_of(params).map_or(f64::NAN, |g| g.weight()),
        total_energy: nan,
        tip_wrench: Wrench::default(),
        base_condition: params.base_condition.name().into(),
        tip_condition: params.tip_condition.name().into(),
        base_angle: nan,
        turns: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn pose(x: f64, y: f64, z: f64, q: Quaternion) -> Pose {
        Pose {
            position: Point { x, y, z },
            orientation: q,
        }
    }

    #[test]
    fn yaw_round_trip() {
        for &t in &[0.0, 0.3, -1.2, FRAC_PI_2, 3.0, -3.0, PI] {
            let (yaw, tilt) = quaternion_to_yaw(&yaw_to_quaternion(t)).unwrap();
            assert!(
                (yaw - t).abs() < 1e-12 || (yaw - t).abs() > 2.0 * PI - 1e-12,
                "{t} {yaw}"
            );
            assert!(tilt < 1e-12);
        }
        // Non-unit quaternion with the same rotation, and q vs −q.
        let q = Quaternion {
            x: 0.0,
            y: 0.0,
            z: -2.0 * (0.4f64).sin(),
            w: -2.0 * (0.4f64).cos(),
        };
        let (yaw, _) = quaternion_to_yaw(&q).unwrap();
        assert!((yaw - 0.8).abs() < 1e-12);
    }

    #[test]
    fn tilt_detected() {
        // 0.1 rad about x.
        let q = Quaternion {
            x: (0.05f64).sin(),
            y: 0.0,
            z: 0.0,
            w: (0.05f64).cos(),
        };
        let (_, tilt) = quaternion_to_yaw(&q).unwrap();
        assert!((tilt - 0.1).abs() < 1e-12);
        let p = Params::default();
        assert!(matches!(
            target_to_planar(&pose(0.5, 0.0, 0.0, q), &p),
            Err(TargetError::Tilted { .. })
        ));
    }

    #[test]
    fn scaling_by_rod_length() {
        let p = Params {
            rod_length: 2.0,
            ..Params::default()
        };
        let t = target_to_planar(&pose(1.0, -0.5, 0.0, yaw_to_quaternion(0.7)), &p).unwrap();
        assert!((t.x - 0.5).abs() < 1e-15 && (t.y + 0.25).abs() < 1e-15);
        assert!((t.theta - 0.7).abs() < 1e-12);
        let back = planar_to_pose(&t, p.rod_length);
        assert!((back.position.x - 1.0).abs() < 1e-15 && (back.position.y + 0.5).abs() < 1e-15);
    }

    #[test]
    fn bad_targets_rejected() {
        let p = Params {
            rod_length: 0.5,
            ..Params::default()
        };
        let id = Quaternion::default();
        let cases = [
            (pose(f64::NAN, 0.0, 0.0, id), "non-finite"),
            (pose(0.1, f64::INFINITY, 0.0, id), "non-finite"),
            (
                pose(0.1, 0.0, 0.0, Quaternion { w: f64::NAN, ..id }),
                "non-finite",
            ),
            (
                pose(
                    0.1,
                    0.0,
                    0.0,
                    Quaternion {
                        x: 0.0,
                        y: 0.0,
                        z: 0.0,
                        w: 0.0,
                    },
                ),
                "not a rotation",
            ),
            (pose(0.1, 0.0, 0.01, id), "not planar"),
            (pose(0.4, 0.4, 0.0, id), "out of reach"),
        ];
        for (pose, what) in cases {
            let e = target_to_planar(&pose, &p).unwrap_err();
            assert!(e.to_string().contains(what), "{e} vs {what}");
        }
        // Exactly at full length: only the straight rod, unstable: rejected too.
        assert!(target_to_planar(&pose(0.5, 0.0, 0.0, id), &p).is_err());
        assert!(target_to_planar(&pose(0.499, 0.0, 0.0, id), &p).is_ok());
        // Tiny z within tolerance: accepted.
        assert!(target_to_planar(&pose(0.3, 0.0, 1e-9, id), &p).is_ok());
    }

    #[test]
    fn header_frame_fallback() {
        let p = Params {
            base_frame: "base".into(),
            ..Params::default()
        };
        let h = Header {
            frame_id: String::new(),
            ..Header::default()
        };
        assert_eq!(output_header(&h, &p).frame_id, "base");
        let h = Header {
            frame_id: "left".into(),
            ..Header::default()
        };
        assert_eq!(output_header(&h, &p).frame_id, "left");
    }

    #[test]
    fn path_and_marker_are_scaled() {
        let shape = vec![
            PlanarPose::new(0.0, 0.0, 0.0),
            PlanarPose::new(0.5, 0.5, FRAC_PI_2),
        ];
        let h = Header {
            frame_id: "f".into(),
            ..Header::default()
        };
        let path = shape_to_path(&shape, &h, 2.0);
        assert_eq!(path.poses.len(), 2);
        assert_eq!(path.poses[1].pose.position.x, 1.0);
        assert!((path.poses[1].pose.orientation.z - (0.25 * PI).sin()).abs() < 1e-15);
        assert_eq!(path.poses[1].header.frame_id, "f");
        let p = Params {
            rod_length: 2.0,
            ..Params::default()
        };
        let m = shape_to_marker(&shape, &h, &p, true);
        assert_eq!(m.points[1].y, 1.0);
        assert_eq!(m.marker_type, Marker::LINE_STRIP);
    }

    #[test]
    fn physical_units() {
        // EI = 2 N m², L = 0.5 m: force × EI/L² = 8, torque × EI/L = 4, energy × 4.
        let w = base_wrench(&[1.0, 2.0, -3.0], 0.5, 2.0);
        assert_eq!((w.force.x, w.force.y, w.torque.z), (16.0, -24.0, 4.0));
        let s = Solved {
            solution: rod_ig_core::planar::ig::Solution {
                a: crate::solver::PlanarParams::new(1.0, 2.0, -3.0),
                tip: PlanarPose::new(0.5, 0.1, 0.2),
                stable: true,
                stability_margin: 0.3,
                iterations: 4,
                position_error: 1e-7,
                orientation_error: 1e-8,
                residual: 1e-9,
                energy: 1.5,
                evaluations: 5,
                starts: 1,
                elapsed_us: 3.0,
                complete: true,
            },
            shape: vec![],
            event: "none",
            critical: None,
            weight: 0.0,
            elastic_energy: 1.5,
            tip_wrench: [1.0, -2.0, 0.0, 0.0, 0.0, 0.5],
            base_angle: 0.0,
        };
        let p = Params {
            rod_length: 0.5,
            bending_stiffness: 2.0,
            ..Params::default()
        };
        let m = solution_message(&s, &Header::default(), &p, 1e-4);
        assert!(m.success && m.wrench_valid);
        assert_eq!(m.elastic_energy_joules, 6.0);
        assert_eq!(m.position_error, 5e-8);
        assert_eq!(m.tip.position.x, 0.25);
        assert_eq!(m.a, [1.0, 2.0, -3.0]);
        // The tip wrench scales as the base's: force × 8, moment × 4.
        let t = m.tip_wrench;
        assert_eq!((t.force.x, t.force.y, t.torque.z), (8.0, -16.0, 2.0));
        let p0 = Params {
            rod_length: 0.5,
            ..Params::default()
        };
        let m0 = solution_message(&s, &Header::default(), &p0, 1e-4);
        assert!(!m0.wrench_valid && m0.elastic_energy_joules.is_nan());
        assert_eq!(m0.base_wrench, Wrench::default());
        // `turns` counts the tangent's full turns along the shape: 0 → 4.5π is two.
        assert_eq!(m.turns, 0);
        let coiled = Solved {
            shape: (0..=90)
                .map(|i| PlanarPose::new(0.0, 0.0, i as f64 * 0.05 * PI))
                .collect(),
            ..s.clone()
        };
        assert_eq!(
            solution_message(&coiled, &Header::default(), &p, 1e-4).turns,
            2
        );
    }

    #[test]
    fn spatial_target_scaling_and_reach() {
        let p = Params {
            rod_length: 2.0,
            ..Params::default()
        };
        let q = Quaternion {
            x: 0.1,
            y: 0.2,
            z: 0.3,
            w: 0.9,
        };
        let t = target_to_spatial(&pose(1.0, 0.4, 0.6, q), &p).unwrap();
        assert!((t.position.x - 0.5).abs() < 1e-15 && (t.position.z - 0.3).abs() < 1e-15);
        let back = spatial_to_pose(&t, p.rod_length);
        assert!((back.position.z - 0.6).abs() < 1e-15);
        let n = (0.01f64 + 0.04 + 0.09 + 0.81).sqrt();
        assert!((back.orientation.y - 0.2 / n).abs() < 1e-12);
        assert!(matches!(
            target_to_spatial(&pose(1.2, 1.2, 1.2, q), &p),
            Err(TargetError::OutOfReach { .. })
        ));
        let zero = Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 0.0,
        };
        assert!(matches!(
            target_to_spatial(&pose(0.1, 0.0, 0.0, zero), &p),
            Err(TargetError::ZeroQuaternion(_))
        ));
        assert!(target_to_planar(&pose(1.0, 0.4, 0.6, q), &p)
            .unwrap_err()
            .is_non_planar());
        // 3-D wrench: force (a4, a5, a6)·EI/L², torque (a1, a2, a3)·EI/L.
        let a = SpatialParams::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);
        let w = base_wrench_3d(&a, 0.5, 2.0);
        assert_eq!((w.force.x, w.force.y, w.force.z), (32.0, 40.0, 48.0));
        assert_eq!((w.torque.x, w.torque.y, w.torque.z), (4.0, 8.0, 12.0));
    }

    #[test]
    fn failure_has_reason() {
        let m = failure_message(
            "why".into(),
            None,
            &Header::default(),
            &Params::default(),
            0.0,
        );
        assert!(!m.success);
        assert_eq!(m.message, "why");
        assert!(m.a[0].is_nan());
        assert!(!m.spatial && m.a_spatial == [0.0; 6]);
    }

    #[test]
    fn weight_from_the_parameters() {
        // A 30 cm cable of 20 g/m and EI = 3.5e-4 N m^2 under 9.81 m/s^2 along −y:
        // w = 0.02 * 9.81 * 0.027 / 3.5e-4 ≈ 15.1, gravity along −y.
        let p = Params {
            rod_length: 0.3,
            bending_stiffness: 3.5e-4,
            linear_density: 0.02,
            gravity: [0.0, -9.81, 0.0],
            ..Params::default()
        };
        let g = gravity_of(&p).unwrap();
        assert!((g.weight() - 0.02 * 9.81 * 0.027 / 3.5e-4).abs() < 1e-12);
        assert_eq!(g.direction(), [0.0, -1.0]);
        assert!(gravity_of(&Params::default()).unwrap().is_weightless());
        let refused = |p: Params, words: &str| {
            let e = gravity_of(&p).unwrap_err();
            assert!(e.to_string().contains(words), "{e}");
            assert_eq!(e.key(), "invalid_input");
        };
        refused(
            Params {
                bending_stiffness: 0.0,
                ..p.clone()
            },
            "bending_stiffness",
        );
        refused(
            Params {
                gravity: [0.0; 3],
                ..p.clone()
            },
            "gravity parameter",
        );
        refused(
            Params {
                gravity: [0.0, -9.0, 4.0],
                ..p.clone()
            },
            "rod's plane",
        );
        refused(
            Params {
                linear_density: 1e3,
                ..p.clone()
            },
            "weight",
        );
    }
}
