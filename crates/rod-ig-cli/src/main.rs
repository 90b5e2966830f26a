//! `rod-ig`: the command-line face of rod-ig-core. JSON lines in, JSON lines out; benchmarks;
//! SVG pictures. A thin adapter: every number comes from the solver crate.

/// `println!` for the benchmark's report, except that a closed stdout (`rod-ig bench | head`)
/// ends the program quietly instead of panicking: std ignores SIGPIPE, so each write would
/// fail with BrokenPipe.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout(), $($arg)*) {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(0);
            }
            eprintln!("rod-ig: cannot write the report to stdout: {e}");
            std::process::exit(1);
        }
    }};
}

mod answer;
mod bench;
mod bench_deadlines;
mod bench_tails;
mod follower;
mod held3d_cmds;
mod held_cmds;
mod jsonl;
mod motion_cmds;
mod planar_cmds;
mod spatial_cmds;
mod spatial_track;
mod svg;
mod timing;

use clap::{Parser, Subcommand, ValueEnum};
use rod_ig_core::planar::heavy::Gravity;
use std::io::{self, Write};
use std::path::PathBuf;
use std::process::ExitCode;

/// Planar Kirchhoff elastic rods held by two grippers: shape, sensitivity, stability and
/// inverse geometry (unit rod, unit stiffness, base at the identity).
#[derive(Parser)]
#[command(name = "rod-ig", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Forward map. Reads JSON lines {"a": [a3, a4, a5], "weight"? (w = ρgAL³/EI, default 0),
    /// "gravity"? ([gx, gy] in the base frame, default [0, -1])} on stdin; writes one line
    /// each: {"tip": {"x", "y", "theta"}, "jacobian": [[dx/da3, dx/da4, dx/da5], [dy/..],
    /// [dθ/..]], "stable", "energy", "stability_margin" (normalised g_min, ≈ 1 for a gently
    /// bent rod), "stability_uncertain", "base_wrench" and "tip_wrench" ({"force": [fx, fy],
    /// "moment"}: what the rod exerts on each gripper, in that gripper's frame, as a wrist
    /// force-torque sensor reads it); with weight also "elastic_energy", "tip_force" and
    /// "condition" (the tip's sensitivity to rounding a: above weight 200 and 1e9 the verdict
    /// is uncertain)}. theta is unwrapped (∫κ). "base_condition" ("clamped" | "pinned") and
    /// "tip_condition" ("clamped" | "pinned" | "free"): a pinned base takes "base_angle" and
    /// a3 = 0, a free tip (a4, a5) = w ĝ + "tip_load"; the verdict is the second variation's
    /// with the natural conditions, and the answer adds "base_angle", "turns",
    /// "self_intersects" (docs/ends.md). A line that cannot be parsed or evaluated gets
    /// {"error": "why"}; the stream goes on.
    Forward,
    /// Inverse geometry. Reads JSON lines {"target": {"x", "y", "theta"}, "a0"?: [..],
    /// "method"?: "robust"|"newton", "alpha"?, "max_iterations"?, "tolerance"?,
    /// "objective"?: "first"|"least_energy" (default: least_energy with weight, else first), "all"?: bool, "deadline_ms"? (default 250, at
    /// most 10000), "weight"?, "gravity"? (as `forward`), "max_turns"? (weight > 200: full
    /// turns an answer may make, default 0 = loop-free)}; writes one line each:
    /// {"success", "a", "tip", "stable", "iterations", "residual", "energy", "position_error",
    /// "orientation_error", "stability_margin", "reason" (on failure), "termination"
    /// ("converged", "deadline", "no_stable_solution", ...), "starts", "complete" (false when
    /// the deadline cut a least-energy search or the list of all), "solutions" (with all),
    /// "base_wrench" and "tip_wrench" (as `forward`), with weight "turns" (full turns of the
    /// tangent: 0 for a loop-free cable)}. One deadline
    /// holds for the whole line, `all` included.
    ///
    /// Ends: "base_condition"? ("clamped" | "pinned") and "tip_condition"? ("clamped" |
    /// "pinned" | "free"), default "clamped". A pinned tip's target is {"x", "y"}; a free tip
    /// has no target (the equilibria of the cable hanging from its base; "tip_load"?: [fx, fy],
    /// a point force hanging from it, base frame, EI/L²). Such a line answers
    /// the least-energy stable rod found (default deadline 1000 ms) with "a", "base_angle"
    /// (θ(0): a pinned base's angle), "tip", "stable", "energy", "elastic_energy",
    /// "stability_margin", "turns", "base_wrench", "tip_wrench", "position_error",
    /// "base_condition", "tip_condition", "termination", "starts", "complete", "rejected"
    /// (equilibria found but unstable or looped), "reason" (on failure), "solutions" (with
    /// all: every stable rod found, least energy first).
    Solve {
        /// Print the solver's events (starts, iterations with residual and step, end) on
        /// stderr as JSON lines.
        #[arg(long)]
        verbose: bool,
    },
    /// 3-D forward map by numerical integration. Reads JSON lines {"a": [a1, .., a6],
    /// "stiffness"?: [c1, c2, c3], "rtol"?, "weight"?, "gravity"?, "deadline_ms"? (default
    /// 1000, at most 10000)}; writes {"tip": {"position": [x, y, z],
    /// "quaternion": [qx, qy, qz, qw]}, "jacobian" (6×6, body twists, rows ω1 ω2 ω3 v1 v2 v3),
    /// "stable", "energy", "stability_margin", "base_wrench" and "tip_wrench" ({"force": [fx, fy, fz],
    /// "moment": [mx, my, mz]}, each in its gripper's frame)}.
    Forward3d,
    /// 3-D inverse geometry. Reads JSON lines {"target": {"position": [..], "quaternion":
    /// [qx, qy, qz, qw]}, "a0"?: [6 numbers], "method"?, "alpha"?, "max_iterations"?,
    /// "tolerance"?, "objective"?, "all"?, "stiffness"?, "deadline_ms"? (default 1000),
    /// "weight"? (w = ρgAL³/EI, 0 ..= 1e4), "gravity"? (direction, default [0, 0, -1])};
    /// writes the fields of `solve` with 3-D a and tip. Long cables (weight > 200) are solved
    /// by multiple shooting from the nearest planar rod.
    Solve3d {
        /// Print the solver's events on stderr as JSON lines (as `solve --verbose`).
        #[arg(long)]
        verbose: bool,
    },
    /// Quasi-static motion: the rod follows its equilibrium branch as the tip gripper moves.
    /// Reads JSON lines {"target": {"x", "y", "theta"}, "a0"?: [a3, a4, a5] (first line: the
    /// rod held at the start; without it the first target is a fresh solve), "tolerance"?,
    /// "deadline_ms"?, "weight"?, "gravity"? (a line may change them: the held rod is carried)};
    /// writes the fields of `solve` plus "event": "none" | "snap" | "lost" | "buckle" (a0 = 0,
    /// the rod at rest, buckles on the first move: the least-energy rod found there),
    /// "progress" (the fraction of the move done: 1 when the target was reached), "held_a"
    /// (the rod held after the line: on a deadline the last equilibrium reached, kept for the
    /// next line) and, after a snap, "critical": {"x", "y", "theta"} (where the branch
    /// folded), "critical_a" and "energy_released". Lines with "base_condition" or
    /// "tip_condition" pinned or free (every line, the same ends) move a rod held by those
    /// ends and answer as `solve` does with them, plus "event" (docs/ends.md).
    Track {
        /// Draw the sequence of rods (snaps marked) into this SVG file at the end.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Quasi-static motion of the 3-D rod (with or without weight): `track`'s 3-D twin.
    /// Reads JSON lines {"target": {"position": [..], "quaternion": [qx, qy, qz, qw]}, "a0"?:
    /// [6 numbers] (first line: the rod held at the start; without it the first target is a
    /// fresh solve, least energy with weight), "tolerance"?, "deadline_ms"? (default 1000),
    /// "weight"?, "gravity"?, "stiffness"? (as `solve3d`; set by the first line: a later line
    /// may restate them, not change them)}; writes the fields of `solve3d` plus "event"
    /// ("none" | "snap" | "lost" | "buckle"), "progress", "held_a" and, after a snap,
    /// "critical", "critical_a" and "energy_released" (as `track`).
    Track3d,
    /// Plans a stable gripper path. Reads JSON lines {"start": [a3, a4, a5], "goal": {"x",
    /// "y", "theta"}, "obstacles"?: [{"type": "disc", "center": [x, y], "radius": r} |
    /// {"type": "polygon", "points": [[x, y], ...]}], "deadline_ms"? (default 500), "weight"?, "gravity"? (as `solve`)}; writes
    /// {"success", "rods": [[a3, a4, a5], ...], "gripper": [{"x", "y", "theta"}, ...],
    /// "min_margin", "reason" (on failure), "elapsed_ms"}. One roadmap serves every line.
    Plan {
        /// Draw the last plan (rods, gripper path, obstacles) into this SVG file.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Samples or draws rods: given parameters (--a, repeatable) or a target pose (--target:
    /// every distinct stable solution found). JSON lines of poses, or an SVG picture.
    Shape {
        /// Rod parameters "a3,a4,a5" (repeat to draw several rods).
        #[arg(long = "a", allow_hyphen_values = true)]
        params: Vec<String>,
        /// Target tip pose "x,y,theta": draw every stable solution found for it.
        #[arg(long, allow_hyphen_values = true)]
        target: Option<String>,
        /// Number of samples from base to tip (2 to 1000000).
        #[arg(long, default_value_t = 100)]
        samples: usize,
        /// Output format (default: svg when --output ends in .svg, else json).
        #[arg(long, value_enum)]
        format: Option<Format>,
        /// Write to this file instead of stdout.
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// Dimensionless weight w = ρgAL³/EI of the rods (default 0). With --target, the
        /// picture shows the heavy rods beside the weightless ones through the same grippers.
        #[arg(long, default_value_t = 0.0)]
        weight: f64,
        /// Direction of gravity "gx,gy" in the base frame (default 0,-1).
        #[arg(long, allow_hyphen_values = true, default_value = "0,-1")]
        gravity: String,
        /// How the base is held: clamped (default) or pinned (docs/ends.md).
        #[arg(long, default_value = "clamped")]
        base_condition: String,
        /// How the tip is held: clamped (default), pinned or free (a free tip draws the rods
        /// hanging from the base when no --a is given).
        #[arg(long, default_value = "clamped")]
        tip_condition: String,
        /// θ(0) of the --a rods at a pinned base (rad).
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        base_angle: f64,
        /// A point force "fx,fy" at a free tip (base frame, units of EI/L²).
        #[arg(long, allow_hyphen_values = true)]
        tip_load: Option<String>,
    },
    /// Measures every speed figure in one run: forward map, J, stability, shape against the
    /// paper's RK4 baseline (dt = 1e-4); the paper's Table 1 protocol for Newton; the robust
    /// solver and tracking; the 3-D rod's forward map and solver.
    Bench {
        /// Fewer rounds and samples (a smoke run, not for quoting).
        #[arg(long)]
        quick: bool,
        /// Inverse-geometry cases for the Table 1 protocol (JSON lines, as in the oracle; default:
        /// the repository's data/oracle/ig_public.jsonl).
        #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/oracle/ig_public.jsonl"))]
        ig_cases: PathBuf,
        /// Which parts to run.
        #[arg(long, value_enum, default_value = "all")]
        only: BenchPart,
    },
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum BenchPart {
    All,
    Forward,
    /// Latency tails on the box and the log-scale samples of issue 9.
    Tails,
    Ig,
    Spatial,
    /// Rods with weight against the weightless closed forms (issue 41's ratios).
    Weight,
    /// Time past their deadline of the requests that once overran it (issue 42).
    Deadlines,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum Format {
    Json,
    Svg,
}

fn parse_triple(text: &str, what: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "{what} needs three comma-separated numbers, got {text:?}"
        ));
    }
    let mut out = [0.0f64; 3];
    for (slot, part) in out.iter_mut().zip(&parts) {
        *slot = part
            .parse()
            .map_err(|_| format!("{what}: {part:?} is not a number"))?;
        if !slot.is_finite() {
            return Err(format!("{what}: {part:?} is not finite"));
        }
    }
    Ok(out)
}

/// Points per rod in an SVG picture: a 640-pixel drawing gains nothing from more, and the
/// picture's size stays bounded whatever `--samples` asks.
const SVG_POINTS: usize = 2000;

fn parse_gravity(weight: f64, text: &str) -> Result<Gravity, String> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("--gravity needs two comma-separated numbers, got {text:?}"))?;
    let [gx, gy] = parts[..] else {
        return Err(format!(
            "--gravity needs two comma-separated numbers, got {text:?}"
        ));
    };
    planar_cmds::gravity_of(Some(weight), Some([gx, gy]))
}

/// What `rod-ig shape` draws: rods by parameters or by target, with or without weight.
struct ShapeRequest<'a> {
    params: &'a [String],
    target: Option<&'a str>,
    samples: usize,
    gravity: Gravity,
}

/// `rod-ig shape`'s end-condition flags.
struct HeldFlags<'a> {
    base_condition: &'a str,
    tip_condition: &'a str,
    base_angle: f64,
    tip_load: Option<&'a str>,
}

impl HeldFlags<'_> {
    /// The ends the flags name, `None` when both are clamped (the paper's rod).
    fn ends(&self) -> Result<Option<rod_ig_core::ends::HeldEnds>, String> {
        let request = serde_json::json!({
            "base_condition": self.base_condition,
            "tip_condition": self.tip_condition,
        });
        held_cmds::held_ends_of(&request).map_err(|e| format!("--{}", e.replacen('_', "-", 1)))
    }

    /// `--tip-load "fx,fy"` (default none).
    fn parsed_tip_load(&self) -> Result<[f64; 2], String> {
        let Some(t) = self.tip_load else {
            return Ok([0.0; 2]);
        };
        t.split_once(',')
            .and_then(|(a, b)| Some([a.trim().parse().ok()?, b.trim().parse().ok()?]))
            .ok_or_else(|| format!("--tip-load must be \"fx,fy\" (got {t:?})"))
    }
}

/// `rod-ig shape` with pinned or free ends: the held forward map's rods (--a) or the held
/// search's stable equilibria (--target; a free tip: the rods hanging from the base).
fn held_shape_command(
    request: ShapeRequest,
    ends: rod_ig_core::ends::HeldEnds,
    flags: &HeldFlags,
    format: Option<Format>,
    output: Option<&PathBuf>,
) -> Result<(), String> {
    let params = request
        .params
        .iter()
        .map(|t| parse_triple(t, "--a"))
        .collect::<Result<Vec<_>, _>>()?;
    let target = match request.target {
        Some(t) => {
            let [x, y, theta] = parse_triple(t, "--target")?;
            Some(rod_ig_core::PlanarPose::new(x, y, theta))
        }
        None => None,
    };
    let tip_load = flags.parsed_tip_load()?;
    let held = held_cmds::HeldShapeRequest {
        ends,
        params: &params,
        base_angle: flags.base_angle,
        tip_load,
        target,
        samples: request.samples,
    };
    let rods = held_cmds::held_shapes(&held, &request.gravity)?;
    if rods.is_empty() {
        return Err("give --a a3,a4,a5 (repeatable) or --target x,y,theta".to_string());
    }
    let svg = match format {
        Some(f) => f == Format::Svg,
        None => output.is_some_and(|p| p.extension().is_some_and(|e| e == "svg")),
    };
    let text = held_shape_text(rods, ends, svg);
    match output {
        Some(path) => std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display())),
        None => io::stdout()
            .lock()
            .write_all(text.as_bytes())
            .map_err(|e| e.to_string()),
    }
}

/// Held rods as an SVG picture, or as JSON lines {"a", "base_angle", "stable", "poses"}.
fn held_shape_text(
    rods: Vec<held_cmds::HeldShape>,
    ends: rod_ig_core::ends::HeldEnds,
    svg: bool,
) -> String {
    if svg {
        let drawn: Vec<_> = rods
            .into_iter()
            .map(|r| svg::DrawnRod {
                label: format!(
                    "{} base, {} tip: a = ({:.3}, {:.3}, {:.3}), base angle {:.3}   energy {:.3}   {}",
                    ends.base().name(),
                    ends.tip().name(),
                    r.a[0],
                    r.a[1],
                    r.a[2],
                    r.base_angle,
                    r.energy,
                    if r.stable { "stable" } else { "unstable (dashed)" }
                ),
                dashed: !r.stable,
                poses: r.poses,
                muted: false,
            })
            .collect();
        svg::draw(&drawn, "rod-ig: rods held by pinned or free ends")
    } else {
        let mut text = String::new();
        for r in rods {
            let line = serde_json::json!({
                "a": r.a, "base_angle": r.base_angle, "stable": r.stable, "poses": r.poses,
            });
            text.push_str(&line.to_string());
            text.push('\n');
        }
        text
    }
}

fn shape_command(
    request: ShapeRequest,
    format: Option<Format>,
    output: Option<&PathBuf>,
) -> Result<(), String> {
    let ShapeRequest {
        params,
        target,
        samples,
        gravity,
    } = request;
    planar_cmds::check_samples(samples)?;
    // (a, gravity) of every rod drawn.
    let mut rods = Vec::new();
    for text in params {
        rods.push((parse_triple(text, "--a")?, gravity));
    }
    let mut title = String::from("rod-ig: planar Kirchhoff rods");
    if let Some(text) = target {
        let [x, y, theta] = parse_triple(text, "--target")?;
        title = format!("Stable rods reaching x = {x}, y = {y}, θ = {theta}");
        if !gravity.is_weightless() {
            title = format!(
                "Stable rods to x = {x}, y = {y}, θ = {theta}: weight {} (colour), none (grey)",
                gravity.weight()
            );
            for a in planar_cmds::all_stable_solutions(x, y, theta, &gravity)? {
                rods.push((a, gravity));
            }
        }
        for a in planar_cmds::all_stable_solutions(x, y, theta, &Gravity::NONE)? {
            rods.push((a, Gravity::NONE));
        }
    }
    if rods.is_empty() {
        return Err("give --a a3,a4,a5 (repeatable) or --target x,y,theta".to_string());
    }
    let format = format.unwrap_or(match output {
        Some(p) if p.extension().is_some_and(|e| e == "svg") => Format::Svg,
        _ => Format::Json,
    });
    let mut sink: Box<dyn Write> = match output {
        Some(path) => {
            Box::new(std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?)
        }
        None => Box::new(io::stdout().lock()),
    };
    let mut out = io::BufWriter::new(&mut sink);
    match format {
        // One line per rod, written pose by pose: memory does not grow with --samples.
        Format::Json => {
            for (a, g) in rods {
                planar_cmds::write_shape_line(&mut out, a, &g, samples)?;
            }
        }
        Format::Svg => {
            let mut drawn = Vec::with_capacity(rods.len());
            // Beside heavy rods, the weightless ones are drawn muted.
            let heavy = !gravity.is_weightless();
            for (a, g) in rods {
                let poses = planar_cmds::sample_shape(a, &g, samples.min(SVG_POINTS))?;
                let muted = heavy && g.is_weightless();
                drawn.push(planar_cmds::drawn_rod(a, &g, poses, muted));
            }
            out.write_all(svg::draw(&drawn, &title).as_bytes())
                .map_err(|e| e.to_string())?;
        }
    }
    out.flush().map_err(|e| e.to_string())
}

fn write_svg(path: &std::path::Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Builds the planar solver's atlases (≈ 0.45 s on two cores) before the first line is read:
/// a process that serves a stream pays it once at start-up, and every request's deadline then
/// counts from its own line (issue 24).
fn warm_up() {
    rod_ig_core::planar::ig::warm_up();
}

/// `rod-ig track`: the JSON-lines loop, then the sequence drawn into `svg`.
fn track(
    stdin: impl io::BufRead,
    stdout: impl Write,
    svg: Option<&std::path::Path>,
) -> Result<(), String> {
    warm_up();
    let mut tracking = motion_cmds::Tracking::new(svg.is_some());
    jsonl::run(stdin, stdout, |line| tracking.line(line)).map_err(|e| e.to_string())?;
    match svg {
        Some(path) => write_svg(
            path,
            &svg::draw_sequence(
                &tracking.drawn,
                &[],
                "rod-ig track: the rod following the gripper",
            ),
        ),
        None => Ok(()),
    }
}

/// `rod-ig plan`: the JSON-lines loop, then the last plan drawn into `svg`.
fn plan(
    stdin: impl io::BufRead,
    stdout: impl Write,
    svg: Option<&std::path::Path>,
) -> Result<(), String> {
    warm_up();
    let mut planning = motion_cmds::Planning::default();
    jsonl::run(stdin, stdout, |line| planning.line(line)).map_err(|e| e.to_string())?;
    match svg {
        Some(path) => write_svg(
            path,
            &svg::draw_sequence(
                &planning.drawn,
                &planning.obstacles,
                "rod-ig plan: a stable gripper path",
            ),
        ),
        None => Ok(()),
    }
}

/// `rod-ig bench`: the parts asked for, in order.
fn bench(quick: bool, ig_cases: &std::path::Path, only: BenchPart) {
    if matches!(only, BenchPart::All | BenchPart::Weight) {
        bench::weight(quick);
    }
    if matches!(only, BenchPart::All | BenchPart::Forward) {
        bench::planar_forward(quick);
    }
    if matches!(only, BenchPart::All | BenchPart::Tails) {
        bench_tails::run(quick);
    }
    if matches!(only, BenchPart::All | BenchPart::Ig) {
        bench::inverse_geometry(quick, ig_cases);
    }
    if matches!(only, BenchPart::All | BenchPart::Spatial) {
        bench::spatial(quick);
    }
    if matches!(only, BenchPart::All | BenchPart::Deadlines) {
        bench_deadlines::run(quick);
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let stdin = io::stdin().lock();
    let stdout = io::stdout().lock();
    let result = match cli.command {
        Command::Forward => {
            jsonl::run(stdin, stdout, held_cmds::forward_line).map_err(|e| e.to_string())
        }
        Command::Solve { verbose } => {
            warm_up();
            jsonl::run(stdin, stdout, |line| held_cmds::solve_line(line, verbose))
                .map_err(|e| e.to_string())
        }
        Command::Forward3d => {
            jsonl::run(stdin, stdout, held3d_cmds::forward3d_line).map_err(|e| e.to_string())
        }
        Command::Solve3d { verbose } => {
            // A rod with weight starts from the planar rods (their atlas, built outside the
            // first line's deadline as for `solve`).
            warm_up();
            jsonl::run(stdin, stdout, |line| {
                held3d_cmds::solve3d_line(line, verbose)
            })
            .map_err(|e| e.to_string())
        }
        Command::Track { svg } => track(stdin, stdout, svg.as_deref()),
        Command::Track3d => spatial_track::run(stdin, stdout, warm_up),
        Command::Plan { svg } => plan(stdin, stdout, svg.as_deref()),
        Command::Shape {
            params,
            target,
            samples,
            format,
            output,
            weight,
            gravity,
            base_condition,
            tip_condition,
            base_angle,
            tip_load,
        } => parse_gravity(weight, &gravity).and_then(|gravity| {
            let request = ShapeRequest {
                params: &params,
                target: target.as_deref(),
                samples,
                gravity,
            };
            let held = HeldFlags {
                base_condition: &base_condition,
                tip_condition: &tip_condition,
                base_angle,
                tip_load: tip_load.as_deref(),
            };
            match held.ends()? {
                Some(ends) => held_shape_command(request, ends, &held, format, output.as_ref()),
                None => shape_command(request, format, output.as_ref()),
            }
        }),
        Command::Bench {
            quick,
            ig_cases,
            only,
        } => {
            bench(quick, &ig_cases, only);
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A closed pipe (e.g. `| head`) is not an error worth a message.
        Err(e) if e.contains("Broken pipe") => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rod-ig: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triples_parse_and_reject() {
        assert_eq!(parse_triple("1, -2,3e1", "x").unwrap(), [1.0, -2.0, 30.0]);
        assert!(parse_triple("1,2", "x").is_err());
        assert!(parse_triple("1,b,3", "x")
            .unwrap_err()
            .contains("not a number"));
        assert!(parse_triple("1,inf,3", "x")
            .unwrap_err()
            .contains("not finite"));
    }

    #[test]
    fn cli_definition_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
