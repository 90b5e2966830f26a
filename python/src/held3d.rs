//! The 3-D rod with pinned or free ends (issue 52): `solve_held3d` and `forward_held3d`, thin
//! batch adapters on `rod_ig_core::spatial::held`.

use crate::{batch, ends_of, f64_out, gravities3, spatial_rows, stiffness_of, thread_count};
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rod_ig_core::spatial::heavy::Gravity3;
use rod_ig_core::spatial::held::{self, SpatialHeldSearch, SpatialHeldSolution};
use rod_ig_core::spatial::{SpatialParams, SpatialPose};

/// Rods per work item of the batch (each is a search of up to its deadline).
const SEARCH_BLOCK: usize = 1;

/// The columns of one held 3-D rod: a (6), base quaternion (4), tip position and quaternion
/// (7), margin, energy, elastic energy, turns, position error, base and tip wrench (6 each),
/// stable, uncertain.
#[derive(Default)]
struct Columns {
    a: Vec<f64>,
    base_quaternion: Vec<f64>,
    tip: Vec<f64>,
    scalars: [Vec<f64>; 5],
    base_wrench: Vec<f64>,
    tip_wrench: Vec<f64>,
    stable: Vec<bool>,
    uncertain: Vec<bool>,
}

impl Columns {
    /// Appends the rod `s` (None: NaN, a failed solve); `target` a pinned tip's.
    fn push(&mut self, s: Option<&SpatialHeldSolution>, target: Option<[f64; 3]>) {
        let Some(s) = s else {
            self.a.extend([f64::NAN; 6]);
            self.base_quaternion.extend([f64::NAN; 4]);
            self.tip.extend([f64::NAN; 7]);
            for c in &mut self.scalars {
                c.push(f64::NAN);
            }
            self.base_wrench.extend([f64::NAN; 6]);
            self.tip_wrench.extend([f64::NAN; 6]);
            self.stable.push(false);
            self.uncertain.push(false);
            return;
        };
        self.a.extend(s.a.iter());
        let base = SpatialPose {
            position: nalgebra::Vector3::zeros(),
            rotation: s.base_rotation,
        };
        self.base_quaternion.extend(base.quaternion_xyzw());
        self.tip.extend(s.tip.position.iter());
        self.tip.extend(s.tip.quaternion_xyzw());
        let error = target.map_or(f64::NAN, |t| {
            (s.tip.position - nalgebra::Vector3::from(t)).norm()
        });
        let values = [
            s.stability.margin,
            s.energy,
            s.elastic_energy,
            f64::from(s.turns),
            error,
        ];
        for (c, v) in self.scalars.iter_mut().zip(values) {
            c.push(v);
        }
        let [b, t] = s
            .wrenches()
            .map(|w| spatial_rows(&w))
            .unwrap_or([[f64::NAN; 6]; 2]);
        self.base_wrench.extend(b);
        self.tip_wrench.extend(t);
        self.stable.push(s.stability.stable);
        self.uncertain.push(s.stability.uncertain);
    }

    fn into_dict(self, d: &Bound<'_, PyDict>) -> PyResult<()> {
        let py = d.py();
        let [margin, energy, elastic, turns, error] = self.scalars;
        for (key, v) in [
            ("a", self.a),
            ("base_quaternion", self.base_quaternion),
            ("tip", self.tip),
            ("margin", margin),
            ("energy", energy),
            ("elastic_energy", elastic),
            ("turns", turns),
            ("position_error", error),
            ("base_wrench", self.base_wrench),
            ("tip_wrench", self.tip_wrench),
        ] {
            d.set_item(key, f64_out(py, v))?;
        }
        d.set_item("stable", self.stable.into_pyarray(py))?;
        d.set_item("uncertain", self.uncertain.into_pyarray(py))?;
        Ok(())
    }
}

/// Pinned and free ends of the 3-D rod: for each of `n` rods the least-energy stable
/// equilibrium held by (`base_condition`, `tip_condition`) through its target (flattened
/// (n, 3) positions for a pinned tip, none for a free tip), and with `all` every stable one
/// found (`solutions`: (k, 6) per rod). Returns a dict of flat arrays.
#[pyfunction]
#[pyo3(signature = (n, positions=None, base_condition="clamped", tip_condition="free",
                    stiffness=(1.0, 1.0, 1.0), weight=None, gravity=None, all=false,
                    deadline_ms=None, max_turns=0, threads=None, quaternions=None, samples=0))]
#[allow(clippy::too_many_arguments)]
pub fn solve_held3d<'py>(
    py: Python<'py>,
    n: usize,
    positions: Option<PyReadonlyArray1<'py, f64>>,
    base_condition: &str,
    tip_condition: &str,
    stiffness: (f64, f64, f64),
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
    all: bool,
    deadline_ms: Option<f64>,
    max_turns: u32,
    threads: Option<i64>,
    quaternions: Option<PyReadonlyArray1<'py, f64>>,
    samples: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if samples == 1 || samples > 1_000_000 {
        return Err(PyValueError::new_err(format!(
            "samples must be 0 (no shape) or in [2, 1000000], got {samples}"
        )));
    }
    let ends = ends_of(base_condition, tip_condition)?;
    let k = stiffness_of(stiffness)?;
    let p = positions.as_ref().map(|p| p.as_slice()).transpose()?;
    if p.is_some_and(|p| p.len() != 3 * n) {
        return Err(PyValueError::new_err("positions: expected n rows of 3"));
    }
    let q = quaternions.as_ref().map(|q| q.as_slice()).transpose()?;
    if q.is_some_and(|q| q.len() != 4 * n) {
        return Err(PyValueError::new_err("quaternions: expected n rows of 4"));
    }
    let gravities = gravities3(n, weight.as_ref(), gravity.as_ref())?;
    let options = crate::held_options(deadline_ms, max_turns)?;
    let target_of = |i: usize| p.map(|p| [p[3 * i], p[3 * i + 1], p[3 * i + 2]]);
    rod_ig_core::planar::ig::warm_up();
    let mut rows: Vec<Option<Row>> = (0..n).map(|_| None).collect();
    batch(
        py,
        n,
        thread_count(threads)?,
        SEARCH_BLOCK,
        |i| {
            let g = gravities.as_ref().map_or(Gravity3::NONE, |g| g[i]);
            let target = target_of(i).map(nalgebra::Vector3::from);
            let found = match (q, target) {
                // A pinned base with a clamped tip: the tip's pose.
                (Some(q), Some(p)) => {
                    let xyzw = [q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]];
                    SpatialPose::from_xyzw(p, xyzw)
                        .map_err(|e| format!("quaternions: {e}"))
                        .and_then(|pose| {
                            held::equilibria_to_pose(&k, &g, &pose, &options)
                                .map_err(|e| e.to_string())
                        })
                }
                _ => held::equilibria(ends, &k, &g, target.as_ref(), &options)
                    .map_err(|e| e.to_string()),
            };
            let shape = match (&found, samples) {
                (Ok(f), 2..) => f
                    .solutions
                    .first()
                    .and_then(|s| shape_of(s, samples))
                    .unwrap_or_default(),
                _ => Vec::new(),
            };
            (found, shape)
        },
        |i, r| rows[i] = Some(r),
    )?;
    let targets: Vec<Option<[f64; 3]>> = (0..n).map(target_of).collect();
    search_dict(
        py,
        ends,
        rows.into_iter().flatten().collect(),
        &targets,
        all,
    )
}

/// One rod's search (or why it was refused) and its best rod's shape (`samples` poses of 7:
/// position, quaternion x y z w; empty when not asked or when there is none).
type Row = (Result<SpatialHeldSearch, String>, Vec<f64>);

/// The rod's shape, `samples` poses from base to tip, flattened.
fn shape_of(s: &SpatialHeldSolution, samples: usize) -> Option<Vec<f64>> {
    let ts: Vec<f64> = (0..samples)
        .map(|i| i as f64 / (samples - 1) as f64)
        .collect();
    let poses = s.cable.poses_at(&ts).ok()?;
    Some(
        poses
            .iter()
            .flat_map(|p| {
                let q = p.quaternion_xyzw();
                [
                    p.position.x,
                    p.position.y,
                    p.position.z,
                    q[0],
                    q[1],
                    q[2],
                    q[3],
                ]
            })
            .collect(),
    )
}

/// The dict of `solve_held3d` from each rod's search (or why it was refused).
fn search_dict<'py>(
    py: Python<'py>,
    ends: rod_ig_core::ends::HeldEnds,
    rows: Vec<Row>,
    targets: &[Option<[f64; 3]>],
    all: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let n = rows.len();
    let shapes = PyList::empty(py);
    let mut columns = Columns::default();
    let (mut complete, mut starts) = (vec![false; n], vec![0u32; n]);
    let (mut termination, mut reason) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let solutions = PyList::empty(py);
    for (i, (row, shape)) in rows.into_iter().enumerate() {
        shapes.append(f64_out(py, shape))?;
        let found = match row {
            Ok(f) => f,
            Err(e) => {
                columns.push(None, None);
                termination.push("invalid_input".to_string());
                reason.push(e);
                solutions.append(f64_out(py, Vec::new()))?;
                continue;
            }
        };
        starts[i] = found.starts;
        complete[i] = !found.cut_short;
        columns.push(found.solutions.first(), targets[i]);
        let (why, text) = match (found.solutions.first(), found.cut_short) {
            (Some(_), _) => ("converged", String::new()),
            (None, true) => ("deadline", found.not_found(ends).to_string()),
            (None, false) => ("no_stable_solution", found.not_found(ends).to_string()),
        };
        termination.push(why.to_string());
        reason.push(text);
        if all {
            let flat = found
                .solutions
                .iter()
                .flat_map(|s| s.a.iter().copied())
                .collect();
            solutions.append(f64_out(py, flat))?;
        }
    }
    let d = PyDict::new(py);
    columns.into_dict(&d)?;
    let success: Vec<bool> = termination.iter().map(|t| t == "converged").collect();
    d.set_item("success", success.into_pyarray(py))?;
    d.set_item("starts", starts.into_pyarray(py))?;
    d.set_item("complete", complete.into_pyarray(py))?;
    d.set_item("termination", termination)?;
    d.set_item("reason", reason)?;
    d.set_item("solutions", solutions)?;
    d.set_item("shapes", shapes)?;
    Ok(d)
}

/// The forward map of n 3-D rods `a` (flattened (n, 6)) held by (`base_condition`,
/// `tip_condition`), a pinned base turned to `base_quaternion` (flattened (n, 4), x y z w;
/// default the identity) (`spatial::held::evaluate`): the columns of `solve_held3d`. A rod
/// the conditions refuse raises ValueError naming the argument.
#[pyfunction]
#[pyo3(signature = (a, base_condition, tip_condition, base_quaternion=None,
                    stiffness=(1.0, 1.0, 1.0), weight=None, gravity=None))]
#[allow(clippy::too_many_arguments)]
pub fn forward_held3d<'py>(
    py: Python<'py>,
    a: PyReadonlyArray1<'py, f64>,
    base_condition: &str,
    tip_condition: &str,
    base_quaternion: Option<PyReadonlyArray1<'py, f64>>,
    stiffness: (f64, f64, f64),
    weight: Option<PyReadonlyArray1<'py, f64>>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let ends = ends_of(base_condition, tip_condition)?;
    let k = stiffness_of(stiffness)?;
    let a = a.as_slice()?;
    let n = a.len() / 6;
    let q = base_quaternion.as_ref().map(|q| q.as_slice()).transpose()?;
    let gravities = gravities3(n, weight.as_ref(), gravity.as_ref())?;
    let mut columns = Columns::default();
    let mut jacobians = Vec::with_capacity(36 * n);
    for i in 0..n {
        let rotation = match q {
            Some(q) => {
                let xyzw = [q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]];
                SpatialPose::from_xyzw(nalgebra::Vector3::zeros(), xyzw)
                    .map_err(|e| PyValueError::new_err(format!("base_quaternion: {e}")))?
                    .rotation
            }
            None => nalgebra::UnitQuaternion::identity(),
        };
        let g = gravities.as_ref().map_or(Gravity3::NONE, |g| g[i]);
        let ai = SpatialParams::from_row_slice(&a[6 * i..6 * i + 6]);
        let s = held::evaluate(&ai, &k, &g, ends, rotation)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        // Row-major 6 × 6 (rows ω, v; columns a_m or a pinned base's turn, then a_f).
        match s.cable.tip_jacobian() {
            Ok(Some(j)) => jacobians.extend(j.transpose().iter()),
            _ => jacobians.extend([f64::NAN; 36]),
        }
        columns.push(Some(&s), None);
    }
    let d = PyDict::new(py);
    columns.into_dict(&d)?;
    d.set_item("jacobian", f64_out(py, jacobians))?;
    Ok(d)
}
