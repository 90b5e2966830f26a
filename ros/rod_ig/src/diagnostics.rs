//! What the node reports on `/diagnostics` (diagnostic_msgs/DiagnosticArray, 1 Hz): solve
//! rate, failures by reason, latency percentiles, the last error. No DDS here: the node's
//! solver thread records every solve, a timer task turns the record into a message.

use std::collections::{BTreeMap, VecDeque};

use crate::messages::{DiagnosticStatus, KeyValue};
use rod_ig_core::solver::Counters;

/// Solve latencies kept for the percentiles: the last this many solves.
pub const LATENCY_WINDOW: usize = 1000;

/// `DiagnosticStatus.level` values.
pub mod level {
    /// All well.
    pub const OK: u8 = 0;
    /// Some targets failed in the last period.
    pub const WARN: u8 = 1;
}

/// Running record of the node's solves.
#[derive(Debug, Default)]
pub struct SolveStats {
    latencies_s: VecDeque<f64>,
    solved: u64,
    failed: u64,
    failures_by_reason: BTreeMap<String, u64>,
    last_error: Option<String>,
    solved_in_period: u64,
    failed_in_period: u64,
    /// The solver's own counts (starts, iterations, deadlines), from its observer.
    work: Counters,
}

impl SolveStats {
    /// Records one solve: its success, why it failed (`failure`: a bounded key, the solver's
    /// termination or `rejected_target`), its message and its wall time in seconds.
    pub fn record(&mut self, success: bool, failure: &str, message: &str, seconds: f64) {
        if seconds.is_finite() && seconds >= 0.0 {
            if self.latencies_s.len() == LATENCY_WINDOW {
                self.latencies_s.pop_front();
            }
            self.latencies_s.push_back(seconds);
        }
        if success {
            self.solved += 1;
            self.solved_in_period += 1;
        } else {
            self.failed += 1;
            self.failed_in_period += 1;
            let key = if failure.is_empty() {
                "unknown"
            } else {
                failure
            };
            *self.failures_by_reason.entry(key.to_string()).or_default() += 1;
            self.last_error = Some(message.to_string());
        }
    }

    /// Adds the solver's counts of one solve (its observer's [`Counters`]).
    pub fn record_work(&mut self, work: &Counters) {
        self.work.iterations += work.iterations;
        self.work.starts += work.starts;
        self.work.solves += work.solves;
        self.work.deadlines += work.deadlines;
        self.work.max_starts_per_solve = self
            .work
            .max_starts_per_solve
            .max(work.max_starts_per_solve);
    }

    /// The `q`-quantile (0..=1) of the kept latencies in seconds, nearest rank; None when no
    /// solve was recorded.
    pub fn latency_quantile(&self, q: f64) -> Option<f64> {
        if self.latencies_s.is_empty() {
            return None;
        }
        let mut v: Vec<f64> = self.latencies_s.iter().copied().collect();
        v.sort_by(f64::total_cmp);
        let rank = (q.clamp(0.0, 1.0) * v.len() as f64).ceil() as usize;
        Some(v[rank.saturating_sub(1).min(v.len() - 1)])
    }

    /// The status for the period since the last report (`period_s` long), and starts a new
    /// period. WARN when a target failed in the period, OK otherwise.
    pub fn report(
        &mut self,
        name: &str,
        period_s: f64,
        received: u64,
        service_calls: u64,
    ) -> DiagnosticStatus {
        let done = self.solved_in_period + self.failed_in_period;
        let rate = if period_s > 0.0 {
            done as f64 / period_s
        } else {
            0.0
        };
        let ms = |q: f64| {
            self.latency_quantile(q)
                .map_or_else(|| "n/a".to_string(), |s| format!("{:.3}", s * 1e3))
        };
        let (level, message) = if self.failed_in_period > 0 {
            (
                level::WARN,
                format!(
                    "{} of {done} solves failed in the last {period_s:.1} s; last error: {}",
                    self.failed_in_period,
                    self.last_error.as_deref().unwrap_or("")
                ),
            )
        } else {
            (
                level::OK,
                format!("{done} solves in the last {period_s:.1} s, none failed"),
            )
        };
        let mut values = vec![
            kv("solves_per_second", format!("{rate:.2}")),
            kv("solved_total", self.solved.to_string()),
            kv("failed_total", self.failed.to_string()),
            kv("targets_received", received.to_string()),
            kv("service_calls", service_calls.to_string()),
            kv("latency_p50_ms", ms(0.5)),
            kv("latency_p99_ms", ms(0.99)),
            kv("latency_window", self.latencies_s.len().to_string()),
            kv("last_error", self.last_error.clone().unwrap_or_default()),
            kv("solver_iterations_total", self.work.iterations.to_string()),
            kv("solver_starts_total", self.work.starts.to_string()),
            // Every deadline, the branch follower's too (whose moves are not solves the
            // observer sees end).
            kv(
                "solver_deadlines_total",
                self.failures_by_reason
                    .get("deadline")
                    .copied()
                    .unwrap_or(0)
                    .to_string(),
            ),
            kv(
                "solver_max_starts_per_solve",
                self.work.max_starts_per_solve.to_string(),
            ),
        ];
        values.extend(
            self.failures_by_reason
                .iter()
                .map(|(reason, n)| kv(&format!("failed: {reason}"), n.to_string())),
        );
        self.solved_in_period = 0;
        self.failed_in_period = 0;
        DiagnosticStatus {
            level,
            name: name.to_string(),
            message,
            // A software component: diagnostic_updater's convention is its node's name.
            hardware_id: name.split(':').next().unwrap_or(name).trim().to_string(),
            values,
        }
    }
}

fn kv(key: &str, value: String) -> KeyValue {
    KeyValue {
        key: key.to_string(),
        value,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value<'a>(s: &'a DiagnosticStatus, key: &str) -> &'a str {
        &s.values.iter().find(|kv| kv.key == key).unwrap().value
    }

    #[test]
    fn failure_keys_are_bounded_whatever_the_messages() {
        // Issue 20: keys embedded free text and numbers ("failed: deadline reached after 161
        // iterations without co"), so the key set grew without bound.
        let mut s = SolveStats::default();
        for k in 0..500 {
            let message = format!("solver failed: deadline reached after {k} iterations");
            s.record(false, "deadline", &message, 0.25);
            s.record(
                false,
                "unreachable",
                &format!("out of reach: |p| = {k}"),
                1e-4,
            );
        }
        let r = s.report("/rod_ig_node: inverse geometry", 1.0, 1000, 0);
        let failure_keys: Vec<&str> = r
            .values
            .iter()
            .map(|kv| kv.key.as_str())
            .filter(|k| k.starts_with("failed: "))
            .collect();
        assert_eq!(failure_keys, ["failed: deadline", "failed: unreachable"]);
        assert_eq!(value(&r, "solver_deadlines_total"), "500");
        assert_eq!(r.hardware_id, "/rod_ig_node");
    }

    #[test]
    fn report_counts_rates_and_percentiles() {
        let mut s = SolveStats::default();
        for i in 1..=100 {
            s.record(true, "", "", f64::from(i) * 1e-3); // 1..100 ms
        }
        s.record(false, "unreachable", "out of reach: far", 0.5e-3);
        s.record(false, "deadline", "solver failed: deadline reached", 0.25);
        let r = s.report("/rod_ig_node: inverse geometry", 2.0, 102, 0);
        assert_eq!(r.level, level::WARN);
        assert!(r.message.contains("2 of 102"), "{}", r.message);
        assert_eq!(value(&r, "solves_per_second"), "51.00");
        assert_eq!(value(&r, "failed: unreachable"), "1");
        assert_eq!(value(&r, "failed: deadline"), "1");
        assert_eq!(value(&r, "last_error"), "solver failed: deadline reached");
        // Nearest rank over 102 latencies: p50 is the 51st smallest (50 ms), p99 the 101st
        // (100 ms).
        assert_eq!(value(&r, "latency_p50_ms"), "50.000");
        assert_eq!(value(&r, "latency_p99_ms"), "100.000");
        // A quiet period is OK, and the totals stay.
        let r = s.report("n", 1.0, 102, 0);
        assert_eq!(r.level, level::OK);
        assert_eq!(value(&r, "solves_per_second"), "0.00");
        assert_eq!(value(&r, "failed_total"), "2");
    }

    #[test]
    fn latency_window_is_bounded() {
        let mut s = SolveStats::default();
        for _ in 0..3 * LATENCY_WINDOW {
            s.record(true, "", "", 1e-3);
        }
        s.record(true, "", "", f64::NAN);
        assert_eq!(s.latencies_s.len(), LATENCY_WINDOW);
        assert_eq!(s.latency_quantile(0.99), Some(1e-3));
    }

    #[test]
    fn solver_work_comes_from_the_observer() {
        use rod_ig_core::planar::ig::{self, SolveOptions};
        use rod_ig_core::solver::observe;
        use rod_ig_core::PlanarPose;
        // The atlas, once per process (the node builds it at start-up).
        ig::warm_up();
        let mut s = SolveStats::default();
        for target in [
            PlanarPose::new(0.5, 0.3, 0.8),
            PlanarPose::new(0.2, 0.6, 2.0),
        ] {
            let (r, work) = observe(Counters::default(), || {
                ig::solve(&target, &SolveOptions::default())
            });
            let solution = r.expect("reachable targets");
            assert_eq!(work.iterations, u64::from(solution.iterations));
            s.record_work(&work);
        }
        let r = s.report("n", 1.0, 2, 0);
        let iterations: u64 = value(&r, "solver_iterations_total").parse().unwrap();
        let starts: u64 = value(&r, "solver_starts_total").parse().unwrap();
        assert!(iterations > 0 && starts >= 2, "{iterations} {starts}");
        assert_eq!(value(&r, "solver_deadlines_total"), "0");
    }
}
