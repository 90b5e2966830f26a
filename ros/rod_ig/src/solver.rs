//! The one place where the node calls the math crate (`rod_ig_core`).
//!
//! Everything the node needs from the solver goes through [`RodSolver`]: warm-started
//! tracking of consecutive targets (`ig::Tracker`), one-off solves with per-request options
//! (`ig::solve`), and the sampled shape of the solution (`planar::PlanarRod`); for non-planar
//! targets (parameter `solve_3d`) the 3-D solver `spatial::ig::solve` (with weight, on the
//! model `spatial::HeavySpatial`), warm-started from the previous 3-D solution, and its shape. Units here are
//! the solver's normalised units (unit rod length, unit bending stiffness); scaling to metres
//! happens in [`crate::convert`].

use rod_ig_core::ends::{EndCondition, HeldEnds};
use rod_ig_core::planar::heavy::{self, held, Gravity, HeavyPlanar};
use rod_ig_core::planar::ig::{self, Failure, Solution, SolveOptions, Tracker};
use rod_ig_core::planar::PlanarClosedForm;
use rod_ig_core::planar::PlanarRod;
use rod_ig_core::solver::{self as rod_solver, BranchEvent, BranchFollower};
use rod_ig_core::spatial::heavy::{self as heavy3, Gravity3};
use rod_ig_core::spatial::ig::{Failure3d, Solution3d, SolveOptions3d};
use rod_ig_core::spatial::{self, Stiffness};
use rod_ig_core::spatial::{HeavySpatial, Spatial};
pub use rod_ig_core::spatial::{SpatialParams, SpatialPose};
pub use rod_ig_core::{PlanarParams, PlanarPose};

use crate::params::Method;

/// Solver settings the node exposes as parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// Robust or Newton.
    pub method: Method,
    /// Convergence tolerance (normalised position error and angle error).
    pub tolerance: f64,
    /// Iteration limit.
    pub max_iterations: u32,
    /// Wall-time budget of one solve.
    pub deadline: std::time::Duration,
    /// Warm-started planar targets move the gripper: the rod follows its branch (parameter
    /// `follow_branch`).
    pub follow_branch: bool,
    /// The rod's weight (parameters `linear_density`, `gravity`; none by default).
    pub gravity: Gravity,
    /// The same weight for the 3-D rod: gravity's direction in the base frame, which may
    /// leave the rod's plane.
    pub gravity_3d: Gravity3,
    /// How the two grippers hold the rod (parameters `base_condition`, `tip_condition`):
    /// both clamped by default; otherwise every planar target is answered by the held-ends
    /// search (`planar::heavy::held`).
    pub ends: HeldEnds,
}

/// A converged solve with its sampled shape, normalised units: the core crate's solution
/// as it is, plus `samples` poses from t = 0 to t = 1.
#[derive(Clone, Debug)]
pub struct WithShape<S, P> {
    /// The solver's answer.
    pub solution: S,
    /// The rod's shape, base to tip.
    pub shape: Vec<P>,
    /// Branch event of a followed move ("none", "snap"), "" when not followed.
    pub event: &'static str,
    /// After a snap: the gripper pose where the old branch ended (normalised).
    pub critical: Option<PlanarPose>,
    /// The dimensionless weight of the solve (0 without weight).
    pub weight: f64,
    /// The elastic part of the solution's energy (all of it without weight).
    pub elastic_energy: f64,
    /// The wrench the rod exerts on the tip gripper, normalised, in the tip frame: force
    /// (x, y, z) then moment (x, y, z) (`rod_ig_core::wrench`; NaN where it could not be
    /// evaluated).
    pub tip_wrench: [f64; 6],
    /// The rod's angle at the base θ(0): 0 unless the base is pinned.
    pub base_angle: f64,
}

/// The planar tip wrench as [`WithShape::tip_wrench`]: (fx, fy, 0, 0, 0, m).
fn planar_tip_wrench(a: &rod_ig_core::PlanarParams, g: &Gravity) -> [f64; 6] {
    heavy::wrenches(a, g).map_or([f64::NAN; 6], |w| {
        let t = w.tip;
        [t.force[0], t.force[1], 0.0, 0.0, 0.0, t.moment]
    })
}

/// A 3-D wrench as [`WithShape::tip_wrench`]: (fx, fy, fz, mx, my, mz).
fn spatial_row(w: &rod_ig_core::wrench::SpatialWrench) -> [f64; 6] {
    let (f, m) = (w.force, w.moment);
    [f[0], f[1], f[2], m[0], m[1], m[2]]
}

/// A converged planar solve and its shape.
pub type Solved = WithShape<Solution, PlanarPose>;
/// A converged 3-D solve and its shape.
pub type Solved3d = WithShape<Solution3d, SpatialPose>;

/// A failed solve.
#[derive(Clone, Debug)]
pub struct Failed {
    /// Why (the solver's own message).
    pub reason: String,
    /// The typed reason (`Termination::as_str`: "deadline", "no_stable_solution", ...): the
    /// bounded key the diagnostics count failures by.
    pub termination: &'static str,
    /// Iterations used.
    pub iterations: u32,
    /// Last residual.
    pub residual: f64,
    /// Last iterate, when there was one (for the 3-D solver: its planar components
    /// (a3, a4, a5)).
    pub last_a: Option<PlanarParams>,
    /// Last iterate of the 3-D solver (a1..a6), when it answered and had one.
    pub last_a_spatial: Option<Box<SpatialParams>>,
    /// The 3-D solver answered (parameter `solve_3d`, non-planar target).
    pub spatial: bool,
    /// "lost" when a followed move lost the rod, "" otherwise.
    pub event: &'static str,
}

impl From<Failure> for Failed {
    fn from(f: Failure) -> Self {
        Self {
            reason: f.reason.to_string(),
            termination: f.termination().as_str(),
            iterations: f.iterations,
            residual: f.residual,
            last_a: f.last_a,
            last_a_spatial: None,
            spatial: false,
            event: "",
        }
    }
}

impl From<Failure3d> for Failed {
    fn from(f: Failure3d) -> Self {
        Self {
            reason: f.reason.to_string(),
            termination: f.termination().as_str(),
            iterations: f.iterations,
            residual: f.residual,
            last_a: f.last_a.as_ref().map(planar_part),
            last_a_spatial: f.last_a.map(Box::new),
            spatial: true,
            event: "",
        }
    }
}

/// The planar components (a3, a4, a5) of 3-D parameters (the in-plane moment and force).
pub fn planar_part(a: &SpatialParams) -> PlanarParams {
    PlanarParams::new(a[2], a[3], a[4])
}

/// 3-D parameters of a planar rod: (0, 0, a3, a4, a5, 0).
pub fn spatial_of_planar(a: &PlanarParams) -> SpatialParams {
    SpatialParams::new(0.0, 0.0, a[0], a[1], a[2], 0.0)
}

fn options(s: &SolverSettings, initial_guess: Option<PlanarParams>) -> SolveOptions {
    SolveOptions {
        method: match s.method {
            Method::Robust => ig::Method::Robust,
            Method::Newton => ig::Method::Newton,
        },
        tolerance: s.tolerance,
        max_iterations: s.max_iterations,
        initial_guess,
        deadline: s.deadline,
        ..SolveOptions::default()
    }
}

fn options_3d(s: &SolverSettings, initial_guess: Option<SpatialParams>) -> SolveOptions3d {
    SolveOptions3d {
        method: match s.method {
            Method::Robust => rod_solver::Method::Robust,
            Method::Newton => rod_solver::Method::Newton,
        },
        tolerance: s.tolerance,
        max_iterations: s.max_iterations,
        initial_guess,
        deadline: s.deadline,
        ..SolveOptions3d::default()
    }
}

/// Inverse-geometry solver with warm start (planar and 3-D kept separately). Cloned to answer
/// a query without side effects.
#[derive(Clone)]
pub struct RodSolver {
    settings: SolverSettings,
    tracker: Tracker,
    /// The rod held by the grippers (planar targets with `follow_branch`).
    follower: BranchFollower<3, PlanarClosedForm>,
    /// The same for a rod with weight (when `settings.gravity` has some).
    heavy_follower: BranchFollower<3, HeavyPlanar>,
    /// Previous solution of the rod with weight: the warm start of the next target when not
    /// following the branch.
    last_heavy: Option<PlanarParams>,
    /// Previous 3-D solution: the warm start of the next 3-D target.
    last_3d: Option<SpatialParams>,
    /// Previous rod held by pinned or free ends: the next target moves it along its branch
    /// (`held::follow`) before any fresh search.
    last_held: Option<held::HeldSolution>,
}

impl RodSolver {
    /// A solver with no warm start yet.
    pub fn new(settings: SolverSettings) -> Self {
        Self {
            settings,
            tracker: Tracker::new(options(&settings, None)),
            follower: BranchFollower::new(PlanarClosedForm, options(&settings, None)),
            heavy_follower: BranchFollower::new(
                HeavyPlanar::new(settings.gravity),
                options(&settings, None),
            ),
            last_heavy: None,
            last_3d: None,
            last_held: None,
        }
    }

    /// Builds the solver's tables now rather than on the first target.
    pub fn warm_up() {
        let _ = ig::warm_up();
    }

    /// The planar rod held now: the branch follower's, else the last warm start.
    pub fn current_rod(&self) -> Option<PlanarParams> {
        if !self.settings.gravity.is_weightless() {
            return self.heavy_follower.rod().or(self.last_heavy);
        }
        self.follower.rod().or_else(|| self.tracker.last())
    }

    /// Current settings.
    pub fn settings(&self) -> SolverSettings {
        self.settings
    }

    /// Changes the settings, keeping the warm start.
    pub fn set_settings(&mut self, settings: SolverSettings) {
        let previous = self.settings.gravity;
        self.settings = settings;
        self.tracker = Tracker::new(options(&settings, self.tracker.last()));
        self.follower.set_options(options(&settings, None));
        if settings.gravity != previous {
            self.change_gravity(&previous);
        } else {
            self.heavy_follower.set_options(options(&settings, None));
        }
    }

    /// A change of weight or of gravity's direction moves the held rod like a gripper move:
    /// it is carried along its branch with the gripper fixed (`heavy::carry`); where that
    /// branch folds, the next target starts afresh.
    fn change_gravity(&mut self, previous: &Gravity) {
        let to = self.settings.gravity;
        let o = options(&self.settings, None);
        let held = if previous.is_weightless() {
            self.follower.rod().zip(self.follower.gripper())
        } else {
            self.heavy_follower.rod().zip(self.heavy_follower.gripper())
        };
        let carried =
            held.and_then(|(a, gripper)| heavy::carry(&a, previous, &to, &gripper, &o).ok());
        self.last_heavy = carried.map(|s| s.a);
        self.heavy_follower = match carried {
            Some(s) if !to.is_weightless() => BranchFollower::holding(HeavyPlanar::new(to), o, s.a)
                .unwrap_or_else(|_| BranchFollower::new(HeavyPlanar::new(to), o)),
            _ => BranchFollower::new(HeavyPlanar::new(to), o),
        };
        if to.is_weightless() {
            self.follower = match carried {
                Some(s) => BranchFollower::holding(PlanarClosedForm, o, s.a)
                    .unwrap_or_else(|_| BranchFollower::new(PlanarClosedForm, o)),
                None => BranchFollower::new(PlanarClosedForm, o),
            };
        }
    }

    /// Forgets the warm starts (planar and 3-D).
    pub fn reset(&mut self) {
        self.tracker.reset();
        self.follower = BranchFollower::new(PlanarClosedForm, options(&self.settings, None));
        self.heavy_follower = BranchFollower::new(
            HeavyPlanar::new(self.settings.gravity),
            options(&self.settings, None),
        );
        self.last_heavy = None;
        self.last_3d = None;
        self.last_held = None;
    }

    /// Solves the 3-D inverse geometry for `target` (normalised) with the 3-D solver and
    /// samples `samples` shape poses.
    ///
    /// Without `initial_guess` and `one_off` settings: warm-started from the previous 3-D
    /// solution, which this solution replaces. With either: a one-off solve that leaves the
    /// warm start untouched. The rod is isotropic (the core's default stiffnesses).
    pub fn solve_3d(
        &mut self,
        target: &SpatialPose,
        initial_guess: Option<SpatialParams>,
        one_off: Option<SolverSettings>,
        samples: usize,
    ) -> Result<Solved3d, Failed> {
        let one_off_solve = initial_guess.is_some() || one_off.is_some();
        let s = one_off.unwrap_or(self.settings);
        let guess = if one_off_solve {
            initial_guess
        } else {
            self.last_3d
        };
        let options = options_3d(&s, guess);
        let g = s.gravity_3d;
        let solution = if g.is_weightless() {
            rod_solver::solve(&Spatial::default(), target, &options)?
        } else {
            let model = HeavySpatial {
                stiffness: Stiffness::default(),
                gravity: g,
            };
            rod_solver::solve(&model, target, &options)?
        };
        if !one_off_solve {
            self.last_3d = Some(solution.a);
        }
        with_shape_3d(&solution, &g, samples)
    }

    /// Solves for `target` (normalised) and samples `samples` shape poses.
    ///
    /// Without `initial_guess` and `one_off` settings: warm-started from the previous solution
    /// (`ig::Tracker` for the robust method; the paper's Newton from the previous solution for
    /// `newton`), and this solution becomes the next warm start. With either: a one-off
    /// `ig::solve` that leaves the warm start untouched.
    pub fn solve(
        &mut self,
        target: &PlanarPose,
        initial_guess: Option<PlanarParams>,
        one_off: Option<SolverSettings>,
        samples: usize,
    ) -> Result<Solved, Failed> {
        if !self.settings.ends.both_clamped() {
            return match one_off {
                Some(s) => solve_held(&s, None, target, samples).map(|(solved, _)| solved),
                None => {
                    let previous = self.last_held.take();
                    let held = solve_held(&self.settings, previous.as_ref(), target, samples);
                    held.map(|(solved, rod)| {
                        self.last_held = Some(rod);
                        solved
                    })
                }
            };
        }
        if !self.settings.gravity.is_weightless() {
            return self.solve_heavy(target, initial_guess, one_off, samples);
        }
        let solution = if initial_guess.is_some() || one_off.is_some() {
            let s = one_off.unwrap_or(self.settings);
            ig::solve(target, &options(&s, initial_guess))?
        } else {
            match self.settings.method {
                Method::Robust if self.settings.follow_branch => {
                    let m = self.follower.follow(target);
                    return followed(m, |s| with_shape(s, samples));
                }
                Method::Robust => self.tracker.solve(target)?,
                Method::Newton => {
                    let s = ig::solve(target, &options(&self.settings, self.tracker.last()))?;
                    self.tracker = Tracker::new(options(&self.settings, Some(s.a)));
                    s
                }
            }
        };
        with_shape(&solution, samples)
    }
}

impl RodSolver {
    /// [`RodSolver::solve`] for the rod with weight: the same warm starts and branch
    /// following, on the model `HeavyPlanar`.
    fn solve_heavy(
        &mut self,
        target: &PlanarPose,
        initial_guess: Option<PlanarParams>,
        one_off: Option<SolverSettings>,
        samples: usize,
    ) -> Result<Solved, Failed> {
        let g = self.settings.gravity;
        let model = HeavyPlanar::new(g);
        // With weight the answer is the least-energy rod: the hanging cable a user sees.
        let heavy_options = |s: &SolverSettings, guess| SolveOptions {
            objective: ig::Objective::LeastEnergy,
            ..options(s, guess)
        };
        if initial_guess.is_some() || one_off.is_some() {
            let s = one_off.unwrap_or(self.settings);
            let solution = rod_solver::solve(&model, target, &heavy_options(&s, initial_guess))?;
            return with_heavy_shape(&solution, &g, samples);
        }
        if self.settings.method == Method::Robust && self.settings.follow_branch {
            let m = self.heavy_follower.follow(target);
            return followed(m, |s| with_heavy_shape(s, &g, samples));
        }
        let o = heavy_options(&self.settings, self.last_heavy);
        let solution = rod_solver::solve(&model, target, &o)?;
        self.last_heavy = Some(solution.a);
        with_heavy_shape(&solution, &g, samples)
    }
}

/// A planar target with pinned or free ends: the rod `previous` (held by the same ends) moved
/// along its branch to the target (`held::follow`, event "none" when following the branch),
/// else the least-energy stable rod of the held-ends search (a pinned tip holds the target's
/// position, a free tip ignores the target; event "snap" when a followed rod's branch ended),
/// as a solver `Solution` (iterations 0: a search, not one Newton run) with its shape, and the
/// rod itself (the next target's `previous`).
fn solve_held(
    s: &SolverSettings,
    previous: Option<&held::HeldSolution>,
    target: &PlanarPose,
    samples: usize,
) -> Result<(Solved, held::HeldSolution), Failed> {
    let options = SolveOptions {
        deadline: s.deadline.max(HELD_MIN_DEADLINE),
        ..SolveOptions::default()
    };
    let tip_target = (s.ends.tip() != EndCondition::Free).then_some(target);
    let previous = previous.filter(|p| p.cable.ends() == s.ends);
    if let Some(p) = previous {
        let started = std::time::Instant::now();
        let follow_options = SolveOptions {
            deadline: s.deadline,
            ..SolveOptions::default()
        };
        if let Ok(rod) = held::follow(p, &s.gravity, tip_target, &follow_options) {
            // One rod followed, not a search: `complete` is false.
            let found = held::HeldSearch {
                starts: 1,
                cut_short: true,
                ..Default::default()
            };
            let event = if s.follow_branch { "none" } else { "" };
            return held_solved(s, rod, &found, target, samples, started, event);
        }
    }
    let event = match (previous, s.follow_branch) {
        (Some(_), true) => "snap",
        _ => "",
    };
    solve_held_afresh(s, &options, tip_target, target, samples, event)
}

/// The held-ends search for `target` ([`solve_held`] without a rod to follow).
fn solve_held_afresh(
    s: &SolverSettings,
    options: &SolveOptions,
    tip_target: Option<&PlanarPose>,
    target: &PlanarPose,
    samples: usize,
    event: &'static str,
) -> Result<(Solved, held::HeldSolution), Failed> {
    let started = std::time::Instant::now();
    let (best, found) =
        held::least_energy(s.ends, &s.gravity, tip_target, options).map_err(|e| {
            let termination = match &e {
                held::HeldError::NotFound { cut, .. } if !cut.is_empty() => "deadline",
                held::HeldError::NotFound { .. } => "no_stable_solution",
                held::HeldError::Target { .. } => "invalid_input",
                // Only `held::follow` loses a rod; a search answers NotFound.
                held::HeldError::Lost { .. } => "no_stable_solution",
            };
            Failed {
                event: if event == "snap" { "lost" } else { "" },
                ..held_failure(e.to_string(), termination)
            }
        })?;
    held_solved(s, best, &found, target, samples, started, event)
}

/// The node's answer for the held rod `best` that a search (or a follow) `found`.
fn held_solved(
    s: &SolverSettings,
    best: held::HeldSolution,
    found: &held::HeldSearch,
    target: &PlanarPose,
    samples: usize,
    started: std::time::Instant,
    event: &'static str,
) -> Result<(Solved, held::HeldSolution), Failed> {
    let shape = best.cable.shape(samples).map_err(|e| {
        held_failure(
            format!("cannot evaluate the solution's shape: {e}"),
            "evaluation_failed",
        )
    })?;
    let position_error = match s.ends.tip() {
        EndCondition::Free => f64::NAN,
        _ => (best.tip.x - target.x).hypot(best.tip.y - target.y),
    };
    let orientation_error = match s.ends.tip() {
        EndCondition::Clamped => (best.tip.theta - target.theta).abs(),
        _ => f64::NAN,
    };
    let w = best.wrenches().tip;
    let solved = WithShape {
        solution: Solution {
            a: best.a,
            tip: best.tip,
            stable: true,
            stability_margin: best.stability.normalised(),
            iterations: 0,
            position_error,
            orientation_error,
            residual: if position_error.is_nan() {
                0.0
            } else {
                position_error
            },
            energy: best.energy,
            evaluations: 0,
            starts: found.starts,
            elapsed_us: started.elapsed().as_secs_f64() * 1e6,
            complete: !found.cut_short,
        },
        shape,
        event,
        critical: None,
        weight: s.gravity.weight(),
        elastic_energy: best.elastic_energy,
        tip_wrench: [w.force[0], w.force[1], 0.0, 0.0, 0.0, w.moment],
        base_angle: best.base_angle,
    };
    Ok((solved, best))
}

/// A non-planar target with pinned or free ends (`solve_3d`): the least-energy stable 3-D rod
/// held by the ends (`spatial::held`: a pinned tip holds the target's position, a free tip
/// ignores the target, a pinned base with a clamped tip holds its pose), a fresh search every
/// time, as a solver `Solution` with its shape. The rod is isotropic (the core's default
/// stiffnesses).
pub fn solve_3d_held(
    s: &SolverSettings,
    target: &SpatialPose,
    samples: usize,
) -> Result<Solved3d, Failed> {
    use rod_ig_core::spatial::held as held3;
    let started = std::time::Instant::now();
    let options = SolveOptions {
        deadline: s.deadline.max(HELD_MIN_DEADLINE),
        ..SolveOptions::default()
    };
    let (k, g) = (Stiffness::default(), s.gravity_3d);
    let found = match s.ends.tip() {
        EndCondition::Clamped => held3::equilibria_to_pose(&k, &g, target, &options),
        EndCondition::Pinned => held3::equilibria(s.ends, &k, &g, Some(&target.position), &options),
        EndCondition::Free => held3::equilibria(s.ends, &k, &g, None, &options),
    }
    .map_err(|e| Failed {
        spatial: true,
        ..held_failure(e.to_string(), "invalid_input")
    })?;
    let Some(best) = found.solutions.first() else {
        let termination = if found.cut_short {
            "deadline"
        } else {
            "no_stable_solution"
        };
        return Err(Failed {
            spatial: true,
            ..held_failure(found.not_found(s.ends).to_string(), termination)
        });
    };
    let shape_failure = |e: rod_ig_core::RodError| Failed {
        spatial: true,
        ..held_failure(
            format!("cannot evaluate the solution's shape: {e}"),
            "evaluation_failed",
        )
    };
    let ts: Vec<f64> = (0..samples)
        .map(|i| i as f64 / (samples.max(2) - 1) as f64)
        .collect();
    let shape = best.cable.poses_at(&ts).map_err(shape_failure)?;
    let mut solution = held_3d_solution(s.ends.tip(), best, target, found.starts);
    solution.elapsed_us = started.elapsed().as_secs_f64() * 1e6;
    solution.complete = !found.cut_short;
    let t = best.wrenches().map_err(shape_failure)?.tip;
    Ok(WithShape {
        solution,
        shape,
        event: "",
        critical: None,
        weight: g.weight(),
        elastic_energy: best.elastic_energy,
        tip_wrench: spatial_row(&t),
        base_angle: 0.0,
    })
}

/// The 3-D held rod `best` as a solver `Solution` (iterations 0: a search): its errors to
/// `target` as the tip's condition defines them (NaN where the tip is free to move).
fn held_3d_solution(
    tip: EndCondition,
    best: &rod_ig_core::spatial::held::SpatialHeldSolution,
    target: &SpatialPose,
    starts: u32,
) -> Solution3d {
    let (dp, dr) = best.tip.distance_to(target);
    let errors = match tip {
        EndCondition::Clamped => (dp, dr),
        EndCondition::Pinned => (dp, f64::NAN),
        EndCondition::Free => (f64::NAN, f64::NAN),
    };
    let mut solution = Solution3d::new(
        best.a,
        rod_ig_core::solver::Verified {
            tip: best.tip,
            errors,
            energy: best.energy,
            margin: best.stability.margin,
        },
        rod_ig_core::solver::Work {
            iterations: 0,
            evaluations: 0,
            starts,
        },
    );
    solution.residual = if errors.0.is_nan() { 0.0 } else { errors.0 };
    solution
}

/// A held-ends solve that failed, and why.
fn held_failure(reason: String, termination: &'static str) -> Failed {
    Failed {
        reason,
        termination,
        iterations: 0,
        residual: f64::NAN,
        last_a: None,
        last_a_spatial: None,
        spatial: false,
        event: "",
    }
}

/// Least time a held-ends solve gets (its search tries more starts than a clamped one).
const HELD_MIN_DEADLINE: std::time::Duration = std::time::Duration::from_millis(1000);

/// A followed move as the node answers it: the solution with its shape (`shape`), the branch
/// event and, after a snap, the critical gripper pose; or the failure with its event.
fn followed(
    m: rod_solver::Move<PlanarParams, PlanarPose>,
    shape: impl FnOnce(&Solution) -> Result<Solved, Failed>,
) -> Result<Solved, Failed> {
    let (event, critical) = match m.event {
        BranchEvent::Snap { critical, .. } => ("snap", Some(critical)),
        BranchEvent::Lost => ("lost", None),
        BranchEvent::None => ("none", None),
        BranchEvent::Buckle => ("buckle", None),
    };
    let s = m.result.map_err(|f| Failed {
        event,
        ..Failed::from(f)
    })?;
    let mut solved = shape(&s)?;
    solved.event = event;
    solved.critical = critical;
    Ok(solved)
}

fn shape_failure(s: &Solution, e: impl std::fmt::Display) -> Failed {
    Failed {
        reason: format!("cannot evaluate the solution's shape: {e}"),
        termination: rod_ig_core::solver::Termination::EvaluationFailed.as_str(),
        iterations: s.iterations,
        residual: s.residual,
        last_a: Some(s.a),
        last_a_spatial: None,
        spatial: false,
        event: "",
    }
}

fn with_heavy_shape(s: &Solution, g: &Gravity, samples: usize) -> Result<Solved, Failed> {
    let shape = heavy::shape(&s.a, g, samples).map_err(|e| shape_failure(s, e))?;
    let (_, elastic) = heavy::energy(&s.a, g).map_err(|e| shape_failure(s, e))?;
    Ok(WithShape {
        solution: *s,
        shape,
        event: "",
        critical: None,
        weight: g.weight(),
        elastic_energy: elastic,
        tip_wrench: planar_tip_wrench(&s.a, g),
        base_angle: 0.0,
    })
}

fn with_shape(s: &Solution, samples: usize) -> Result<Solved, Failed> {
    let rod = PlanarRod::new(&s.a).map_err(|e| shape_failure(s, e))?;
    Ok(WithShape {
        solution: *s,
        shape: rod.shape(samples),
        event: "",
        critical: None,
        weight: 0.0,
        elastic_energy: s.energy,
        tip_wrench: planar_tip_wrench(&s.a, &Gravity::NONE),
        base_angle: 0.0,
    })
}

fn with_shape_3d(s: &Solution3d, g: &Gravity3, samples: usize) -> Result<Solved3d, Failed> {
    let k = Stiffness::default();
    let failure = |e: rod_ig_core::RodError| Failed {
        reason: format!("cannot evaluate the solution's shape: {e}"),
        termination: rod_ig_core::solver::Termination::EvaluationFailed.as_str(),
        iterations: s.iterations,
        residual: s.residual,
        last_a: Some(planar_part(&s.a)),
        last_a_spatial: Some(Box::new(s.a)),
        spatial: true,
        event: "",
    };
    let (shape, elastic_energy) = if g.is_weightless() {
        (
            spatial::shape(&s.a, &k, samples).map_err(failure)?,
            s.energy,
        )
    } else {
        let shape = heavy3::shape(&s.a, &k, g, samples).map_err(failure)?;
        let elastic = heavy3::evaluate(&s.a, &k, g)
            .map_err(failure)?
            .elastic_energy;
        (shape, elastic)
    };
    Ok(WithShape {
        solution: *s,
        shape,
        event: "",
        critical: None,
        weight: g.weight(),
        elastic_energy,
        tip_wrench: heavy3::wrenches(&s.a, &k, g).map_or([f64::NAN; 6], |w| spatial_row(&w.tip)),
        base_angle: 0.0,
    })
}
