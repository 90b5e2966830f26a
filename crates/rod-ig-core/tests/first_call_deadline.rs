//! Deadlines hold from a process's first call (issue 24): the atlas of stable rods, built on
//! first use, is charged to the calls that need it, in pieces that poll their deadline. This
//! binary holds one test so that nothing else builds the atlas first.
//!
//! Checked by counting work, not by reading a clock (issue 42: a loaded CI machine made the
//! timed version fail): each first call runs under a budget counted in work units
//! ([`deadline::work_budget`]) and must charge at most the budget plus one atlas piece and
//! one poll interval. Helper threads building the atlas get the units the caller had left.

use rod_ig_core::deadline;
use rod_ig_core::plan::{PlanError, PlanRequest, Planner};
use rod_ig_core::planar::ig::{self, SolveOptions, Termination};
use rod_ig_core::planar::PlanarClosedForm;
use rod_ig_core::solver::{BranchFollower, MAX_DEADLINE};
use rod_ig_core::{PlanarParams, PlanarPose};

/// Units a call may charge past its budget: one atlas piece under way when the budget
/// passes, and one poll interval.
const SLACK: u64 = deadline::units::ATLAS_PIECE + deadline::POLL_UNITS;

/// Runs `f` under a counted budget; asserts it charged at most the budget plus [`SLACK`].
fn within<R>(what: &str, budget: u64, f: impl FnOnce() -> R) -> R {
    let _budget = deadline::work_budget(budget);
    let before = deadline::charged();
    let r = f();
    let charged = deadline::charged() - before;
    assert!(
        charged <= budget + SLACK,
        "{what}: charged {charged} units for a budget of {budget}"
    );
    r
}

#[test]
fn first_calls_answer_within_their_budget() {
    let target = PlanarPose::new(0.9, 0.1, 3.0);
    // Wall-time deadlines far away: only the counted budgets can stop the calls.
    let options = SolveOptions {
        deadline: MAX_DEADLINE,
        ..SolveOptions::default()
    };
    // The very first call cannot build the atlas (tens of pieces of 500 units) in 1,000.
    let first = within("first solve", 1_000, || ig::solve(&target, &options));
    let f = first.expect_err("no atlas yet");
    assert_eq!(f.termination(), Termination::Deadline, "{}", f.reason);
    for budget in [1_000u64, 10_000, 100_000] {
        let r = within("solve", budget, || ig::solve(&target, &options));
        if let Err(f) = &r {
            // Out of budget, or (once the atlas is ready) no stable rod found in it.
            assert!(
                matches!(
                    f.termination(),
                    Termination::Deadline | Termination::NoStableSolution
                ),
                "{}",
                f.reason
            );
        }
        let newton = SolveOptions {
            method: ig::Method::Newton,
            ..options
        };
        let _ = within("Newton from the default start", budget, || {
            ig::solve(&target, &newton)
        });
        let _ = within("tracker", budget, || {
            ig::Tracker::new(options).solve(&target)
        });
        let _ = within("branch follower", budget, || {
            BranchFollower::new(PlanarClosedForm, options).follow(&target)
        });
        let plan = within("plan", budget, || {
            Planner::new().plan(&PlanRequest {
                start: PlanarParams::new(0.5, 0.1, 0.1),
                goal: PlanarPose::new(0.8, 0.3, 0.5),
                obstacles: Vec::new(),
                deadline: MAX_DEADLINE,
                gravity: rod_ig_core::planar::heavy::Gravity::NONE,
            })
        });
        if let Err(e) = plan {
            assert!(
                matches!(
                    e,
                    PlanError::Deadline { .. } | PlanError::GoalUnreachable(_)
                ),
                "{e}"
            );
        }
    }
    // The pieces built by those calls are kept: the next calls complete the atlas and solve.
    let easy = PlanarPose::new(0.6, 0.3, 0.5);
    let solved =
        (0..100).find_map(|_| within("later solve", 100_000, || ig::solve(&easy, &options)).ok());
    assert!(solved.is_some(), "the atlas completes across calls");
}
