//! One target in, messages out: the node's per-request logic, free of DDS so it can be
//! tested directly. [`Processor`] owns the solver (and so the warm start); the node's
//! solver task owns the [`Processor`].

use std::time::Instant;

use rod_ig_core::spatial::heavy::Gravity3;

use crate::convert::{
    failure_message, output_header, shape_to_marker, shape_to_path, solution_message,
    solution_message_3d, target_to_planar, target_to_spatial, ShapeSample,
};
use crate::messages::{
    Header, Marker, Path, PlanRodRequest, PlanRodResponse, PoseStamped, RodSolution,
    SolveRodRequest,
};
use crate::params::{Method, Params};
use crate::solver::{spatial_of_planar, Failed, PlanarParams, RodSolver, SolverSettings};

/// What one target produces. `path` and `marker` are `None` when `solution.success` is false:
/// a failed solve has no shape worth drawing, and subscribers of /rod/path keep the last
/// valid shape (the choice documented in `ros/rod_ig/README.md`).
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Always present.
    pub solution: RodSolution,
    /// Why it failed, as a bounded key: the solver's termination, or for a target refused
    /// before any solve [`crate::convert::TargetError::key`]; "" on success.
    pub failure: &'static str,
    /// The shape, on success.
    pub path: Option<Path>,
    /// The RViz line strip, on success when `publish_marker` is set.
    pub marker: Option<Marker>,
}

/// Per-request options of the `/rod/solve` service.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Overrides {
    /// Start here instead of the warm start (and leave the warm start alone).
    pub initial_guess: Option<PlanarParams>,
    /// Tolerance instead of the parameter.
    pub tolerance: Option<f64>,
    /// Iteration limit instead of the parameter.
    pub max_iterations: Option<u32>,
    /// Method instead of the parameter.
    pub method: Option<Method>,
    /// Path poses instead of the parameter.
    pub path_samples: Option<usize>,
}

impl Overrides {
    /// Reads the optional fields of a service request (0 / "" = not given).
    pub fn from_request(req: &SolveRodRequest) -> Result<Self, String> {
        let mut o = Overrides::default();
        if req.use_initial_guess {
            let g = req.initial_guess;
            if !g.iter().all(|v| v.is_finite()) {
                return Err(format!("initial_guess must be finite, got {g:?}"));
            }
            o.initial_guess = Some(PlanarParams::new(g[0], g[1], g[2]));
        }
        if req.tolerance != 0.0 {
            use rod_ig_core::planar::ig::{MAX_TOLERANCE, MIN_TOLERANCE};
            if !(MIN_TOLERANCE..=MAX_TOLERANCE).contains(&req.tolerance) {
                return Err(format!(
                    "tolerance must be in [{MIN_TOLERANCE:e}, {MAX_TOLERANCE:e}], got {}",
                    req.tolerance
                ));
            }
            o.tolerance = Some(req.tolerance);
        }
        if req.max_iterations != 0 {
            let limit = rod_ig_core::planar::ig::MAX_ITERATIONS_LIMIT;
            if req.max_iterations > limit {
                return Err(format!(
                    "max_iterations must be in [1, {limit}] (per start), got {}",
                    req.max_iterations
                ));
            }
            o.max_iterations = Some(req.max_iterations);
        }
        if req.path_samples != 0 {
            if !(2..=100_000).contains(&req.path_samples) {
                return Err(format!(
                    "path_samples must be in [2, 100000], got {}",
                    req.path_samples
                ));
            }
            o.path_samples = Some(req.path_samples as usize);
        }
        if !req.method.trim().is_empty() {
            o.method = Some(Method::parse(&req.method).map_err(|e| e.to_string())?);
        }
        Ok(o)
    }

    fn is_empty(&self) -> bool {
        *self == Overrides::default()
    }
}

/// The outcome of a solve (planar or 3-D): `parts` gives the solution message, the shape and
/// the stability of a converged solve.
fn outcome<T, S: ShapeSample>(
    result: Result<T, Failed>,
    header: &Header,
    params: &Params,
    elapsed: f64,
    parts: impl FnOnce(T) -> (RodSolution, Vec<S>, bool),
) -> Outcome {
    match result {
        Ok(solved) => {
            let (solution, shape, stable) = parts(solved);
            let path = shape_to_path(&shape, header, params.rod_length);
            let marker = params
                .publish_marker
                .then(|| shape_to_marker(&shape, header, params, stable));
            Outcome {
                solution,
                failure: "",
                path: Some(path),
                marker,
            }
        }
        Err(failed) => Outcome {
            failure: failed.termination,
            solution: failure_message(
                format!("solver failed: {}", failed.reason),
                Some(&failed),
                header,
                params,
                elapsed,
            ),
            path: None,
            marker: None,
        },
    }
}

/// Solver settings from the parameters.
pub fn settings_of(params: &Params) -> SolverSettings {
    SolverSettings {
        method: params.method,
        tolerance: params.tolerance,
        max_iterations: params.max_iterations,
        deadline: std::time::Duration::from_secs_f64(params.deadline_ms / 1e3),
        follow_branch: params.follow_branch,
        // Unusable weight parameters refuse every target (`process`); the settings keep none.
        gravity: crate::convert::gravity_of(params).unwrap_or_default(),
        gravity_3d: crate::convert::gravity_3d_of(params).unwrap_or(Gravity3::NONE),
        // An unusable pair refuses every target (`process`); the settings keep both clamped.
        ends: crate::convert::ends_of(params).unwrap_or_default(),
    }
}

/// Turns targets into solutions, warm-starting each solve from the previous solution, and
/// plans stable gripper paths (`rod/plan`).
pub struct Processor {
    solver: RodSolver,
    /// The roadmap planner, reused across `rod/plan` calls.
    planner: rod_ig_core::plan::Planner,
}

/// Most rods drawn on `rod/plan_rods` (every k-th rod of a longer plan, and the last).
const PLAN_RODS_DRAWN: usize = 25;
/// Samples per rod drawn on `rod/plan_rods`.
const PLAN_ROD_SAMPLES: usize = 30;

/// A planned motion answered on `rod/plan`, and its rods drawn for RViz.
pub struct Planned {
    /// The service answer.
    pub response: PlanRodResponse,
    /// The planned rods as a LINE_LIST, on success.
    pub marker: Option<Marker>,
}

/// The settings of a request with solver overrides (a one-off solve that neither follows nor
/// moves the warm starts); None without any (the path's sample count is not one).
fn one_off_settings(overrides: &Overrides, settings: SolverSettings) -> Option<SolverSettings> {
    let solver_overrides = Overrides {
        path_samples: None,
        ..overrides.clone()
    };
    (!solver_overrides.is_empty()).then(|| SolverSettings {
        method: overrides.method.unwrap_or(settings.method),
        tolerance: overrides.tolerance.unwrap_or(settings.tolerance),
        max_iterations: overrides.max_iterations.unwrap_or(settings.max_iterations),
        follow_branch: false,
        ..settings
    })
}

impl Processor {
    /// A processor for the given parameters (no warm start yet).
    pub fn new(params: &Params) -> Self {
        Self {
            solver: RodSolver::new(settings_of(params)),
            planner: rod_ig_core::plan::Planner::new(),
        }
    }

    /// The planar rod held now (the start of a `use_current` plan).
    pub fn held_rod(&self) -> Option<PlanarParams> {
        self.solver.current_rod()
    }

    /// Solves for one target with the current `params` (and optional per-request overrides).
    pub fn process(
        &mut self,
        target: &PoseStamped,
        params: &Params,
        overrides: &Overrides,
    ) -> Outcome {
        let started = Instant::now();
        let header = output_header(&target.header, params);
        let settings = settings_of(params);
        if self.solver.settings() != settings {
            self.solver.set_settings(settings);
        }
        let samples = overrides.path_samples.unwrap_or(params.path_samples);
        let one_off = one_off_settings(overrides, settings);
        let rejected = |e: crate::convert::TargetError| Outcome {
            failure: e.key(),
            solution: failure_message(
                e.to_string(),
                None,
                &header,
                params,
                started.elapsed().as_secs_f64(),
            ),
            path: None,
            marker: None,
        };
        // Gravity out of the rod's plane makes every target the 3-D rod's, as a non-planar one.
        let planar = crate::convert::ends_of(params)
            .and_then(|_| crate::convert::gravity_3d_of(params))
            .and_then(|_| crate::convert::gravity_of(params))
            .and_then(|_| target_to_planar(&target.pose, params));
        match planar {
            Ok(planar) => {
                let result = self
                    .solver
                    .solve(&planar, overrides.initial_guess, one_off, samples);
                let elapsed = started.elapsed().as_secs_f64();
                outcome(result, &header, params, elapsed, |s| {
                    (
                        solution_message(&s, &header, params, elapsed),
                        s.shape,
                        s.solution.stable,
                    )
                })
            }
            // Non-planar (or under gravity out of the rod's plane) but otherwise valid: the
            // 3-D solver when enabled (the planar initial guess of a service request is
            // embedded as (0, 0, a3, a4, a5, 0)); with pinned or free ends, the 3-D rod held
            // by them.
            Err(e) if e.is_non_planar() && params.solve_3d => {
                let spatial = match target_to_spatial(&target.pose, params) {
                    Ok(t) => t,
                    Err(e) => return rejected(e),
                };
                let result = if settings.ends.both_clamped() {
                    let guess = overrides.initial_guess.as_ref().map(spatial_of_planar);
                    self.solver.solve_3d(&spatial, guess, one_off, samples)
                } else {
                    let s = one_off.unwrap_or(settings);
                    crate::solver::solve_3d_held(&s, &spatial, samples)
                };
                let elapsed = started.elapsed().as_secs_f64();
                outcome(result, &header, params, elapsed, |s| {
                    (
                        solution_message_3d(&s, &header, params, elapsed),
                        s.shape,
                        s.solution.stable,
                    )
                })
            }
            Err(e) if e.is_non_planar() && !settings.ends.both_clamped() => {
                rejected(crate::convert::planar_ends_only(e, params))
            }
            Err(e) => rejected(e),
        }
    }

    /// The answer to a target refused before any solve (its frame could not be resolved):
    /// the failure with its reason and key, no path, in `base_frame` as every output under
    /// `use_tf`.
    pub fn refused(
        target: &PoseStamped,
        params: &Params,
        e: crate::convert::TargetError,
    ) -> Outcome {
        let mut header = output_header(&target.header, params);
        if params.use_tf {
            header.frame_id.clone_from(&params.base_frame);
        }
        Outcome {
            failure: e.key(),
            solution: failure_message(e.to_string(), None, &header, params, 0.0),
            path: None,
            marker: None,
        }
    }

    /// As [`Processor::process`], without side effects: the held rod and the warm starts are
    /// as they were before the call (`rod/solve` without `move_rod`).
    pub fn query(
        &mut self,
        target: &PoseStamped,
        params: &Params,
        overrides: &Overrides,
    ) -> Outcome {
        let held = self.solver.clone();
        let outcome = self.process(target, params, overrides);
        self.solver = held;
        outcome
    }

    /// Plans a stable gripper path (`rod/plan`): metres and the base frame in, the core
    /// planner in normalised units, metres out.
    ///
    /// `held` is the rod the node holds now (the last target's solution), the start of a
    /// request with `use_current`; the planner runs on a thread of its own, so it is passed
    /// in rather than read from this processor's solver.
    pub fn plan(
        &mut self,
        request: &PlanRodRequest,
        params: &Params,
        held: Option<PlanarParams>,
    ) -> Planned {
        let header = output_header(&request.goal.header, params);
        // The planar rod's weight (gravity out of its plane is refused with the reason: the
        // planner is planar).
        let gravity = crate::convert::gravity_of(params).map_err(|e| e.to_string());
        let plan = gravity.and_then(|g| {
            let query = Self::plan_query(request, params, held, g)?;
            let plan = self.planner.plan(&query).map_err(|e| e.to_string())?;
            Ok((plan, g))
        });
        match plan {
            Ok((plan, g)) => planned(&plan, &g, header, params),
            Err(reason) => Planned {
                response: PlanRodResponse {
                    success: false,
                    reason,
                    gripper_path: Path {
                        header,
                        poses: Vec::new(),
                    },
                    rods: Vec::new(),
                    min_margin: f64::NAN,
                },
                marker: None,
            },
        }
    }

    /// The core planner's query for `request`: the start rod (given, or the one held now), the
    /// goal, the obstacles and the deadline, in normalised units.
    fn plan_query(
        request: &PlanRodRequest,
        params: &Params,
        held: Option<PlanarParams>,
        gravity: rod_ig_core::planar::heavy::Gravity,
    ) -> Result<rod_ig_core::plan::PlanRequest, String> {
        use rod_ig_core::plan::{Obstacle, PlanRequest, DEFAULT_PLAN_DEADLINE};
        let l = params.rod_length;
        let start = if request.use_current {
            held.ok_or(
                "no current rod: send a target on rod/target first, or give start".to_string(),
            )?
        } else {
            PlanarParams::from(request.start)
        };
        let goal =
            target_to_planar(&request.goal.pose, params).map_err(|e| format!("goal: {e}"))?;
        let n = request.disc_x.len();
        if request.disc_y.len() != n || request.disc_radius.len() != n {
            return Err("disc_x, disc_y and disc_radius must have the same length".into());
        }
        let mut obstacles: Vec<Obstacle> = (0..n)
            .map(|i| Obstacle::Disc {
                center: [request.disc_x[i] / l, request.disc_y[i] / l],
                radius: request.disc_radius[i] / l,
            })
            .collect();
        obstacles.extend(request.polygons.iter().map(|p| {
            Obstacle::Polygon {
                points: p
                    .points
                    .iter()
                    .map(|q| [f64::from(q.x) / l, f64::from(q.y) / l])
                    .collect(),
            }
        }));
        let max_ms = rod_ig_core::solver::MAX_DEADLINE.as_secs_f64() * 1e3;
        let deadline = match request.deadline_ms {
            0.0 => DEFAULT_PLAN_DEADLINE,
            ms if ms.is_finite() && ms > 0.0 && ms <= max_ms => {
                std::time::Duration::from_secs_f64(ms / 1e3)
            }
            ms => {
                return Err(format!(
                    "deadline_ms must be in (0, {max_ms}] (0 = {}), got {ms}",
                    DEFAULT_PLAN_DEADLINE.as_millis()
                ))
            }
        };
        Ok(PlanRequest {
            start,
            goal,
            obstacles,
            deadline,
            gravity,
        })
    }

    /// Forgets the warm start.
    pub fn reset(&mut self) {
        self.solver.reset();
    }
}

/// The answer to a successful plan: the gripper path in metres, the rods, and a marker with
/// at most [`PLAN_RODS_DRAWN`] of them.
fn planned(
    plan: &rod_ig_core::plan::Plan,
    gravity: &rod_ig_core::planar::heavy::Gravity,
    header: Header,
    params: &Params,
) -> Planned {
    let l = params.rod_length;
    let poses = plan
        .gripper
        .iter()
        .map(|q| crate::messages::PoseStamped {
            header: header.clone(),
            pose: crate::convert::planar_to_pose(q, l),
        })
        .collect();
    let stride = plan.rods.len().div_ceil(PLAN_RODS_DRAWN).max(1);
    let mut drawn: Vec<&PlanarParams> = plan.rods.iter().step_by(stride).collect();
    if let Some(last) = plan.rods.last() {
        drawn.push(last);
    }
    let shapes: Vec<Vec<rod_ig_core::PlanarPose>> = drawn
        .iter()
        .filter_map(|a| rod_ig_core::planar::heavy::shape(a, gravity, PLAN_ROD_SAMPLES).ok())
        .collect();
    Planned {
        marker: Some(crate::convert::rods_to_marker(&shapes, &header, params)),
        response: PlanRodResponse {
            success: true,
            reason: String::new(),
            gripper_path: Path { header, poses },
            rods: plan.rods.iter().flat_map(|a| [a[0], a[1], a[2]]).collect(),
            min_margin: plan.min_margin,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convert::yaw_to_quaternion;
    use crate::messages::{Header, Point, Pose, Quaternion, Time};

    /// A processor as the node builds one: the solver's tables first (the node builds them
    /// before it reads its first target, so that no target pays for them against its
    /// deadline; built here inside a 250 ms deadline, on a slow machine they were not ready).
    fn warm_processor(params: &Params) -> Processor {
        RodSolver::warm_up();
        Processor::new(params)
    }

    fn target(x: f64, y: f64, yaw: f64, frame: &str) -> PoseStamped {
        PoseStamped {
            header: Header {
                stamp: Time { sec: 5, nanosec: 6 },
                frame_id: frame.into(),
            },
            pose: Pose {
                position: Point { x, y, z: 0.0 },
                orientation: yaw_to_quaternion(yaw),
            },
        }
    }

    fn check_path_reaches(o: &Outcome, t: &PoseStamped, samples: usize, tol: f64) {
        let path = o.path.as_ref().expect("path");
        assert_eq!(path.poses.len(), samples);
        let first = &path.poses[0].pose;
        assert!(first.position.x.abs() < 1e-12 && first.position.y.abs() < 1e-12);
        assert!((first.orientation.w.abs() - 1.0).abs() < 1e-12);
        let last = &path.poses[samples - 1].pose;
        assert!(
            (last.position.x - t.pose.position.x).abs() < tol,
            "{last:?}"
        );
        assert!(
            (last.position.y - t.pose.position.y).abs() < tol,
            "{last:?}"
        );
        // Same rotation about z: |dot of quaternions| ≈ 1.
        let q = &t.pose.orientation;
        let dot = last.orientation.z * q.z + last.orientation.w * q.w;
        assert!((dot.abs() - 1.0).abs() < tol, "{last:?} vs {q:?}");
    }

    #[test]
    fn solves_and_scales() {
        let params = Params {
            rod_length: 2.0,
            path_samples: 33,
            ..Params::default()
        };
        let mut p = warm_processor(&params);
        let t = target(1.2, 0.6, 0.5, "left");
        let o = p.process(&t, &params, &Overrides::default());
        assert!(o.solution.success, "{}", o.solution.message);
        assert_eq!(o.solution.header.frame_id, "left");
        assert_eq!(o.solution.header.stamp, Time { sec: 5, nanosec: 6 });
        assert_eq!(o.solution.rod_length, 2.0);
        check_path_reaches(&o, &t, 33, 1e-5);
        let m = o.marker.expect("marker");
        assert_eq!(m.points.len(), 33);
        assert_eq!(m.header.frame_id, "left");
    }

    #[test]
    fn warm_started_sequence() {
        let params = Params::default();
        let mut p = warm_processor(&params);
        for i in 0..20 {
            let s = i as f64 / 20.0;
            let t = target(0.8 - 0.2 * s, 0.1 + 0.3 * s, 0.8 * s, "");
            let o = p.process(&t, &params, &Overrides::default());
            assert!(o.solution.success, "step {i}: {}", o.solution.message);
            assert_eq!(o.solution.header.frame_id, params.base_frame);
            check_path_reaches(&o, &t, params.path_samples, 1e-5);
        }
    }

    #[test]
    fn bad_targets_answered_without_path() {
        let params = Params::default();
        let mut p = warm_processor(&params);
        let mut nonfinite = target(0.5, 0.0, 0.0, "");
        nonfinite.pose.position.y = f64::NAN;
        let mut offplane = target(0.5, 0.0, 0.0, "");
        offplane.pose.position.z = 0.1;
        let mut tilted = target(0.5, 0.0, 0.0, "");
        tilted.pose.orientation = Quaternion {
            x: 0.2,
            y: 0.0,
            z: 0.0,
            w: 0.98,
        };
        let far = target(1.5, 0.0, 0.0, "");
        for (t, what) in [
            (nonfinite, "non-finite"),
            (offplane, "not planar"),
            (tilted, "not about z"),
            (far, "out of reach"),
        ] {
            let o = p.process(&t, &params, &Overrides::default());
            assert!(!o.solution.success);
            assert!(
                o.solution.message.contains(what),
                "{} vs {what}",
                o.solution.message
            );
            assert!(o.path.is_none() && o.marker.is_none());
        }
        // Still works afterwards.
        let t = target(0.5, 0.2, 0.3, "");
        assert!(
            p.process(&t, &params, &Overrides::default())
                .solution
                .success
        );
    }

    /// z = 0.2 m and a rotation of 0.3 rad about (1, 1, 0)/√2 composed with yaw 0.4: not
    /// planar.
    fn tilted_target() -> PoseStamped {
        let mut t = target(0.6, 0.2, 0.0, "left");
        t.pose.position.z = 0.2;
        // q = q_yaw(0.4) ⊗ q_tilt(0.3 about (1, 1, 0)/√2).
        let (s, c) = (0.15f64.sin() / 2f64.sqrt(), 0.15f64.cos());
        let (sz, cz) = (0.2f64.sin(), 0.2f64.cos());
        t.pose.orientation = Quaternion {
            x: cz * s - sz * s,
            y: cz * s + sz * s,
            z: sz * c,
            w: cz * c,
        };
        t
    }

    #[test]
    fn non_planar_target_solved_in_3d_when_enabled() {
        let off = Params::default();
        let mut p = warm_processor(&off);
        let t = tilted_target();
        let o = p.process(&t, &off, &Overrides::default());
        assert!(!o.solution.success && o.path.is_none());
        assert!(
            o.solution.message.contains("not planar"),
            "{}",
            o.solution.message
        );
        assert!(!o.solution.spatial);

        let on = Params {
            solve_3d: true,
            rod_length: 1.0,
            bending_stiffness: 2.0,
            path_samples: 41,
            ..Params::default()
        };
        let o = p.process(&t, &on, &Overrides::default());
        let sol = &o.solution;
        assert!(sol.success, "{}", sol.message);
        assert!(sol.spatial && sol.stable && sol.stability_margin > 0.0);
        assert!(sol.position_error < 1e-5 && sol.orientation_error < 1e-5);
        let tip = &sol.tip;
        let dp = ((tip.position.x - 0.6).powi(2)
            + (tip.position.y - 0.2).powi(2)
            + (tip.position.z - 0.2).powi(2))
        .sqrt();
        assert!(dp < 1e-5, "{tip:?}");
        let q = &t.pose.orientation;
        let o_ = &tip.orientation;
        let dot = q.x * o_.x + q.y * o_.y + q.z * o_.z + q.w * o_.w;
        assert!((dot.abs() - 1.0).abs() < 1e-9, "{tip:?} vs {q:?}");
        assert_eq!(
            sol.a,
            [sol.a_spatial[2], sol.a_spatial[3], sol.a_spatial[4]]
        );
        assert!(sol.a_spatial.iter().any(|v| *v != 0.0));
        // Wrench: force (a4, a5, a6)·EI/L², torque (a1, a2, a3)·EI/L (EI = 2, L = 1).
        assert!(sol.wrench_valid);
        assert_eq!(sol.base_wrench.force.z, 2.0 * sol.a_spatial[5]);
        assert_eq!(sol.base_wrench.torque.x, 2.0 * sol.a_spatial[0]);
        // The 3-D path: base at the origin, tip at the target.
        let path = o.path.as_ref().expect("path");
        assert_eq!(path.poses.len(), 41);
        let first = &path.poses[0].pose;
        assert!(first.position.x.abs() < 1e-12 && first.position.z.abs() < 1e-12);
        assert!((first.orientation.w.abs() - 1.0).abs() < 1e-12);
        let last = &path.poses[40].pose;
        assert!((last.position.z - 0.2).abs() < 1e-5, "{last:?}");
        assert!((last.position.x - 0.6).abs() < 1e-5, "{last:?}");
        let m = o.marker.expect("marker");
        assert!((m.points[40].z - 0.2).abs() < 1e-5);

        // Warm start: a nearby target converges in few iterations.
        let mut t2 = t.clone();
        t2.pose.position.z = 0.21;
        let o2 = p.process(&t2, &on, &Overrides::default());
        assert!(
            o2.solution.success && o2.solution.spatial,
            "{}",
            o2.solution.message
        );
        assert!(o2.solution.iterations <= 10, "{}", o2.solution.iterations);

        // Planar targets still use the planar solver.
        let o3 = p.process(&target(0.6, 0.3, 0.5, ""), &on, &Overrides::default());
        assert!(o3.solution.success && !o3.solution.spatial);
        assert_eq!(o3.solution.a_spatial, [0.0; 6]);

        // Out of reach in 3-D: rejected.
        let mut far = t.clone();
        far.pose.position.z = 0.9;
        let o4 = p.process(&far, &on, &Overrides::default());
        assert!(!o4.solution.success && o4.solution.message.contains("out of reach"));
    }

    #[test]
    fn no_marker_when_disabled() {
        let params = Params {
            publish_marker: false,
            ..Params::default()
        };
        let mut p = warm_processor(&params);
        let o = p.process(&target(0.6, 0.2, 0.1, ""), &params, &Overrides::default());
        assert!(o.path.is_some() && o.marker.is_none());
    }

    #[test]
    fn service_overrides() {
        let mut req = SolveRodRequest::default();
        assert_eq!(Overrides::from_request(&req).unwrap(), Overrides::default());
        req.method = "newton".into();
        req.tolerance = 1e-9;
        req.max_iterations = 20;
        req.use_initial_guess = true;
        req.initial_guess = [0.1, 0.2, 0.3];
        let o = Overrides::from_request(&req).unwrap();
        assert_eq!(o.method, Some(Method::Newton));
        assert_eq!(o.tolerance, Some(1e-9));
        assert_eq!(o.max_iterations, Some(20));
        assert_eq!(o.initial_guess, Some(PlanarParams::new(0.1, 0.2, 0.3)));
        req.path_samples = 1;
        assert!(Overrides::from_request(&req).is_err());
        req.path_samples = 8;
        assert_eq!(Overrides::from_request(&req).unwrap().path_samples, Some(8));
        req.method = "bogus".into();
        assert!(Overrides::from_request(&req).is_err());
        req.method.clear();
        req.initial_guess = [f64::NAN, 0.0, 0.0];
        assert!(Overrides::from_request(&req).is_err());
        req.use_initial_guess = false;
        req.tolerance = -1.0;
        assert!(Overrides::from_request(&req).is_err());
    }

    /// Malformed input (issue 9, "malformed messages"): every truncation of the rclpy
    /// fixtures, and 2,000 deterministic mutations of each (byte flips, and string or sequence
    /// length prefixes set to huge values), decode to an error or to a value without a panic,
    /// and whatever decodes is answered by the node's pipeline without a panic, within its
    /// deadline. RustDDS hands the node exactly these bytes (after the 4-byte header).
    #[test]
    fn malformed_cdr_is_an_error_or_an_answer_never_a_panic() {
        use crate::messages::tests::fixture;
        use crate::messages::SolveRodRequest;
        use byteorder::LittleEndian;
        let params = Params {
            deadline_ms: 20.0,
            ..Params::default()
        };
        let mut processor = warm_processor(&params);
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut decoded = 0;
        for name in ["pose_stamped.hex", "solve_rod_request.hex"] {
            let good = fixture(name);
            let mut inputs: Vec<Vec<u8>> = (0..good.len()).map(|n| good[..n].to_vec()).collect();
            for _ in 0..2000 {
                let mut m = good.clone();
                let i = (next() as usize) % m.len();
                match next() % 3 {
                    0 => m[i] ^= 1 << (next() % 8),
                    1 => m[i] = next() as u8,
                    _ => {
                        // A 4-byte length prefix (aligned) set to something huge.
                        let j = (i / 4) * 4;
                        if j + 4 <= m.len() {
                            m[j..j + 4].copy_from_slice(
                                &(0xFFFF_FFF0u32 - (next() % 16) as u32).to_le_bytes(),
                            );
                        }
                    }
                }
                inputs.push(m);
            }
            for bytes in &inputs {
                let target = if name == "pose_stamped.hex" {
                    ros2_client::dds::rustdds::cdr_encoding::from_bytes::<PoseStamped, LittleEndian>(bytes)
                        .ok()
                        .map(|(t, _)| t)
                } else {
                    ros2_client::dds::rustdds::cdr_encoding::from_bytes::<
                        SolveRodRequest,
                        LittleEndian,
                    >(bytes)
                    .ok()
                    .map(|(r, _)| r.target)
                };
                if let Some(target) = target {
                    decoded += 1;
                    let started = std::time::Instant::now();
                    let outcome = processor.process(&target, &params, &Overrides::default());
                    // Deadline 20 ms; generous slack for the path and a loaded machine.
                    assert!(
                        started.elapsed().as_secs_f64() < 2.0,
                        "{name}: {:?}",
                        started.elapsed()
                    );
                    assert!(outcome.solution.success || !outcome.solution.message.is_empty());
                }
            }
        }
        // The mutations are not all rejected: the decoded ones exercised the pipeline.
        assert!(decoded > 100, "only {decoded} mutated messages decoded");
    }

    /// Gravity out of the rod's plane: refused without `solve_3d` (the reason names it), the
    /// 3-D rod's with it, sagging out of the plane with the weight reported.
    #[test]
    fn gravity_out_of_the_plane_is_served_by_the_3d_rod() {
        let cable = Params {
            rod_length: 0.3,
            bending_stiffness: 3.5e-4,
            linear_density: 0.02,
            gravity: [0.0, -6.0, 7.0],
            path_samples: 20,
            ..Params::default()
        };
        let w = 0.02 * (36.0f64 + 49.0).sqrt() * 0.027 / 3.5e-4;
        let t = target(0.18, 0.09, 0.5, "base_gripper");
        let refused = warm_processor(&cable).process(&t, &cable, &Overrides::default());
        assert!(!refused.solution.success);
        assert!(
            refused.solution.message.contains("solve_3d"),
            "{}",
            refused.solution.message
        );
        let params = Params {
            solve_3d: true,
            ..cable
        };
        let o = warm_processor(&params).process(&t, &params, &Overrides::default());
        let sol = &o.solution;
        assert!(sol.success && sol.spatial && sol.stable, "{}", sol.message);
        assert!((sol.weight - w).abs() <= 1e-12 * w);
        assert_ne!(sol.total_energy, sol.elastic_energy);
        check_path_reaches(&o, &t, 20, 1e-6);
        let path = o.path.as_ref().expect("path");
        let sag = path
            .poses
            .iter()
            .map(|p| p.pose.position.z.abs())
            .fold(0.0, f64::max);
        assert!(sag > 1e-3, "the rod stays in its plane: {sag}");
    }
}
