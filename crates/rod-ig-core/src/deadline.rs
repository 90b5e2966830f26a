//! The deadline of the call running on this thread, and the work meter that enforces it
//! inside every evaluation (issues 9 and 42: bounded time on every call).
//!
//! - **Set once** by the public entry points ([`crate::solver::solve`], the planar tracker, the
//!   branch follower, the planner, the evaluations that take a deadline) through a [`Guard`],
//!   so that no nested loop needs a parameter to stop in time. The guard restores the
//!   enclosing deadline on drop; a nested scope never extends an enclosing one.
//! - **Polled between evaluations** ([`expired`]: Newton iterations, line searches, starts)
//!   and **charged inside them** ([`charge`]: every integration step, stability-scan sample,
//!   collision test and atlas piece), so that one long evaluation (a 3-D integration of
//!   100,000 steps, a Taylor series of 2,000 steps, a collision scan over 10⁶ discs) stops
//!   with the time left too.
//! - **Work units.** One unit is about a microsecond of work on a current x86-64 core: each
//!   site charges its measured cost ([`units`]). The clock is read once per [`POLL_UNITS`]
//!   units charged (≈ 64 µs), so the meter costs one thread-local add per step; once the
//!   deadline has passed every further charge polls, so that work abandoned on one path is not
//!   resumed on the next.
//! - **Counted budgets.** [`work_budget`] puts a deadline counted in units instead of time in
//!   force: the same calls stop at the same point on a loaded or an idle machine, which is
//!   how the tests check that every request stops within its budget without reading a clock,
//!   and [`charged`] reports the work done.

use std::cell::Cell;
use std::time::{Duration, Instant};

/// Units charged between two reads of the clock (≈ 64 µs of work).
pub const POLL_UNITS: u64 = 64;

/// The measured cost, in work units (≈ µs), of the steps the evaluations charge. The
/// benchmark `rod-ig bench --only deadlines` reports the time each unit really takes.
pub mod units {
    /// One attempted DOP853 step of the 3-D rod with its 6 variational columns (≈ 1.5 µs).
    pub const DOP853_STEP: u64 = 2;
    /// One planar evaluation by its closed forms (≈ 0.3–2 µs; charged at every public entry).
    pub const PLANAR_EVALUATION: u64 = 1;
    /// One Taylor step of the planar series, in f64 or double-double (≈ 1–15 µs: up to 30
    /// terms with their gradients; measured 14 µs per step on a coil of a3 = 3e6).
    pub const TAYLOR_STEP: u64 = 10;
    /// One step of the series of the rod with weight, with its variational columns (≈ 1 µs).
    pub const HEAVY_STEP: u64 = 1;
    /// One sample of a planar stability scan (an evaluation of J(t, a), ≈ 0.2 µs): charged in
    /// groups of 8.
    pub const SCAN_SAMPLES_PER_UNIT: u64 = 8;
    /// One planar stability report (a scan of J(t, a), ≈ 5–20 µs).
    pub const STABILITY_REPORT: u64 = 10;
    /// One piece of the atlas of stable rods built on first use (≈ 0.5 ms).
    pub const ATLAS_PIECE: u64 = 500;
    /// Segment–obstacle tests per unit of a planner's collision scan (≈ 15 ns each).
    pub const DISC_TESTS_PER_UNIT: u64 = 64;
}

thread_local! {
    static END: Cell<Option<Instant>> = const { Cell::new(None) };
    static WORK_END: Cell<Option<u64>> = const { Cell::new(None) };
    /// Units charged on this thread since it started (the counted clock).
    static CHARGED: Cell<u64> = const { Cell::new(0) };
    /// Units charged since the clock was last read.
    static UNPOLLED: Cell<u64> = const { Cell::new(0) };
}

/// Restores the enclosing deadline when dropped.
#[must_use = "the deadline holds only while the guard lives"]
pub struct Guard {
    end: Option<Instant>,
    work_end: Option<u64>,
}

impl Drop for Guard {
    fn drop(&mut self) {
        END.with(|e| e.set(self.end));
        WORK_END.with(|e| e.set(self.work_end));
        // The next charge reads the clock again under the restored deadline.
        UNPOLLED.with(|u| u.set(0));
    }
}

fn guard() -> Guard {
    Guard {
        end: END.with(|e| e.get()),
        work_end: WORK_END.with(|e| e.get()),
    }
}

/// Starts a deadline `budget` from now until the guard is dropped (an enclosing, earlier
/// deadline is kept).
pub fn scope(budget: Duration) -> Guard {
    let g = guard();
    let end = Instant::now().checked_add(budget);
    let new = match (g.end, end) {
        (Some(p), Some(n)) => Some(p.min(n)),
        (p, n) => p.or(n),
    };
    END.with(|e| e.set(new));
    g
}

/// Narrows the deadline in force to `fraction` of the time it leaves (of its work units too),
/// until the guard is dropped: a search that tries several starts in turn gives one start a
/// share, so that one start cannot spend the time of all the others. Without a deadline in
/// force, none is started.
pub(crate) fn share_of_remaining(fraction: f64) -> Guard {
    let g = guard();
    let now = Instant::now();
    if let Some(end) = g.end {
        let left = end
            .saturating_duration_since(now)
            .mul_f64(fraction.clamp(0.0, 1.0));
        END.with(|e| e.set(now.checked_add(left).map(|n| n.min(end)).or(Some(end))));
    }
    if let Some(work_end) = g.work_end {
        let left = work_end.saturating_sub(charged()) as f64 * fraction.clamp(0.0, 1.0);
        WORK_END.with(|e| e.set(Some(charged().saturating_add(left as u64).min(work_end))));
        UNPOLLED.with(|u| u.set(0));
    }
    g
}

/// Puts a deadline counted in work units in force until the guard is dropped: it passes once
/// `units` more have been charged on this thread (an enclosing budget that ends earlier is
/// kept). Deterministic: the same call stops at the same point on any machine.
pub fn work_budget(units: u64) -> Guard {
    let g = guard();
    let end = charged().saturating_add(units);
    WORK_END.with(|e| e.set(Some(g.work_end.map_or(end, |p| p.min(end)))));
    UNPOLLED.with(|u| u.set(0));
    g
}

/// Units charged on this thread so far (a monotonic count; subtract two readings).
pub fn charged() -> u64 {
    CHARGED.with(|c| c.get())
}

/// The deadline in force on this thread, to hand to a helper thread working for the same call.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Handoff {
    end: Option<Instant>,
    work_left: Option<u64>,
}

/// The deadline in force here, for [`Handoff::enter`] on a helper thread.
pub(crate) fn handoff() -> Handoff {
    Handoff {
        end: END.with(|e| e.get()),
        work_left: WORK_END
            .with(|e| e.get())
            .map(|end| end.saturating_sub(charged())),
    }
}

impl Handoff {
    /// Puts the handed-off deadline in force on this (helper) thread until dropped: the same
    /// time, and a counted budget of the units the caller had left.
    pub(crate) fn enter(self) -> Guard {
        let g = guard();
        END.with(|e| e.set(self.end));
        let work_end = self.work_left.map(|left| charged().saturating_add(left));
        WORK_END.with(|e| e.set(work_end));
        UNPOLLED.with(|u| u.set(0));
        g
    }
}

/// Lifts the deadline until dropped (work that must complete, such as an explicit warm-up).
pub(crate) fn unbounded() -> Guard {
    let g = guard();
    END.with(|e| e.set(None));
    WORK_END.with(|e| e.set(None));
    g
}

/// True once the deadline in force has passed (reads the clock).
#[inline]
pub fn expired() -> bool {
    let passed = WORK_END
        .with(|e| e.get())
        .is_some_and(|end| charged() >= end)
        || END
            .with(|e| e.get())
            .is_some_and(|end| Instant::now() >= end);
    // Once passed, every later charge polls: the caller that ignores one abandoned evaluation
    // and starts another stops that one at its first step.
    UNPOLLED.with(|u| u.set(if passed { POLL_UNITS } else { 0 }));
    passed
}

/// Charges `units` of work done inside an evaluation; reads the clock once [`POLL_UNITS`]
/// units have accumulated since the last read, and returns true when the deadline has
/// passed (the caller abandons the evaluation with an error that says so).
#[inline]
pub fn charge(units: u64) -> bool {
    CHARGED.with(|c| c.set(c.get() + units));
    let unpolled = UNPOLLED.with(|u| {
        let n = u.get() + units;
        u.set(n);
        n
    });
    unpolled >= POLL_UNITS && expired()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A share narrows the budget in force to its fraction of what is left, and dropping it
    /// gives back the rest: counted in work units, so the test does not depend on the clock.
    #[test]
    fn a_share_of_the_remaining_work_expires_first_and_gives_back_the_rest() {
        let _budget = work_budget(1_000);
        assert!(!charge(100));
        {
            let _share = share_of_remaining(0.5);
            // 900 left: the share ends after 450 more.
            assert!(!charge(440));
            assert!(!expired());
            assert!(charge(20) || expired());
        }
        // The share's end is gone; the budget's 1,000 still holds.
        assert!(!expired());
        assert!(!charge(400));
        assert!(charge(100) || expired());
    }

    /// Without a deadline in force a share starts none.
    #[test]
    fn a_share_without_a_deadline_is_unbounded() {
        let _unbounded = unbounded();
        let _share = share_of_remaining(0.01);
        assert!(!charge(1 << 40));
        assert!(!expired());
    }
}
