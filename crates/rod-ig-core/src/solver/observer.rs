//! Watching a solve: an [`Observer`] receives an [`Event`] at every start, accepted iterate and
//! end of every solve on this thread while [`observe`] runs (the argmin pattern of a solver
//! and its observers, without a parameter threaded through every inner loop).
//!
//! ```
//! use rod_ig_core::solver::{self, observe, Event, IterationLog};
//! use rod_ig_core::planar::PlanarClosedForm;
//! use rod_ig_core::PlanarPose;
//!
//! rod_ig_core::planar::ig::warm_up(); // the atlas, outside the solve's deadline
//! let target = PlanarPose::new(0.6, 0.3, 0.5);
//! let options = solver::SolveOptions::default();
//! let (result, log) = observe(IterationLog::default(), || {
//!     solver::solve(&PlanarClosedForm, &target, &options)
//! });
//! let solution = result.unwrap();
//! assert_eq!(log.iterations(), solution.iterations as usize);
//! assert!(matches!(log.events.last(), Some(Event::Finished { .. })));
//! ```

use super::Termination;
use std::any::Any;
use std::cell::{Cell, RefCell};

/// Something that happened inside a solve. Scalars only, so that one observer serves every
/// model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// A start (initial guess, seed, polishing run) begins; `index` counts from 0 per solve.
    StartBegun {
        /// Start number within the solve.
        index: u32,
        /// ‖a0‖₂ of the start.
        a0_norm: f64,
    },
    /// An iterate was accepted.
    Iteration {
        /// Iteration number within its start (1 = first step).
        iteration: u32,
        /// Residual ‖(position error, orientation error)‖₂ at the iterate the step was taken
        /// from, towards the solve's current goal.
        residual: f64,
        /// ‖Δa‖₂ of the step.
        step: f64,
        /// Step length factor used (α, after backtracking).
        alpha: f64,
    },
    /// A start ended.
    StartEnded {
        /// Start number within the solve.
        index: u32,
        /// How it ended (`Converged` when it produced the answer or a candidate).
        termination: Termination,
    },
    /// A public entry point ([`super::solve`], [`super::solve_all`]) returned.
    Finished {
        /// Why it ended.
        termination: Termination,
        /// Newton iterations over all starts.
        iterations: u32,
        /// Starts tried.
        starts: u32,
        /// Wall time, µs.
        elapsed_us: f64,
    },
}

/// Receives the events of the solves run inside [`observe`].
pub trait Observer: Any {
    /// Called synchronously for every event (keep it cheap: it runs inside the solver loop).
    fn observe(&mut self, event: &Event);
}

/// Records every event (the CLI's `--verbose` and the tests).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IterationLog {
    /// The events in order.
    pub events: Vec<Event>,
}

impl IterationLog {
    /// Accepted iterates recorded.
    pub fn iterations(&self) -> usize {
        self.events
            .iter()
            .filter(|e| matches!(e, Event::Iteration { .. }))
            .count()
    }

    /// Starts recorded.
    pub fn starts(&self) -> usize {
        self.events
            .iter()
            .filter(|e| matches!(e, Event::StartBegun { .. }))
            .count()
    }
}

impl Observer for IterationLog {
    fn observe(&mut self, event: &Event) {
        self.events.push(*event);
    }
}

/// Counts without storing (the benchmarks and the node's diagnostics).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counters {
    /// Accepted iterates.
    pub iterations: u64,
    /// Starts begun.
    pub starts: u64,
    /// Solves finished.
    pub solves: u64,
    /// Solves that ended at their deadline.
    pub deadlines: u64,
    /// Largest number of starts one solve used.
    pub max_starts_per_solve: u32,
}

impl Observer for Counters {
    fn observe(&mut self, event: &Event) {
        match *event {
            Event::StartBegun { .. } => self.starts += 1,
            Event::Iteration { .. } => self.iterations += 1,
            Event::StartEnded { .. } => {}
            Event::Finished {
                termination,
                starts,
                ..
            } => {
                self.solves += 1;
                if termination == Termination::Deadline {
                    self.deadlines += 1;
                }
                self.max_starts_per_solve = self.max_starts_per_solve.max(starts);
            }
        }
    }
}

impl<F: FnMut(&Event) + 'static> Observer for F {
    fn observe(&mut self, event: &Event) {
        self(event)
    }
}

thread_local! {
    static ACTIVE: Cell<bool> = const { Cell::new(false) };
    static CURRENT: RefCell<Option<Box<dyn Observer>>> = const { RefCell::new(None) };
}

/// Restores the enclosing observer if `f` unwinds.
struct Restore(Option<Box<dyn Observer>>, bool);

impl Drop for Restore {
    fn drop(&mut self) {
        let previous = self.0.take();
        let active = self.1;
        CURRENT.with(|c| *c.borrow_mut() = previous);
        ACTIVE.with(|a| a.set(active));
    }
}

/// Runs `f` with `observer` receiving the events of every solve `f` runs on this thread, and
/// gives the observer back. Nested calls shadow the enclosing observer for their duration; an
/// observer that calls `observe` from its own callback gets no events from that inner scope.
pub fn observe<O: Observer, R>(observer: O, f: impl FnOnce() -> R) -> (R, O) {
    let mut mine: Option<Box<dyn Observer>> = Some(Box::new(observer));
    let installed = CURRENT.with(|c| match c.try_borrow_mut() {
        Ok(mut slot) => Some(std::mem::replace(&mut *slot, mine.take())),
        Err(_) => None,
    });
    let result = match installed {
        Some(previous) => {
            let was_active = ACTIVE.with(|a| a.replace(true));
            let restore = Restore(previous, was_active);
            let result = f();
            mine = CURRENT.with(|c| c.borrow_mut().take());
            drop(restore);
            result
        }
        None => f(),
    };
    let mine: Box<dyn Any> = match mine {
        Some(m) => m,
        None => unreachable!("the slot is restored only by the scope that filled it"),
    };
    match mine.downcast::<O>() {
        Ok(o) => (result, *o),
        Err(_) => unreachable!("the slot holds the observer this scope installed"),
    }
}

/// Delivers `event` to the current observer, if any (a flag test when there is none).
#[inline]
pub(crate) fn emit(event: Event) {
    if !ACTIVE.with(|a| a.get()) {
        return;
    }
    CURRENT.with(|c| {
        // An observer that itself runs a solve would re-enter: its inner events are dropped.
        if let Ok(mut slot) = c.try_borrow_mut() {
            if let Some(o) = slot.as_mut() {
                o.observe(&event);
            }
        }
    });
}
