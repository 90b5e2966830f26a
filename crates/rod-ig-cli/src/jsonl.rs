//! The JSON-lines loop shared by every streaming subcommand: one answer line per input line,
//! in order; a line that cannot be handled gets `{"error": "why"}` and the stream goes on.

use serde::Serialize;
use serde_json::Value;
use std::io::{BufRead, Write};

/// Longest request line accepted (16 MiB: a `plan` at its obstacle and vertex bounds takes
/// ≈ 4 MB). A longer line is answered with an error and skipped without being buffered whole.
pub const MAX_LINE_BYTES: usize = 16 << 20;

/// Reads `input` line by line, answers each with `handle`, and writes one JSON line per input
/// line to `output`, flushing after each so that a client can drive the tool interactively.
pub fn run<R: BufRead, W: Write>(
    mut input: R,
    mut output: W,
    mut handle: impl FnMut(&str) -> Result<Value, String>,
) -> std::io::Result<()> {
    let mut raw = Vec::new();
    loop {
        raw.clear();
        let answer = match read_line(&mut input, &mut raw)? {
            Line::End => return Ok(()),
            Line::TooLong(bytes) => error_value(format!(
                "line of {bytes} bytes or more refused: at most {MAX_LINE_BYTES} bytes per request"
            )),
            Line::Read => match std::str::from_utf8(&raw) {
                Err(e) => error_value(format!("line is not UTF-8: {e}")),
                Ok(line) if line.trim().is_empty() => error_value("empty line".to_string()),
                Ok(line) => handle(line.trim()).unwrap_or_else(error_value),
            },
        };
        serde_json::to_writer(&mut output, &answer)?;
        output.write_all(b"\n")?;
        output.flush()?;
    }
}

/// What [`read_line`] found.
enum Line {
    /// End of input.
    End,
    /// A line in the buffer (its newline included, if any).
    Read,
    /// A line longer than [`MAX_LINE_BYTES`], skipped up to its newline: its length so far.
    TooLong(usize),
}

/// Reads one line into `raw`, or skips it when it exceeds [`MAX_LINE_BYTES`] (never holding
/// more than that).
fn read_line<R: BufRead>(input: &mut R, raw: &mut Vec<u8>) -> std::io::Result<Line> {
    let mut skipped = 0usize;
    loop {
        let chunk = match input.fill_buf() {
            Ok(c) => c,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if chunk.is_empty() {
            return Ok(match (raw.is_empty(), skipped) {
                (_, n) if n > 0 => Line::TooLong(n),
                (true, _) => Line::End,
                (false, _) => Line::Read,
            });
        }
        let (take, done) = match chunk.iter().position(|&b| b == b'\n') {
            Some(i) => (i + 1, true),
            None => (chunk.len(), false),
        };
        if skipped == 0 && raw.len() + take <= MAX_LINE_BYTES {
            raw.extend_from_slice(&chunk[..take]);
        } else {
            skipped = skipped.max(raw.len()) + take;
            raw.clear();
        }
        input.consume(take);
        if done {
            return Ok(if skipped > 0 {
                Line::TooLong(skipped)
            } else {
                Line::Read
            });
        }
    }
}

/// `{"error": message}`.
pub fn error_value(message: String) -> Value {
    serde_json::json!({ "error": message })
}

/// Parses one request line into `T`, with serde's message (field, column) on failure.
pub fn parse<T: serde::de::DeserializeOwned>(line: &str) -> Result<T, String> {
    serde_json::from_str(line).map_err(|e| format!("malformed request: {e}"))
}

/// Serialises an answer; non-finite floats become `null` (JSON has no NaN).
pub fn to_value<T: Serialize>(answer: &T) -> Result<Value, String> {
    serde_json::to_value(answer).map_err(|e| format!("cannot encode answer: {e}"))
}

/// Adds the fields `fields_of` computes from a rod's `a` to a solve answer and to each of its
/// `solutions` (an answer without `a`, a failure, gets none).
pub fn with_fields_of_a(
    value: &mut Value,
    fields_of: impl Fn(&[f64]) -> Vec<(&'static str, Value)>,
) {
    let add = |v: &mut Value| {
        let a: Option<Vec<f64>> = v
            .get("a")
            .and_then(Value::as_array)
            .map(|a| a.iter().filter_map(Value::as_f64).collect());
        if let Some(a) = a {
            for (key, field) in fields_of(&a) {
                v[key] = field;
            }
        }
    };
    add(value);
    if let Some(list) = value.get_mut("solutions").and_then(Value::as_array_mut) {
        list.iter_mut().for_each(add);
    }
}

/// `base_wrench` and `tip_wrench` as answer fields (`rod_ig_core::wrench`: what the rod exerts
/// on each gripper, in that gripper's frame); none where they cannot be evaluated.
pub fn wrench_fields<W: Serialize>(
    wrenches: Option<rod_ig_core::wrench::GripperWrenches<W>>,
) -> Vec<(&'static str, Value)> {
    let Some(w) = wrenches else {
        return Vec::new();
    };
    match (serde_json::to_value(w.base), serde_json::to_value(w.tip)) {
        (Ok(base), Ok(tip)) => vec![("base_wrench", base), ("tip_wrench", tip)],
        _ => Vec::new(),
    }
}

/// A request's `deadline_ms` as a duration: finite and positive (the solver checks the upper
/// limit and says so).
pub fn deadline_from_ms(ms: f64) -> Result<std::time::Duration, String> {
    if ms.is_finite() && ms > 0.0 && ms <= 1e7 {
        Ok(std::time::Duration::from_secs_f64(ms / 1000.0))
    } else {
        Err(format!(
            "deadline_ms must be a positive number of milliseconds, got {ms}"
        ))
    }
}

/// Checks a Newton step length α ∈ (0, 1] (paper §3.1).
pub fn check_alpha(alpha: f64) -> Result<f64, String> {
    if alpha.is_finite() && alpha > 0.0 && alpha <= 1.0 {
        Ok(alpha)
    } else {
        Err(format!("alpha must be in (0, 1], got {alpha}"))
    }
}

/// Checks a solver tolerance against the solver's documented range.
pub fn check_tolerance(tolerance: f64) -> Result<f64, String> {
    use rod_ig_core::solver::{MAX_TOLERANCE, MIN_TOLERANCE};
    if (MIN_TOLERANCE..=MAX_TOLERANCE).contains(&tolerance) {
        Ok(tolerance)
    } else {
        Err(format!(
            "tolerance must be in [{MIN_TOLERANCE:e}, {MAX_TOLERANCE:e}], got {tolerance}"
        ))
    }
}

/// Checks an iteration budget (per start, [`rod_ig_core::solver::SolveOptions`]).
pub fn check_max_iterations(n: u32) -> Result<u32, String> {
    use rod_ig_core::solver::MAX_ITERATIONS_LIMIT;
    if (1..=MAX_ITERATIONS_LIMIT).contains(&n) {
        Ok(n)
    } else {
        Err(format!(
            "max_iterations must be in [1, {MAX_ITERATIONS_LIMIT}] (per start), got {n}"
        ))
    }
}

/// Applies a request's optional step length, iteration limit and tolerance (shared by `solve`
/// and `solve3d`) to a solver's options, checking each.
pub fn apply_newton_knobs(
    (alpha, max_iterations, tolerance): (Option<f64>, Option<u32>, Option<f64>),
    into: (&mut f64, &mut u32, &mut f64),
) -> Result<(), String> {
    if let Some(a) = alpha {
        *into.0 = check_alpha(a)?;
    }
    if let Some(n) = max_iterations {
        *into.1 = check_max_iterations(n)?;
    }
    if let Some(t) = tolerance {
        *into.2 = check_tolerance(t)?;
    }
    Ok(())
}

/// The options of a branch-following line (`track`, `track3d`): the default options with the
/// line's `tolerance` and `deadline_ms`, each checked; with weight the least-energy objective,
/// so that a fresh solve answers the hanging cable (as `solve`).
pub fn follow_options<P>(
    tolerance: Option<f64>,
    deadline_ms: Option<f64>,
    weighted: bool,
) -> Result<rod_ig_core::solver::SolveOptions<P>, String>
where
    rod_ig_core::solver::SolveOptions<P>: Default,
{
    let mut options = rod_ig_core::solver::SolveOptions::<P>::default();
    if let Some(t) = tolerance {
        options.tolerance = check_tolerance(t)?;
    }
    if let Some(ms) = deadline_ms {
        options.deadline = deadline_from_ms(ms)?;
    }
    if weighted {
        options.objective = rod_ig_core::solver::Objective::LeastEnergy;
    }
    Ok(options)
}

/// The message for a Newton request without a start.
pub const NEWTON_NEEDS_A0: &str = "method \"newton\" needs an initial guess \"a0\"";

/// Solver choice as spelled in requests.
#[derive(serde::Deserialize, Clone, Copy, Default)]
#[serde(rename_all = "snake_case")]
pub enum MethodName {
    /// Multi-start robust search.
    #[default]
    Robust,
    /// The paper's fixed-step Newton.
    Newton,
}

/// Objective as spelled in requests.
#[derive(serde::Deserialize, Clone, Copy, Default)]
#[serde(rename_all = "snake_case")]
pub enum ObjectiveName {
    /// The first stable solution found.
    #[default]
    First,
    /// The least elastic energy among the solutions found.
    LeastEnergy,
}

/// The solver fields every solve request shares (`solve` and `solve3d`).
pub struct Knobs<P> {
    /// "method".
    pub method: MethodName,
    /// "objective".
    pub objective: ObjectiveName,
    /// "alpha".
    pub alpha: Option<f64>,
    /// "max_iterations".
    pub max_iterations: Option<u32>,
    /// "tolerance".
    pub tolerance: Option<f64>,
    /// "deadline_ms".
    pub deadline_ms: Option<f64>,
    /// "a0".
    pub a0: Option<P>,
}

/// The solver options of a request, from the model's defaults.
pub fn solve_options<P>(
    knobs: Knobs<P>,
    defaults: rod_ig_core::solver::SolveOptions<P>,
) -> Result<rod_ig_core::solver::SolveOptions<P>, String> {
    use rod_ig_core::solver::{Method, Objective};
    let mut options = rod_ig_core::solver::SolveOptions {
        method: match knobs.method {
            MethodName::Robust => Method::Robust,
            MethodName::Newton => Method::Newton,
        },
        objective: match knobs.objective {
            ObjectiveName::First => Objective::FirstFound,
            ObjectiveName::LeastEnergy => Objective::LeastEnergy,
        },
        initial_guess: knobs.a0,
        ..defaults
    };
    apply_newton_knobs(
        (knobs.alpha, knobs.max_iterations, knobs.tolerance),
        (
            &mut options.alpha,
            &mut options.max_iterations,
            &mut options.tolerance,
        ),
    )?;
    if let Some(ms) = knobs.deadline_ms {
        options.deadline = deadline_from_ms(ms)?;
    }
    if options.method == Method::Newton && options.initial_guess.is_none() {
        return Err(NEWTON_NEEDS_A0.to_string());
    }
    Ok(options)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn answers(input: &str) -> Vec<Value> {
        let mut out = Vec::new();
        run(input.as_bytes(), &mut out, |line| {
            let v: Value = parse(line)?;
            Ok(serde_json::json!({ "echo": v }))
        })
        .expect("in-memory I/O");
        String::from_utf8(out)
            .expect("utf8")
            .lines()
            .map(|l| serde_json::from_str(l).expect("valid JSON out"))
            .collect()
    }

    #[test]
    fn one_answer_per_line_and_errors_do_not_stop_the_stream() {
        let out = answers("{\"a\":1}\nnot json\n\n{\"b\":2}\n");
        assert_eq!(out.len(), 4);
        assert_eq!(out[0]["echo"]["a"], 1);
        assert!(out[1]["error"].as_str().unwrap().contains("malformed"));
        assert_eq!(out[2]["error"], "empty line");
        assert_eq!(out[3]["echo"]["b"], 2);
    }

    #[test]
    fn option_checks() {
        assert_eq!(check_alpha(0.5), Ok(0.5));
        assert!(
            check_alpha(0.0).is_err()
                && check_alpha(1.5).is_err()
                && check_alpha(f64::NAN).is_err()
        );
        assert_eq!(check_tolerance(1e-9), Ok(1e-9));
        assert!(check_tolerance(-1.0).is_err() && check_tolerance(f64::INFINITY).is_err());
        assert!(check_tolerance(1e308).is_err() && check_tolerance(1e-20).is_err());
        assert_eq!(check_max_iterations(1), Ok(1));
        assert!(check_max_iterations(0).is_err() && check_max_iterations(100_001).is_err());
    }

    #[test]
    fn last_line_without_newline_is_answered() {
        assert_eq!(answers("{\"a\":1}").len(), 1);
    }

    #[test]
    fn invalid_utf8_is_an_error_line() {
        let mut out = Vec::new();
        run(&b"\xff\xfe\n{}\n"[..], &mut out, |_| Ok(Value::Null)).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2);
        assert!(lines[0].contains("UTF-8"));
    }
}
