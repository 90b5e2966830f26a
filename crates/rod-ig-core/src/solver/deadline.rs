//! The deadline of the solve running on this thread (issue 9: bounded time on every call).
//!
//! Set once by the public entry points ([`super::solve`], [`super::solve_all`], the planar
//! tracker, the branch follower, the planner) through a guard, and polled by every loop inside them (Newton
//! iterations, line searches, starts, polishing), so that no nested loop needs a parameter to
//! stop in time. The guard restores the previous deadline on drop.

use std::cell::Cell;
use std::time::{Duration, Instant};

thread_local! {
    static END: Cell<Option<Instant>> = const { Cell::new(None) };
}

/// Restores the enclosing deadline when dropped.
pub(crate) struct Guard(Option<Instant>);

impl Drop for Guard {
    fn drop(&mut self) {
        END.with(|e| e.set(self.0));
    }
}

/// Starts a deadline `budget` from now (an enclosing, earlier deadline is kept).
pub(crate) fn scope(budget: Duration) -> Guard {
    let end = Instant::now().checked_add(budget);
    END.with(|e| {
        let previous = e.get();
        let new = match (previous, end) {
            (Some(p), Some(n)) => Some(p.min(n)),
            (p, n) => p.or(n),
        };
        e.set(new);
        Guard(previous)
    })
}

/// The deadline in force on this thread.
pub(crate) fn current() -> Option<Instant> {
    END.with(|e| e.get())
}

/// Puts `end` in force on this thread until dropped (a helper thread working for a call).
pub(crate) fn until(end: Option<Instant>) -> Guard {
    END.with(|e| Guard(e.replace(end)))
}

/// Lifts the deadline until dropped (work that must complete, such as an explicit warm-up).
pub(crate) fn unbounded() -> Guard {
    END.with(|e| Guard(e.replace(None)))
}

/// True once the current deadline has passed.
#[inline]
pub(crate) fn expired() -> bool {
    END.with(|e| e.get())
        .is_some_and(|end| Instant::now() >= end)
}
