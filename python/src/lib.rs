//! The native half of the `rod_ig` Python package: batch loops over `rod_ig_core` on all cores
//! with the GIL released. Arrays come in C-contiguous and float64 with the batch flattened
//! (the Python half, `rod_ig/__init__.py`, checks shapes and dtypes, broadcasts and reshapes);
//! every output is allocated once and handed to numpy without a copy.

use nalgebra::{Vector3, Vector6};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyMemoryError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rod_ig_core::ends::{EndCondition, HeldEnds};
use rod_ig_core::plan::{Obstacle, PlanRequest, Planner as CorePlanner};
use rod_ig_core::planar::heavy::{self, held, Gravity, HeavyPlanar};
use rod_ig_core::planar::PlanarClosedForm;
use rod_ig_core::solver::{self, BranchEvent, BranchFollower, Method, Objective, SolveOptions};
use rod_ig_core::spatial::heavy::{self as heavy3, Gravity3};
use rod_ig_core::spatial::{self, SpatialPose, StabilityOptions, Stiffness};
use rod_ig_core::spatial::{HeavySpatial, Spatial};
use rod_ig_core::wrench::{self, GripperWrenches, PlanarWrench, SpatialWrench};
use rod_ig_core::{planar, PlanarParams, PlanarPose};
use std::time::Duration;

mod held3d;

/// Rods per block between two checks for Ctrl-C (the GIL is taken back for each check).
const FORWARD_BLOCK: usize = 1 << 14;

/// Runs `work(i)` for i in 0..n on `threads` threads in blocks, writing each result through
/// `write(i, result)` on the calling side of each block; Ctrl-C between blocks raises
/// KeyboardInterrupt. `work` runs with the GIL released.
fn batch<R: Send>(
    py: Python<'_>,
    n: usize,
    threads: usize,
    block: usize,
    work: impl Fn(usize) -> R + Sync,
    mut write: impl FnMut(usize, R),
) -> PyResult<()> {
    // No more threads than rods: an idle thread only costs its creation.
    let threads = threads.min(n).max(1);
    let mut start = 0;
    while start < n {
        let end = (start + block.max(threads)).min(n);
        let results: Option<Vec<R>> = py.detach(|| {
            let len = end - start;
            let per = len.div_ceil(threads);
            std::thread::scope(|s| {
                let handles: Vec<_> = (0..threads)
                    .map(|t| {
                        let lo = start + t * per;
                        let hi = (lo + per).min(end);
                        let work = &work;
                        s.spawn(move || (lo..hi).map(work).collect::<Vec<R>>())
                    })
                    .collect();
                // A worker that panicked has no rows: fail the call rather than shift the
                // rows of the others onto the wrong rods.
                let mut all = Vec::with_capacity(len);
                for h in handles {
                    all.extend(h.join().ok()?);
                }
                Some(all)
            })
        });
        let results = results.ok_or_else(|| {
            pyo3::exceptions::PyRuntimeError::new_err("a worker thread failed; no result returned")
        })?;
        for (k, r) in results.into_iter().enumerate() {
            write(start + k, r);
        }
        py.check_signals()?;
        start = end;
    }
    Ok(())
}

/// Most threads per core a batch uses: beyond it more threads only cost their creation.
const THREADS_PER_CORE: usize = 4;

/// The number of threads to use: `threads` if given (≥ 1, capped at [`THREADS_PER_CORE`] per
/// core), else every core. Negative or zero values raise `ValueError` naming `threads`.
fn thread_count(threads: Option<i64>) -> PyResult<usize> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    match threads {
        Some(t) if t < 1 => Err(PyValueError::new_err(format!(
            "threads must be >= 1, got {t}"
        ))),
        Some(t) => Ok(usize::try_from(t)
            .unwrap_or(usize::MAX)
            .min(THREADS_PER_CORE * cores)),
        None => Ok(cores),
    }
}

/// Rod i of a flattened (n, 3) array of planar parameters (a3, a4, a5).
fn planar_params(a: &[f64], i: usize) -> PlanarParams {
    PlanarParams::new(a[3 * i], a[3 * i + 1], a[3 * i + 2])
}

/// The (weight, direction) of each of n rods from the flattened `weight` (n) and `gravity`
/// (D n) arrays, each made a gravity by `make`; None when no weight was given (the weightless
/// models). Errors name the rod.
fn gravities<const D: usize, G>(
    n: usize,
    weight: Option<&PyReadonlyArray1<'_, f64>>,
    gravity: Option<&PyReadonlyArray1<'_, f64>>,
    default: [f64; D],
    make: impl Fn(f64, [f64; D]) -> Result<G, rod_ig_core::RodError>,
) -> PyResult<Option<Vec<G>>> {
    let Some(weight) = weight else {
        return Ok(None);
    };
    let w = weight.as_slice()?;
    let g = gravity.map(|g| g.as_slice()).transpose()?;
    if w.len() != n || g.is_some_and(|g| g.len() != D * n) {
        return Err(PyValueError::new_err(
            "weight and gravity must broadcast against the batch",
        ));
    }
    (0..n)
        .map(|i| {
            let dir = g.map_or(default, |g| std::array::from_fn(|k| g[D * i + k]));
            make(w[i], dir)
                .map_err(|e| PyValueError::new_err(format!("weight/gravity of rod {i}: {e}")))
        })
        .collect::<PyResult<Vec<_>>>()
        .map(Some)
}

/// [`gravities`] of planar rods (default direction −y).
fn gravities2(
    n: usize,
    weight: Option<&PyReadonlyArray1<'_, f64>>,
    gravity: Option<&PyReadonlyArray1<'_, f64>>,
) -> PyResult<Option<Vec<Gravity>>> {
    gravities(n, weight, gravity, [0.0, -1.0], Gravity::new)
}

fn f64_out<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    v.into_pyarray(py)
}

/// Outputs above this size (bytes) are checked against the memory available first.
const LARGE_OUTPUT: u64 = 64 << 20;

/// Memory the machine has available (Linux's MemAvailable), if known.
fn available_bytes() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb: u64 = info
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb.saturating_mul(1024))
}

/// An output of `rows × per_row` values, each `fill`, sized before it is allocated: an
/// impossible size raises `MemoryError` naming it (issue 42: it aborted the interpreter).
fn buffer<T: Clone>(rows: usize, per_row: usize, fill: T) -> PyResult<Vec<T>> {
    let too_big = || {
        PyMemoryError::new_err(format!(
            "cannot allocate the output: {rows} rows × {per_row} values of {} bytes",
            std::mem::size_of::<T>()
        ))
    };
    let len = rows.checked_mul(per_row).ok_or_else(too_big)?;
    // Beyond the memory the machine has free the allocation may "succeed" (overcommit) and
    // the process be killed while it fills: refused first.
    let bytes = (len as u64).saturating_mul(std::mem::size_of::<T>() as u64);
    if bytes > LARGE_OUTPUT && available_bytes().is_some_and(|free| bytes > free) {
        return Err(too_big());
    }
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| too_big())?;
    // Filled a slice at a time with a check for Ctrl-C between slices: filling gigabytes
    // takes seconds (the first touch of every page), and a KeyboardInterrupt must not wait
    // for it (a 20-million-rod `forward` answered SIGINT after 1.4–7 s, all of it here).
    while v.len() < len {
        let next = (v.len() + FILL_SLICE).min(len);
        v.resize(next, fill.clone());
        Python::attach(|py| py.check_signals())?;
    }
    Ok(v)
}

/// Values an output is filled with between two checks for Ctrl-C (8 MB of f64).
const FILL_SLICE: usize = 1 << 20;

/// Planar forward map of n rods `a` (flattened (n, 3)): tip (x, y, θ unwrapped), J (rows x, y,
/// θ; columns a3, a4, a5), stable, margin, uncertain, condition, energy. A rod that cannot be
/// evaluated gets NaN, stable False, uncertain True.
#[pyfunction]
#[pyo3(signature = (a, threads=None, weight=None, gravity=None))]
fn forward<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = a.as_slice()?;
    let n = a.len() / 3;
    let threads = thread_count(threads)?;
    let g = gravities2(n, weight.as_ref(), gravity.as_ref())?;
    let mut elastic = buffer(n, 1, f64::NAN)?;
    let mut tip = buffer(n, 3, f64::NAN)?;
    let mut jac = buffer(n, 9, f64::NAN)?;
    let mut stable = buffer(n, 1, false)?;
    let mut margin = buffer(n, 1, f64::NAN)?;
    let mut uncertain = buffer(n, 1, true)?;
    let mut energy = buffer(n, 1, f64::NAN)?;
    let mut cond = buffer(n, 1, f64::NAN)?;
    let (mut base_w, mut tip_w) = (buffer(n, 3, f64::NAN)?, buffer(n, 3, f64::NAN)?);
    batch(
        py,
        n,
        threads,
        FORWARD_BLOCK,
        |i| {
            let (ai, gi) = (
                planar_params(a, i),
                g.as_ref().map_or(Gravity::NONE, |g| g[i]),
            );
            let e = heavy::evaluate(&ai, &gi).ok()?;
            Some((e, planar_wrenches_of(&ai, &gi, &e.tip)))
        },
        |i, e| {
            if let Some((e, w)) = e {
                if let Some([b, t]) = w.as_ref().map(planar_rows) {
                    base_w[3 * i..3 * i + 3].copy_from_slice(&b);
                    tip_w[3 * i..3 * i + 3].copy_from_slice(&t);
                }
                elastic[i] = e.elastic_energy;
                tip[3 * i..3 * i + 3].copy_from_slice(&[e.tip.x, e.tip.y, e.tip.theta]);
                for r in 0..3 {
                    for c in 0..3 {
                        jac[9 * i + 3 * r + c] = e.jacobian[(r, c)];
                    }
                }
                stable[i] = e.stability.stable;
                margin[i] = e.stability.margin;
                uncertain[i] = e.stability.uncertain;
                energy[i] = e.energy;
                cond[i] = e.condition;
            }
        },
    )?;
    let d = PyDict::new(py);
    d.set_item("tip", f64_out(py, tip))?;
    d.set_item("condition", f64_out(py, cond))?;
    d.set_item("jacobian", f64_out(py, jac))?;
    d.set_item("stable", stable.into_pyarray(py))?;
    d.set_item("margin", f64_out(py, margin))?;
    d.set_item("uncertain", uncertain.into_pyarray(py))?;
    d.set_item("energy", f64_out(py, energy))?;
    d.set_item("elastic_energy", f64_out(py, elastic))?;
    d.set_item("base_wrench", f64_out(py, base_w))?;
    d.set_item("tip_wrench", f64_out(py, tip_w))?;
    Ok(d)
}

/// The wrenches n planar rods `a` (flattened (n, 3)) exert on their grippers
/// (`rod_ig_core::wrench`: each in its gripper's frame, as a wrist sensor reads it): a dict of
/// "base" and "tip", each flattened (n, 3) rows (fx, fy, moment). NaN where a rod cannot be
/// evaluated.
#[pyfunction]
#[pyo3(signature = (a, threads=None, weight=None, gravity=None))]
fn wrenches<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = a.as_slice()?;
    let n = a.len() / 3;
    let threads = thread_count(threads)?;
    let g = gravities2(n, weight.as_ref(), gravity.as_ref())?;
    let mut base = buffer(n, 3, f64::NAN)?;
    let mut tip = buffer(n, 3, f64::NAN)?;
    batch(
        py,
        n,
        threads,
        FORWARD_BLOCK,
        |i| {
            let gi = g.as_ref().map_or(Gravity::NONE, |g| g[i]);
            heavy::wrenches(&planar_params(a, i), &gi).ok()
        },
        |i, w| {
            if let Some(w) = w {
                let [b, t] = planar_rows(&w);
                base[3 * i..3 * i + 3].copy_from_slice(&b);
                tip[3 * i..3 * i + 3].copy_from_slice(&t);
            }
        },
    )?;
    let d = PyDict::new(py);
    d.set_item("base", f64_out(py, base))?;
    d.set_item("tip", f64_out(py, tip))?;
    Ok(d)
}

/// A planar wrench pair as two rows (fx, fy, moment).
fn planar_rows(w: &GripperWrenches<PlanarWrench>) -> [[f64; 3]; 2] {
    let row = |x: &PlanarWrench| [x.force[0], x.force[1], x.moment];
    [row(&w.base), row(&w.tip)]
}

/// A 3-D wrench pair as two rows (fx, fy, fz, mx, my, mz).
fn spatial_rows(w: &GripperWrenches<SpatialWrench>) -> [[f64; 6]; 2] {
    let row = |x: &SpatialWrench| {
        let (f, m) = (x.force, x.moment);
        [f[0], f[1], f[2], m[0], m[1], m[2]]
    };
    [row(&w.base), row(&w.tip)]
}

/// The planar wrenches of a rod already evaluated: without weight from its tip (the moment
/// balance, no second evaluation), with weight by `heavy::wrenches`.
fn planar_wrenches_of(
    a: &PlanarParams,
    g: &Gravity,
    tip: &PlanarPose,
) -> Option<GripperWrenches<PlanarWrench>> {
    if g.is_weightless() {
        let k1 = wrench::weightless_tip_curvature(a, tip);
        Some(wrench::planar(a, tip, [a[1], a[2]], k1))
    } else {
        heavy::wrenches(a, g).ok()
    }
}

/// Full turns of the tangent along n planar rods `a` (flattened (n, 3)) under their weight
/// (`heavy::cable::turns_of` on the shape's check samples: 0 for a loop-free cable); -1 where a
/// rod cannot be evaluated.
#[pyfunction]
#[pyo3(signature = (a, threads=None, weight=None, gravity=None))]
fn turns<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let a = a.as_slice()?;
    let n = a.len() / 3;
    let threads = thread_count(threads)?;
    let g = gravities2(n, weight.as_ref(), gravity.as_ref())?;
    let mut out = buffer(n, 1, -1i64)?;
    batch(
        py,
        n,
        threads,
        FORWARD_BLOCK,
        |i| {
            let gi = g.as_ref().map_or(Gravity::NONE, |g| g[i]);
            heavy::shape(&planar_params(a, i), &gi, heavy::cable::SHAPE_CHECK_SAMPLES)
                .ok()
                .map(|s| heavy::cable::turns_of(&s))
        },
        |i, t| {
            if let Some(t) = t {
                out[i] = i64::from(t);
            }
        },
    )?;
    Ok(out.into_pyarray(py))
}

/// The wrenches n 3-D rods `a` (flattened (n, 6)) exert on their grippers: "base" and "tip",
/// each flattened (n, 6) rows (fx, fy, fz, mx, my, mz) in its gripper's frame. NaN where a rod
/// cannot be evaluated.
#[pyfunction]
#[pyo3(signature = (a, stiffness=(1.0, 1.0, 1.0), threads=None, weight=None, gravity=None))]
fn wrenches3d<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    stiffness: (f64, f64, f64),
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = a.as_slice()?;
    let n = a.len() / 6;
    let k = stiffness_of(stiffness)?;
    let threads = thread_count(threads)?;
    let g = gravities3(n, weight.as_ref(), gravity.as_ref())?;
    let mut base = buffer(n, 6, f64::NAN)?;
    let mut tip = buffer(n, 6, f64::NAN)?;
    batch(
        py,
        n,
        threads,
        SOLVE_BLOCK,
        |i| {
            let ai = Vector6::from_column_slice(&a[6 * i..6 * i + 6]);
            let gi = g.as_ref().map_or(heavy3::Gravity3::NONE, |g| g[i]);
            heavy3::wrenches(&ai, &k, &gi).ok()
        },
        |i, w| {
            if let Some(w) = w {
                let [b, t] = spatial_rows(&w);
                base[6 * i..6 * i + 6].copy_from_slice(&b);
                tip[6 * i..6 * i + 6].copy_from_slice(&t);
            }
        },
    )?;
    let d = PyDict::new(py);
    d.set_item("base", f64_out(py, base))?;
    d.set_item("tip", f64_out(py, tip))?;
    Ok(d)
}

/// Stability verdicts of n rods `a` (flattened (n, 3)) by `planar::stability_verdict`: true
/// iff the rod is established stable (what `forward` gives as `stable`), without the margin
/// it refines. A rod that cannot be evaluated gets false.
#[pyfunction]
#[pyo3(signature = (a, threads=None, weight=None, gravity=None))]
fn is_stable<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let a = a.as_slice()?;
    let n = a.len() / 3;
    let threads = thread_count(threads)?;
    let g = gravities2(n, weight.as_ref(), gravity.as_ref())?;
    let mut stable = buffer(n, 1, false)?;
    batch(
        py,
        n,
        threads,
        FORWARD_BLOCK,
        |i| {
            let rod = planar_params(a, i);
            match &g {
                Some(g) => heavy::stability(&rod, &g[i]).is_ok_and(|r| r.stable),
                None => planar::stability_verdict(&rod).is_ok_and(|v| v.is_stable()),
            }
        },
        |i, s| stable[i] = s,
    )?;
    Ok(stable.into_pyarray(py))
}

/// Shapes of n rods: `samples` poses (x, y, θ) each from the base to the tip (NaN for a rod
/// that cannot be evaluated).
#[pyfunction]
#[pyo3(signature = (a, samples, threads=None, weight=None, gravity=None))]
fn shape<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    samples: usize,
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a = a.as_slice()?;
    let n = a.len() / 3;
    let threads = thread_count(threads)?;
    let g = gravities2(n, weight.as_ref(), gravity.as_ref())?;
    let mut out = buffer(n, samples.saturating_mul(3), f64::NAN)?;
    batch(
        py,
        n,
        threads,
        (FORWARD_BLOCK / samples.max(1)).max(1),
        |i| match &g {
            Some(g) => heavy::shape(&planar_params(a, i), &g[i], samples).ok(),
            None => planar::PlanarRod::new(&planar_params(a, i))
                .ok()
                .map(|rod| rod.shape(samples)),
        },
        |i, poses| {
            for (k, p) in poses.into_iter().flatten().enumerate() {
                let o = 3 * (samples * i + k);
                out[o..o + 3].copy_from_slice(&[p.x, p.y, p.theta]);
            }
        },
    )?;
    Ok(f64_out(py, out))
}

/// Solver options from the keyword arguments of `solve`/`solve3d` (defaults: the model's).
#[allow(clippy::too_many_arguments)]
fn options<const N: usize>(
    defaults: SolveOptions<nalgebra::SVector<f64, N>>,
    method: &str,
    objective: &str,
    deadline_ms: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<u32>,
    alpha: Option<f64>,
    has_a0: bool,
) -> PyResult<SolveOptions<nalgebra::SVector<f64, N>>> {
    let mut o = defaults;
    o.method = match method {
        "robust" => Method::Robust,
        "newton" => Method::Newton,
        m => {
            return Err(PyValueError::new_err(format!(
                "method must be 'robust' or 'newton', got {m:?}"
            )))
        }
    };
    o.objective = match objective {
        "first" => Objective::FirstFound,
        "least_energy" => Objective::LeastEnergy,
        m => {
            return Err(PyValueError::new_err(format!(
                "objective must be 'first' or 'least_energy', got {m:?}"
            )))
        }
    };
    if let Some(ms) = deadline_ms {
        if !(ms.is_finite() && ms > 0.0 && ms <= solver::MAX_DEADLINE.as_secs_f64() * 1e3) {
            return Err(PyValueError::new_err(format!(
                "deadline_ms must be in (0, {}], got {ms}",
                solver::MAX_DEADLINE.as_millis()
            )));
        }
        o.deadline = Duration::from_secs_f64(ms / 1e3);
    }
    if let Some(t) = tolerance {
        o.tolerance = t;
    }
    if let Some(m) = max_iterations {
        o.max_iterations = m;
    }
    if let Some(a) = alpha {
        o.alpha = a;
    }
    // The solver's own check, with its message, before any work.
    solver::check_options(&o).map_err(|e| PyValueError::new_err(e.to_string()))?;
    if o.method == Method::Newton && !has_a0 {
        return Err(PyValueError::new_err("method 'newton' needs a0"));
    }
    Ok(o)
}

/// The per-target outputs of a batch solve.
struct SolveOut {
    success: Vec<bool>,
    a: Vec<f64>,
    termination: Vec<&'static str>,
    /// Why a solve failed ("" when it succeeded), scipy's `message`.
    reason: Vec<String>,
    iterations: Vec<u32>,
    margin: Vec<f64>,
    energy: Vec<f64>,
    position_error: Vec<f64>,
    orientation_error: Vec<f64>,
    /// Starts tried (0 where the solve failed).
    starts: Vec<u32>,
    /// The search ran to its end (a least-energy search or `all` list not cut by the deadline).
    complete: Vec<bool>,
    solutions: Vec<Vec<f64>>,
}

impl SolveOut {
    fn new(n: usize, dim: usize) -> PyResult<Self> {
        Ok(SolveOut {
            success: buffer(n, 1, false)?,
            a: buffer(n, dim, f64::NAN)?,
            termination: buffer(n, 1, "")?,
            reason: buffer(n, 1, String::new())?,
            iterations: buffer(n, 1, 0)?,
            margin: buffer(n, 1, f64::NAN)?,
            energy: buffer(n, 1, f64::NAN)?,
            position_error: buffer(n, 1, f64::NAN)?,
            orientation_error: buffer(n, 1, f64::NAN)?,
            starts: buffer(n, 1, 0)?,
            complete: buffer(n, 1, true)?,
            solutions: Vec::new(),
        })
    }

    fn write<P: AsRef<[f64]>, X>(
        &mut self,
        i: usize,
        r: &Result<solver::Solution<P, X>, solver::Failure<P>>,
    ) {
        match r {
            Ok(s) => {
                let a = s.a.as_ref();
                let dim = a.len();
                self.success[i] = true;
                self.a[dim * i..dim * (i + 1)].copy_from_slice(a);
                self.termination[i] = solver::Termination::Converged.as_str();
                self.iterations[i] = s.iterations;
                self.margin[i] = s.stability_margin;
                self.energy[i] = s.energy;
                self.position_error[i] = s.position_error;
                self.orientation_error[i] = s.orientation_error;
                self.starts[i] = s.starts;
                self.complete[i] = s.complete;
            }
            Err(f) => {
                self.termination[i] = f.termination().as_str();
                self.reason[i] = f.reason.to_string();
                self.iterations[i] = f.iterations;
                self.starts[i] = f.starts;
            }
        }
    }

    fn into_dict(self, py: Python<'_>, all: bool) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("success", self.success.into_pyarray(py))?;
        d.set_item("a", f64_out(py, self.a))?;
        d.set_item("termination", PyList::new(py, self.termination)?)?;
        d.set_item("reason", PyList::new(py, self.reason)?)?;
        d.set_item("iterations", self.iterations.into_pyarray(py))?;
        d.set_item("margin", f64_out(py, self.margin))?;
        d.set_item("energy", f64_out(py, self.energy))?;
        d.set_item("position_error", f64_out(py, self.position_error))?;
        d.set_item("orientation_error", f64_out(py, self.orientation_error))?;
        d.set_item("starts", self.starts.into_pyarray(py))?;
        d.set_item("complete", self.complete.into_pyarray(py))?;
        if all {
            let list = PyList::empty(py);
            for s in self.solutions {
                list.append(f64_out(py, s))?;
            }
            d.set_item("solutions", list)?;
        }
        Ok(d)
    }
}

/// Largest accepted `max_turns` (as the CLI's).
const MAX_TURNS: u32 = 100;

/// Targets per block of a batch solve between two checks for Ctrl-C (a solve takes µs to ms).
const SOLVE_BLOCK: usize = 256;

/// Planar inverse geometry of n targets (x, y, θ) (flattened), optional starts `a0`.
/// The ends a `solve_held` call names and the width of its targets (0 for a free tip, 2
/// pinned, 3 clamped), checked against `targets`; refusals name the argument.
fn held_request(
    n: usize,
    t: Option<&[f64]>,
    base_condition: &str,
    tip_condition: &str,
    max_turns: u32,
) -> PyResult<(HeldEnds, usize)> {
    let ends = ends_of(base_condition, tip_condition)?;
    let width = tip_width(ends);
    match (width, t) {
        (0, Some(_)) => {
            return Err(PyValueError::new_err(
                "targets: a free tip has no target (the cable hangs from its base)",
            ))
        }
        (w, Some(t)) if t.len() != w * n => {
            return Err(PyValueError::new_err(format!(
                "targets must have shape (..., {w}) for a {tip_condition} tip"
            )))
        }
        (w, None) if w > 0 => {
            return Err(PyValueError::new_err(format!(
                "targets: a {tip_condition} tip needs targets of shape (..., {w})"
            )))
        }
        _ => {}
    }
    if max_turns > MAX_TURNS {
        return Err(PyValueError::new_err(format!(
            "max_turns must be in [0, {MAX_TURNS}], got {max_turns}"
        )));
    }
    Ok((ends, width))
}

/// Components of a target for the tip `ends` hold: 0 free, 2 pinned (x, y), 3 clamped.
fn tip_width(ends: HeldEnds) -> usize {
    match ends.tip() {
        EndCondition::Free => 0,
        EndCondition::Pinned => 2,
        EndCondition::Clamped => 3,
    }
}

/// The ends named by `base_condition` and `tip_condition` (refusals name the argument).
fn ends_of(base_condition: &str, tip_condition: &str) -> PyResult<HeldEnds> {
    let condition = |field: &str, v: &str| {
        v.parse::<EndCondition>().map_err(|_| {
            PyValueError::new_err(format!(
                "{field} must be \"clamped\", \"pinned\" or \"free\", got {v:?}"
            ))
        })
    };
    HeldEnds::new(
        condition("base_condition", base_condition)?,
        condition("tip_condition", tip_condition)?,
    )
    .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The forward map of n rods `a` (flattened (n, 3)) held by (`base_condition`,
/// `tip_condition`), each leaving its base at `base_angle[i]` (`held::evaluate`): the keys of
/// [`forward`] (margin: μ/μ₀ of the second variation with the natural conditions; J's first
/// column ∂/∂θ(0) at a pinned base) plus `base_angle` and `turns`. A rod the conditions refuse
/// (a moment at a pinned base, a force at a free tip other than w ĝ + `tip_load`) raises
/// ValueError naming the argument.
#[pyfunction]
#[pyo3(signature = (a, base_angle, base_condition, tip_condition, weight=None, gravity=None,
                    tip_load=None))]
#[allow(clippy::too_many_arguments)]
fn forward_held<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    base_angle: PyReadonlyArray1<'py, f64>,
    base_condition: &str,
    tip_condition: &str,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
    tip_load: Option<(f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let (a, angles) = (a.as_slice()?, base_angle.as_slice()?);
    let n = a.len() / 3;
    let ends = ends_of(base_condition, tip_condition)?;
    let g = gravities2(n, weight.as_ref(), gravity.as_ref())?;
    let load = tip_load.map_or([0.0; 2], |(x, y)| [x, y]);
    let mut out: [Vec<f64>; 10] = std::array::from_fn(|_| Vec::with_capacity(n));
    let (mut stable, mut uncertain) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for i in 0..n {
        let gi = g.as_ref().map_or(Gravity::NONE, |g| g[i]);
        let e = held::evaluate(angles[i], &planar_params(a, i), &gi, ends, load)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let s = &e.solution;
        let w = s.wrenches();
        let [b, t] = planar_rows(&w);
        out[0].extend([s.tip.x, s.tip.y, s.tip.theta]);
        out[1].extend(e.jacobian.transpose().iter());
        out[2].push(s.stability.normalised());
        out[3].push(s.energy);
        out[4].push(s.elastic_energy);
        out[5].extend(b);
        out[6].extend(t);
        out[7].push(e.condition);
        out[8].push(s.base_angle);
        out[9].push(s.turns as f64);
        stable.push(e.stable());
        uncertain.push(e.uncertain());
    }
    let d = PyDict::new(py);
    let [tip, jac, margin, energy, elastic, base_w, tip_w, cond, angle, turns] = out;
    for (key, v) in [
        ("tip", tip),
        ("jacobian", jac),
        ("margin", margin),
        ("energy", energy),
        ("elastic_energy", elastic),
        ("base_wrench", base_w),
        ("tip_wrench", tip_w),
        ("condition", cond),
        ("base_angle", angle),
        ("turns", turns),
    ] {
        d.set_item(key, f64_out(py, v))?;
    }
    d.set_item("stable", stable.into_pyarray(py))?;
    d.set_item("uncertain", uncertain.into_pyarray(py))?;
    Ok(d)
}

/// One held-ends answer, flattened for the batch arrays.
struct HeldRow {
    found: Result<held::HeldSearch, String>,
    target: Option<PlanarPose>,
    /// The best rod's shape, `samples` poses (x, y, θ) base to tip (empty when not asked or
    /// when there is no rod).
    shape: Vec<f64>,
}

/// Pinned and free ends (issue 52): for each of `n` rods, the least-energy stable
/// equilibrium held by (`base_condition`, `tip_condition`) through its target (flattened
/// (n, 2) positions for a pinned tip, (n, 3) poses for a clamped one, none for a free tip),
/// and with `all` every stable one found. Returns a dict of flat arrays.
#[pyfunction]
#[pyo3(signature = (n, targets=None, base_condition="clamped", tip_condition="clamped",
                    weight=None, gravity=None, all=false, deadline_ms=None, max_turns=0,
                    threads=None, tip_load=None, samples=0))]
#[allow(clippy::too_many_arguments)]
fn solve_held<'py>(
    py: Python<'py>,
    n: usize,
    targets: Option<PyReadonlyArray1<'py, f64>>,
    base_condition: &str,
    tip_condition: &str,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
    all: bool,
    deadline_ms: Option<f64>,
    max_turns: u32,
    threads: Option<i64>,
    tip_load: Option<[f64; 2]>,
    samples: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if samples == 1 || samples > 1_000_000 {
        return Err(PyValueError::new_err(format!(
            "samples must be 0 (no shape) or in [2, 1000000], got {samples}"
        )));
    }
    let t = targets.as_ref().map(|t| t.as_slice()).transpose()?;
    let tip_load = tip_load.unwrap_or([0.0; 2]);
    let (ends, width) = held_request(n, t, base_condition, tip_condition, max_turns)?;
    let gravities = gravities2(n, weight.as_ref(), gravity.as_ref())?;
    let options = held_options(deadline_ms, max_turns)?;
    let target_of = |i: usize| {
        t.map(|t| match width {
            2 => PlanarPose::new(t[2 * i], t[2 * i + 1], 0.0),
            _ => PlanarPose::new(t[3 * i], t[3 * i + 1], t[3 * i + 2]),
        })
    };
    rod_ig_core::planar::ig::warm_up();
    let mut rows: Vec<Option<HeldRow>> = (0..n).map(|_| None).collect();
    batch(
        py,
        n,
        thread_count(threads)?,
        FORWARD_BLOCK,
        |i| {
            let g = gravities.as_ref().map_or(Gravity::NONE, |g| g[i]);
            let target = target_of(i);
            let found =
                held::equilibria_with_tip_load(ends, &g, tip_load, target.as_ref(), &options)
                    .map_err(|e| e.to_string());
            let shape = match (&found, samples) {
                (Ok(f), 2..) => f
                    .solutions
                    .first()
                    .and_then(|s| s.cable.shape(samples).ok())
                    .map(|p| p.iter().flat_map(|q| [q.x, q.y, q.theta]).collect())
                    .unwrap_or_default(),
                _ => Vec::new(),
            };
            HeldRow {
                found,
                target,
                shape,
            }
        },
        |i, r| rows[i] = Some(r),
    )?;
    held_dict(py, ends, rows.into_iter().flatten().collect(), all)
}

/// The options of a held-ends search: `deadline_ms` (default 1 s) and `max_turns`.
fn held_options(deadline_ms: Option<f64>, max_turns: u32) -> PyResult<planar::ig::SolveOptions> {
    let deadline = match deadline_ms {
        Some(ms) if ms.is_finite() && ms > 0.0 && ms <= 1e7 => Duration::from_secs_f64(ms / 1e3),
        Some(ms) => {
            return Err(PyValueError::new_err(format!(
                "deadline_ms must be a positive number of milliseconds, got {ms}"
            )))
        }
        None => Duration::from_millis(1000),
    };
    Ok(planar::ig::SolveOptions {
        deadline,
        max_turns,
        ..planar::ig::SolveOptions::default()
    })
}

/// Quasi-static motion of a rod held by pinned or free ends (`held::step`): the rod follows
/// its branch as the tip gripper moves (event "none"), is searched afresh where the branch
/// ends ("snap"), or is lost ("lost").
#[pyclass(module = "rod_ig._rod_ig")]
struct HeldTracker {
    ends: HeldEnds,
    width: usize,
    gravity: Gravity,
    tip_load: [f64; 2],
    options: planar::ig::SolveOptions,
    held: Option<held::HeldSolution>,
}

#[pymethods]
impl HeldTracker {
    #[new]
    #[pyo3(signature = (base_condition, tip_condition, deadline_ms=None, weight=0.0,
                        gravity=(0.0, -1.0), max_turns=0, tip_load=None))]
    fn new(
        base_condition: &str,
        tip_condition: &str,
        deadline_ms: Option<f64>,
        weight: f64,
        gravity: (f64, f64),
        max_turns: u32,
        tip_load: Option<[f64; 2]>,
    ) -> PyResult<Self> {
        let ends = ends_of(base_condition, tip_condition)?;
        if max_turns > MAX_TURNS {
            return Err(PyValueError::new_err(format!(
                "max_turns must be in [0, {MAX_TURNS}], got {max_turns}"
            )));
        }
        let width = tip_width(ends);
        let gravity = Gravity::new(weight, [gravity.0, gravity.1])
            .map_err(|e| PyValueError::new_err(format!("weight/gravity: {e}")))?;
        rod_ig_core::planar::ig::warm_up();
        Ok(HeldTracker {
            ends,
            width,
            gravity,
            tip_load: tip_load.unwrap_or([0.0; 2]),
            options: held_options(deadline_ms, max_turns)?,
            held: None,
        })
    }

    /// Moves the tip gripper to `target` ((x, y, θ) clamped, (x, y) pinned, None free); the
    /// keys of `solve_held` for one rod plus `event`.
    #[pyo3(name = "move", signature = (target=None))]
    fn move_to<'py>(
        &mut self,
        py: Python<'py>,
        target: Option<Vec<f64>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let tip = self.ends.tip();
        let pose = match (self.width, target) {
            (0, None) => None,
            (0, Some(_)) => {
                return Err(PyValueError::new_err(
                    "target: a free tip has no target (the cable hangs from its base)",
                ))
            }
            (2, Some(t)) if t.len() == 2 => Some(PlanarPose::new(t[0], t[1], 0.0)),
            (3, Some(t)) if t.len() == 3 => Some(PlanarPose::new(t[0], t[1], t[2])),
            (w, _) => {
                return Err(PyValueError::new_err(format!(
                    "target must have {w} components for a {tip} tip"
                )))
            }
        };
        if pose.is_some_and(|p| !p.is_finite()) {
            return Err(PyValueError::new_err("target must be finite"));
        }
        let (ends, g, load, o) = (self.ends, self.gravity, self.tip_load, self.options);
        let held = self.held.take();
        let stepped = py.detach(|| held::step(held.as_ref(), ends, &g, load, pose.as_ref(), &o));
        let (event, found) = match stepped {
            Ok((event, found)) => (event, Ok(found)),
            Err(e @ held::HeldError::Target { .. }) => {
                self.held = held;
                return Err(PyValueError::new_err(e.to_string()));
            }
            Err(e) => (held::HeldEvent::Lost, Err(e.to_string())),
        };
        self.held = found
            .as_ref()
            .ok()
            .and_then(|f| f.solutions.first().cloned());
        let row = HeldRow {
            found,
            target: pose,
            shape: Vec::new(),
        };
        let d = held_dict(py, ends, vec![row], false)?;
        d.set_item("event", event.as_str())?;
        Ok(d)
    }

    /// The rod held now, (a3, a4, a5, base angle), or None.
    #[getter]
    fn rod(&self) -> Option<[f64; 4]> {
        self.held
            .as_ref()
            .map(|h| [h.a[0], h.a[1], h.a[2], h.base_angle])
    }
}

/// The columns of [`solve_held`]'s answer, one row per rod (NaN where it failed).
struct HeldColumns {
    a: Vec<f64>,
    tip: Vec<f64>,
    base_angle: Vec<f64>,
    energy: Vec<f64>,
    elastic: Vec<f64>,
    margin: Vec<f64>,
    position_error: Vec<f64>,
    turns: Vec<i64>,
    base_wrench: Vec<f64>,
    tip_wrench: Vec<f64>,
    success: Vec<bool>,
}

impl HeldColumns {
    fn new(n: usize) -> Self {
        let nan = f64::NAN;
        Self {
            a: vec![nan; 3 * n],
            tip: vec![nan; 3 * n],
            base_angle: vec![nan; n],
            energy: vec![nan; n],
            elastic: vec![nan; n],
            margin: vec![nan; n],
            position_error: vec![nan; n],
            turns: vec![-1; n],
            base_wrench: vec![nan; 3 * n],
            tip_wrench: vec![nan; 3 * n],
            success: vec![false; n],
        }
    }

    fn set(&mut self, i: usize, s: &held::HeldSolution, target: Option<PlanarPose>) {
        self.success[i] = true;
        self.a[3 * i..3 * i + 3].copy_from_slice(s.a.as_slice());
        self.tip[3 * i..3 * i + 3].copy_from_slice(&[s.tip.x, s.tip.y, s.tip.theta]);
        self.base_angle[i] = s.base_angle;
        self.energy[i] = s.energy;
        self.elastic[i] = s.elastic_energy;
        self.margin[i] = s.stability.normalised();
        self.turns[i] = i64::from(s.turns);
        self.position_error[i] = target.map_or(f64::NAN, |t| (s.tip.x - t.x).hypot(s.tip.y - t.y));
        let w = s.wrenches();
        self.base_wrench[3 * i..3 * i + 3].copy_from_slice(&[
            w.base.force[0],
            w.base.force[1],
            w.base.moment,
        ]);
        self.tip_wrench[3 * i..3 * i + 3].copy_from_slice(&[
            w.tip.force[0],
            w.tip.force[1],
            w.tip.moment,
        ]);
    }

    fn into_dict(self, d: &Bound<'_, PyDict>) -> PyResult<()> {
        let py = d.py();
        d.set_item("success", self.success.into_pyarray(py))?;
        d.set_item("a", f64_out(py, self.a))?;
        d.set_item("tip", f64_out(py, self.tip))?;
        d.set_item("base_angle", f64_out(py, self.base_angle))?;
        d.set_item("energy", f64_out(py, self.energy))?;
        d.set_item("elastic_energy", f64_out(py, self.elastic))?;
        d.set_item("margin", f64_out(py, self.margin))?;
        d.set_item("position_error", f64_out(py, self.position_error))?;
        d.set_item("turns", self.turns.into_pyarray(py))?;
        d.set_item("base_wrench", f64_out(py, self.base_wrench))?;
        d.set_item("tip_wrench", f64_out(py, self.tip_wrench))?;
        Ok(())
    }
}

/// The dict of [`solve_held`]'s arrays.
fn held_dict<'py>(
    py: Python<'py>,
    ends: HeldEnds,
    rows: Vec<HeldRow>,
    all: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let n = rows.len();
    let mut columns = HeldColumns::new(n);
    let (mut complete, mut starts) = (vec![false; n], vec![0u32; n]);
    let (mut termination, mut reason) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let solutions = PyList::empty(py);
    let solution_angles = PyList::empty(py);
    let shapes = PyList::empty(py);
    for (i, row) in rows.iter().enumerate() {
        shapes.append(f64_out(py, row.shape.clone()))?;
        let found = match &row.found {
            Ok(f) => f,
            Err(e) => {
                termination.push("invalid_input".to_string());
                reason.push(e.clone());
                solutions.append(f64_out(py, Vec::new()))?;
                solution_angles.append(f64_out(py, Vec::new()))?;
                continue;
            }
        };
        starts[i] = found.starts;
        complete[i] = !found.cut_short;
        if let Some(s) = found.solutions.first() {
            columns.set(i, s, row.target);
            termination.push("converged".to_string());
            reason.push(String::new());
        } else {
            let why = if found.cut_short {
                "deadline"
            } else {
                "no_stable_solution"
            };
            termination.push(why.into());
            reason.push(held::not_found(ends, found).to_string());
        }
        if all {
            let flat: Vec<f64> = found
                .solutions
                .iter()
                .flat_map(|s| s.a.as_slice().to_vec())
                .collect();
            solutions.append(f64_out(py, flat))?;
            let angles = found.solutions.iter().map(|s| s.base_angle).collect();
            solution_angles.append(f64_out(py, angles))?;
        }
    }
    let d = PyDict::new(py);
    columns.into_dict(&d)?;
    d.set_item("starts", starts.into_pyarray(py))?;
    d.set_item("complete", complete.into_pyarray(py))?;
    d.set_item("termination", termination)?;
    d.set_item("reason", reason)?;
    d.set_item("solutions", solutions)?;
    d.set_item("solutions_base_angle", solution_angles)?;
    d.set_item("shapes", shapes)?;
    Ok(d)
}

#[pyfunction]
#[pyo3(signature = (targets, a0=None, objective="first", method="robust", deadline_ms=None,
                    tolerance=None, max_iterations=None, alpha=None, all=false, threads=None,
                    weight=None, gravity=None, max_turns=0))]
#[allow(clippy::too_many_arguments)]
fn solve<'py>(
    py: Python<'py>,
    targets: PyReadonlyArray1<'py, f64>,
    a0: Option<PyReadonlyArray1<'py, f64>>,
    objective: &str,
    method: &str,
    deadline_ms: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<u32>,
    alpha: Option<f64>,
    all: bool,
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
    max_turns: u32,
) -> PyResult<Bound<'py, PyDict>> {
    let t = targets.as_slice()?;
    let g = gravities2(t.len() / 3, weight.as_ref(), gravity.as_ref())?;
    let a0 = a0.as_ref().map(|a| a.as_slice()).transpose()?;
    if max_turns > MAX_TURNS {
        return Err(PyValueError::new_err(format!(
            "max_turns must be in [0, {MAX_TURNS}], got {max_turns}"
        )));
    }
    let mut base = options(
        SolveOptions::default(),
        method,
        objective,
        deadline_ms,
        tolerance,
        max_iterations,
        alpha,
        a0.is_some(),
    )?;
    base.max_turns = max_turns;
    rod_ig_core::planar::ig::warm_up();
    let target_of = |i: usize| Ok(PlanarPose::new(t[3 * i], t[3 * i + 1], t[3 * i + 2]));
    if let Some(g) = g {
        return solve_batch(
            py,
            |i| HeavyPlanar::new(g[i]),
            t.len() / 3,
            a0,
            base,
            all,
            threads,
            target_of,
        );
    }
    solve_batch(
        py,
        |_| PlanarClosedForm,
        t.len() / 3,
        a0,
        base,
        all,
        threads,
        target_of,
    )
}

/// Solves the n targets `target_of(i)` on `model` (a start from row i of `a0`, if given, and
/// with `all` every distinct stable solution) and collects the outputs: the loop shared by
/// `solve` and `solve3d`. A target that cannot be formed is an invalid-input failure.
#[allow(clippy::too_many_arguments)]
fn solve_batch<'py, const N: usize, M>(
    py: Python<'py>,
    model_of: impl Fn(usize) -> M + Sync,
    n: usize,
    a0: Option<&[f64]>,
    base: SolveOptions<nalgebra::SVector<f64, N>>,
    all: bool,
    threads: Option<i64>,
    target_of: impl Fn(usize) -> Result<M::Pose, String> + Sync,
) -> PyResult<Bound<'py, PyDict>>
where
    M: solver::InverseGeometry<N> + Sync,
    M::Pose: Send,
{
    let threads = thread_count(threads)?;
    let mut out = SolveOut::new(n, N)?;
    batch(
        py,
        n,
        threads,
        SOLVE_BLOCK,
        |i| {
            let mut o = base;
            o.initial_guess =
                a0.map(|g| nalgebra::SVector::from_column_slice(&g[N * i..N * (i + 1)]));
            let model = &model_of(i);
            match target_of(i) {
                Ok(target) => {
                    // One deadline for the target: the `all` list gets the time left.
                    let _deadline = rod_ig_core::deadline::scope(o.deadline);
                    let first = solver::solve(model, &target, &o);
                    let every = all.then(|| solver::solve_every(model, &target, &o));
                    (first, every)
                }
                Err(e) => (
                    Err(solver::Failure::early(solver::IgError::InvalidOptions(e))),
                    all.then(|| solver::Every {
                        solutions: Vec::new(),
                        complete: true,
                    }),
                ),
            }
        },
        |i, (first, every)| {
            out.write(i, &first);
            if let Some(every) = every {
                out.complete[i] &= every.complete;
                out.solutions.push(
                    every
                        .solutions
                        .iter()
                        .flat_map(|s| s.a.iter().copied())
                        .collect(),
                );
            }
        },
    )?;
    out.into_dict(py, all)
}

fn stiffness_of(c: (f64, f64, f64)) -> PyResult<Stiffness> {
    let k = Stiffness {
        c1: c.0,
        c2: c.1,
        c3: c.2,
    };
    k.validate()
        .map_err(|e| PyValueError::new_err(format!("stiffness: {e}")))?;
    Ok(k)
}

/// What `forward3d` writes of one rod, whichever integration evaluated it.
struct Evaluated3d {
    tip: SpatialPose,
    jacobian: nalgebra::Matrix6<f64>,
    stability: rod_ig_core::StabilityReport,
    energy: f64,
}

/// [`gravities`] of 3-D rods (default direction −z).
fn gravities3(
    n: usize,
    weight: Option<&PyReadonlyArray1<'_, f64>>,
    gravity: Option<&PyReadonlyArray1<'_, f64>>,
) -> PyResult<Option<Vec<Gravity3>>> {
    gravities(n, weight, gravity, [0.0, 0.0, -1.0], Gravity3::new)
}

/// One 3-D rod's forward map (with weight `g`, else weightless): tip, J, stability, energy,
/// wrenches, condition figure.
#[allow(clippy::type_complexity)]
fn evaluate3d(
    a: &rod_ig_core::spatial::SpatialParams,
    k: &Stiffness,
    g: Option<&Gravity3>,
    opts: &StabilityOptions,
) -> Option<(
    SpatialPose,
    nalgebra::Matrix6<f64>,
    rod_ig_core::StabilityReport,
    f64,
    Option<rod_ig_core::wrench::GripperWrenches<rod_ig_core::wrench::SpatialWrench>>,
    f64,
)> {
    let (am, af) = (a.fixed_rows::<3>(0).into(), a.fixed_rows::<3>(3).into());
    match g {
        Some(g) => heavy3::evaluate(a, k, g).ok().map(|e| {
            let w = heavy3::wrenches(a, k, g).ok();
            (e.tip, e.jacobian, e.stability, e.energy, w, e.condition)
        }),
        // Without weight the world wrench is conserved: the tip's follows from the tip.
        None => spatial::evaluate(a, k, opts).ok().map(|e| {
            let w = Some(wrench::spatial(a, &e.tip, af, am));
            let condition = heavy3::condition_of(a, &e.jacobian);
            (e.tip, e.jacobian, e.stability, e.energy, w, condition)
        }),
    }
}

/// 3-D forward map of n rods `a` (flattened (n, 6)): position, quaternion (x, y, z, w),
/// J (6×6, body twists, rows ω1 ω2 ω3 v1 v2 v3), stable, margin, uncertain, condition,
/// energy.
#[pyfunction]
#[pyo3(signature = (a, stiffness=(1.0, 1.0, 1.0), threads=None, weight=None, gravity=None))]
fn forward3d<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    stiffness: (f64, f64, f64),
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = a.as_slice()?;
    let n = a.len() / 6;
    let k = stiffness_of(stiffness)?;
    let threads = thread_count(threads)?;
    let g = gravities3(n, weight.as_ref(), gravity.as_ref())?;
    let opts = StabilityOptions::production();
    let mut position = buffer(n, 3, f64::NAN)?;
    let mut quaternion = buffer(n, 4, f64::NAN)?;
    let mut jac = buffer(n, 36, f64::NAN)?;
    let mut stable = buffer(n, 1, false)?;
    let mut margin = buffer(n, 1, f64::NAN)?;
    let mut energy = buffer(n, 1, f64::NAN)?;
    let (mut uncertain, mut cond) = (buffer(n, 1, true)?, buffer(n, 1, f64::NAN)?);
    let (mut base_w, mut tip_w) = (buffer(n, 6, f64::NAN)?, buffer(n, 6, f64::NAN)?);
    batch(
        py,
        n,
        threads,
        SOLVE_BLOCK,
        |i| {
            let ai = Vector6::from_column_slice(&a[6 * i..6 * i + 6]);
            evaluate3d(&ai, &k, g.as_ref().map(|g| &g[i]), &opts)
        },
        |i, e| {
            let e = e.map(|(tip, jacobian, stability, energy, w, condition)| {
                cond[i] = condition;
                if let Some([b, t]) = w.as_ref().map(spatial_rows) {
                    base_w[6 * i..6 * i + 6].copy_from_slice(&b);
                    tip_w[6 * i..6 * i + 6].copy_from_slice(&t);
                }
                Evaluated3d {
                    tip,
                    jacobian,
                    stability,
                    energy,
                }
            });
            if let Some(e) = e {
                let p = e.tip.position;
                position[3 * i..3 * i + 3].copy_from_slice(&[p.x, p.y, p.z]);
                quaternion[4 * i..4 * i + 4].copy_from_slice(&e.tip.quaternion_xyzw());
                for r in 0..6 {
                    for c in 0..6 {
                        jac[36 * i + 6 * r + c] = e.jacobian[(r, c)];
                    }
                }
                stable[i] = e.stability.stable;
                margin[i] = e.stability.margin;
                uncertain[i] = e.stability.uncertain;
                energy[i] = e.energy;
            }
        },
    )?;
    let d = PyDict::new(py);
    d.set_item("position", f64_out(py, position))?;
    d.set_item("uncertain", uncertain.into_pyarray(py))?;
    d.set_item("condition", f64_out(py, cond))?;
    d.set_item("quaternion", f64_out(py, quaternion))?;
    d.set_item("jacobian", f64_out(py, jac))?;
    d.set_item("stable", stable.into_pyarray(py))?;
    d.set_item("margin", f64_out(py, margin))?;
    d.set_item("energy", f64_out(py, energy))?;
    d.set_item("base_wrench", f64_out(py, base_w))?;
    d.set_item("tip_wrench", f64_out(py, tip_w))?;
    Ok(d)
}

/// 3-D inverse geometry of n targets (positions (n, 3), quaternions (n, 4) x, y, z, w).
#[pyfunction]
#[pyo3(signature = (position, quaternion, a0=None, objective="first", method="robust",
                    deadline_ms=None, tolerance=None, max_iterations=None, alpha=None,
                    stiffness=(1.0, 1.0, 1.0), all=false, threads=None, weight=None,
                    gravity=None))]
#[allow(clippy::too_many_arguments)]
fn solve3d<'py>(
    py: Python<'py>,
    position: PyReadonlyArray1<'py, f64>,
    quaternion: PyReadonlyArray1<'py, f64>,
    a0: Option<PyReadonlyArray1<'py, f64>>,
    objective: &str,
    method: &str,
    deadline_ms: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<u32>,
    alpha: Option<f64>,
    stiffness: (f64, f64, f64),
    all: bool,
    threads: Option<i64>,
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = position.as_slice()?;
    let q = quaternion.as_slice()?;
    let g = gravities3(p.len() / 3, weight.as_ref(), gravity.as_ref())?;
    let a0 = a0.as_ref().map(|a| a.as_slice()).transpose()?;
    let model = Spatial::with_stiffness(stiffness_of(stiffness)?);
    let base = options(
        SolveOptions::default(),
        method,
        objective,
        deadline_ms,
        tolerance,
        max_iterations,
        alpha,
        a0.is_some(),
    )?;
    let target_of = |i: usize| {
        SpatialPose::from_xyzw(
            Vector3::new(p[3 * i], p[3 * i + 1], p[3 * i + 2]),
            [q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]],
        )
        .map_err(|e| e.to_string())
    };
    if let Some(g) = g {
        let heavy = |i: usize| HeavySpatial {
            stiffness: model.stiffness,
            gravity: g[i],
        };
        return solve_batch(py, heavy, p.len() / 3, a0, base, all, threads, target_of);
    }
    solve_batch(
        py,
        |_| model,
        p.len() / 3,
        a0,
        base,
        all,
        threads,
        target_of,
    )
}

/// Quasi-static motion of the planar rod: the rod follows its equilibrium branch as the tip
/// gripper moves, and snaps where the branch folds.
#[pyclass(module = "rod_ig._rod_ig")]
struct Tracker {
    /// Without weight, `HeavyPlanar` is the closed forms' model in every method.
    follower: BranchFollower<3, HeavyPlanar>,
}

#[pymethods]
impl Tracker {
    #[new]
    #[pyo3(signature = (a0=None, deadline_ms=None, tolerance=None, weight=0.0, gravity=(0.0, -1.0)))]
    fn new(
        a0: Option<[f64; 3]>,
        deadline_ms: Option<f64>,
        tolerance: Option<f64>,
        weight: f64,
        gravity: (f64, f64),
    ) -> PyResult<Self> {
        let g = Gravity::new(weight, [gravity.0, gravity.1])
            .map_err(|e| PyValueError::new_err(format!("weight/gravity: {e}")))?;
        let model = HeavyPlanar::new(g);
        let o = options(
            SolveOptions::default(),
            "robust",
            "first",
            deadline_ms,
            tolerance,
            None,
            None,
            false,
        )?;
        rod_ig_core::planar::ig::warm_up();
        let follower = match a0 {
            Some(a) => BranchFollower::holding(model, o, PlanarParams::from(a))
                .map_err(|e| PyValueError::new_err(format!("a0 cannot be held: {e}")))?,
            None => BranchFollower::new(model, o),
        };
        Ok(Tracker { follower })
    }

    /// Moves the gripper to `target` (x, y, θ); returns the solve's fields plus `event`.
    #[pyo3(name = "move")]
    fn move_to<'py>(&mut self, py: Python<'py>, target: [f64; 3]) -> PyResult<Bound<'py, PyDict>> {
        let pose = PlanarPose::new(target[0], target[1], target[2]);
        let follower = &mut self.follower;
        let m = py.detach(|| follower.follow(&pose));
        let mut out = SolveOut::new(1, 3)?;
        out.write(0, &m.result);
        let d = PyDict::new(py);
        d.set_item("success", out.success[0])?;
        d.set_item("a", f64_out(py, out.a))?;
        d.set_item("termination", out.termination[0])?;
        d.set_item("iterations", out.iterations[0])?;
        d.set_item("margin", out.margin[0])?;
        d.set_item("energy", out.energy[0])?;
        d.set_item("position_error", out.position_error[0])?;
        d.set_item("orientation_error", out.orientation_error[0])?;
        d.set_item("event", m.event.as_str())?;
        if let BranchEvent::Snap {
            critical,
            critical_a,
            energy_released,
            ..
        } = m.event
        {
            d.set_item(
                "critical",
                f64_out(py, vec![critical.x, critical.y, critical.theta]),
            )?;
            d.set_item(
                "critical_a",
                f64_out(py, critical_a.iter().copied().collect()),
            )?;
            d.set_item("energy_released", energy_released)?;
        }
        if let Err(f) = &m.result {
            d.set_item("reason", f.reason.to_string())?;
        }
        Ok(d)
    }

    /// The rod held now (a3, a4, a5), or None.
    #[getter]
    fn rod(&self) -> Option<[f64; 3]> {
        self.follower.rod().map(|a| [a[0], a[1], a[2]])
    }
}

/// Stable gripper paths for the planar rod: a roadmap over stable rods, kept across calls.
#[pyclass(module = "rod_ig._rod_ig")]
struct Planner {
    planner: CorePlanner,
}

#[pymethods]
impl Planner {
    #[new]
    fn new() -> Self {
        Planner {
            planner: CorePlanner::new(),
        }
    }

    /// Plans from the rod `start` to a rod whose tip is `goal` (x, y, θ) around `obstacles`
    /// (dicts {"type": "disc", "center": [x, y], "radius": r} or {"type": "polygon",
    /// "points": [[x, y], ...]}), for the rod with `weight` along `gravity` (0: weightless).
    #[pyo3(signature = (start, goal, obstacles=Vec::new(), deadline_ms=500.0, weight=0.0,
                        gravity=(0.0, -1.0)))]
    #[allow(clippy::too_many_arguments)] // the Python keyword arguments, one each
    fn plan<'py>(
        &mut self,
        py: Python<'py>,
        start: [f64; 3],
        goal: [f64; 3],
        obstacles: Vec<Bound<'py, PyDict>>,
        deadline_ms: f64,
        weight: f64,
        gravity: (f64, f64),
    ) -> PyResult<Bound<'py, PyDict>> {
        let gravity = Gravity::new(weight, [gravity.0, gravity.1])
            .map_err(|e| PyValueError::new_err(format!("weight/gravity: {e}")))?;
        let obstacles = obstacles
            .iter()
            .map(obstacle_of)
            .collect::<PyResult<Vec<_>>>()?;
        if !(deadline_ms.is_finite() && deadline_ms > 0.0 && deadline_ms <= 10_000.0) {
            return Err(PyValueError::new_err(format!(
                "deadline_ms must be in (0, 10000], got {deadline_ms}"
            )));
        }
        let request = PlanRequest {
            start: PlanarParams::from(start),
            goal: PlanarPose::new(goal[0], goal[1], goal[2]),
            obstacles,
            deadline: Duration::from_secs_f64(deadline_ms / 1e3),
            gravity,
        };
        let planner = &mut self.planner;
        let r = py.detach(|| {
            rod_ig_core::planar::ig::warm_up();
            planner.plan(&request)
        });
        let d = PyDict::new(py);
        match r {
            Ok(p) => {
                d.set_item("success", true)?;
                let rods: Vec<f64> = p.rods.iter().flat_map(|a| a.iter().copied()).collect();
                let gripper: Vec<f64> =
                    p.gripper.iter().flat_map(|g| [g.x, g.y, g.theta]).collect();
                d.set_item("rods", f64_out(py, rods))?;
                d.set_item("gripper", f64_out(py, gripper))?;
                d.set_item("min_margin", p.min_margin)?;
                d.set_item("reason", "")?;
            }
            Err(e) => {
                d.set_item("success", false)?;
                d.set_item("rods", f64_out(py, Vec::new()))?;
                d.set_item("gripper", f64_out(py, Vec::new()))?;
                d.set_item("min_margin", f64::NAN)?;
                d.set_item("reason", e.to_string())?;
            }
        }
        Ok(d)
    }

    /// Roadmap nodes (0 before the first plan).
    #[getter]
    fn roadmap_size(&self) -> usize {
        self.planner.roadmap_size()
    }
}

fn obstacle_of(d: &Bound<'_, PyDict>) -> PyResult<Obstacle> {
    let kind: String = d
        .get_item("type")?
        .ok_or_else(|| PyValueError::new_err("obstacle needs a 'type'"))?
        .extract()?;
    match kind.as_str() {
        "disc" => Ok(Obstacle::Disc {
            center: d
                .get_item("center")?
                .ok_or_else(|| PyValueError::new_err("disc needs 'center'"))?
                .extract()?,
            radius: d
                .get_item("radius")?
                .ok_or_else(|| PyValueError::new_err("disc needs 'radius'"))?
                .extract()?,
        }),
        "polygon" => Ok(Obstacle::Polygon {
            points: d
                .get_item("points")?
                .ok_or_else(|| PyValueError::new_err("polygon needs 'points'"))?
                .extract()?,
        }),
        other => Err(PyValueError::new_err(format!(
            "obstacle type must be 'disc' or 'polygon', got {other:?}"
        ))),
    }
}

/// Seconds the plain Rust loop of `planar::evaluate` takes over the rods `a` (no Python, no
/// output arrays): the baseline of the package's benchmark (`python/bench.py`).
#[pyfunction]
fn _time_evaluate(py: Python<'_>, a: PyReadonlyArray1<'_, f64>) -> PyResult<f64> {
    let a = a.as_slice()?;
    Ok(py.detach(|| {
        let t0 = std::time::Instant::now();
        for r in a.chunks_exact(3) {
            std::hint::black_box(planar::evaluate(&PlanarParams::new(r[0], r[1], r[2])).ok());
        }
        t0.elapsed().as_secs_f64()
    }))
}

/// Builds the planar solver's atlas now (≈ 0.15 s on two cores); returns its size.
#[pyfunction]
fn warm_up(py: Python<'_>) -> usize {
    py.detach(rod_ig_core::planar::ig::warm_up)
}

#[pymodule]
fn _rod_ig(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(forward, m)?)?;
    m.add_function(wrap_pyfunction!(forward_held, m)?)?;
    m.add_function(wrap_pyfunction!(is_stable, m)?)?;
    m.add_function(wrap_pyfunction!(shape, m)?)?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(solve_held, m)?)?;
    m.add_function(wrap_pyfunction!(forward3d, m)?)?;
    m.add_function(wrap_pyfunction!(solve3d, m)?)?;
    m.add_function(wrap_pyfunction!(held3d::solve_held3d, m)?)?;
    m.add_function(wrap_pyfunction!(held3d::forward_held3d, m)?)?;
    m.add_function(wrap_pyfunction!(wrenches, m)?)?;
    m.add_function(wrap_pyfunction!(wrenches3d, m)?)?;
    m.add_function(wrap_pyfunction!(turns, m)?)?;
    m.add_function(wrap_pyfunction!(warm_up, m)?)?;
    m.add_function(wrap_pyfunction!(_time_evaluate, m)?)?;
    m.add_class::<Tracker>()?;
    m.add_class::<HeldTracker>()?;
    m.add_class::<Planner>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
