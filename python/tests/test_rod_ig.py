"""Tests of the rod_ig Python package: against the reference data, against the CLI, batch
shapes and broadcasting, every error path, the GIL released, Ctrl-C, the Dask recipe."""

from __future__ import annotations

import json
import os
import pickle
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rod_ig

HERE = Path(__file__).parent
REPO = HERE.parents[1]


def oracle() -> list[dict]:
    lines = (REPO / "data" / "oracle" / "cases_public.jsonl").read_text().splitlines()[:200]
    return [json.loads(line) for line in lines]


def cli() -> str:
    path = os.environ.get("ROD_IG_CLI", str(REPO / "target" / "release" / "rod-ig"))
    if not Path(path).exists():
        subprocess.run(
            ["cargo", "build", "--release", "-p", "rod-ig-cli"], cwd=REPO, check=True
        )
    return path


def run_cli(command: str, requests: list[dict]) -> list[dict]:
    text = "".join(json.dumps(r) + "\n" for r in requests)
    out = subprocess.run([cli(), command], input=text, capture_output=True, text=True, check=True)
    return [json.loads(line) for line in out.stdout.splitlines()]


# --- the reference data ----------------------------------------------------------------------


def test_forward_matches_the_oracle() -> None:
    """Tolerances of the oracle's README: tip 1e-11, J 1e-8 relative, identical verdicts."""
    cases = oracle()
    a = np.array([c["a"] for c in cases])
    r = rod_ig.forward(a)
    for i, c in enumerate(cases):
        theta, x, y = c["tip"]
        assert np.allclose(r.tip[i], [x, y, theta], rtol=0, atol=1e-11)
        jac = np.array(c["jac"])[[1, 2, 0]]  # oracle rows θ, x, y -> ours x, y, θ
        scale = np.abs(jac).max()
        assert np.abs(r.jacobian[i] - jac).max() <= 1e-8 * scale
        assert bool(r.stable[i]) == c["stable"]
        assert abs(r.energy[i] - c["energy"]) <= 1e-9 * max(1.0, c["energy"])


def test_results_equal_the_cli_on_the_same_inputs() -> None:
    a = np.array([c["a"] for c in oracle()[:40]] + [[0.0, 0.0, 0.0], [1e-30, 5.0, -0.0]])
    r = rod_ig.forward(a, threads=2)
    answers = run_cli("forward", [{"a": list(map(float, row))} for row in a])
    for i, ans in enumerate(answers):
        tip = ans["tip"]
        assert list(r.tip[i]) == [tip["x"], tip["y"], tip["theta"]]
        assert r.jacobian[i].tolist() == ans["jacobian"]
        assert bool(r.stable[i]) == ans["stable"]
        assert r.energy[i] == ans["energy"]
        assert bool(r.uncertain[i]) == ans["stability_uncertain"]
    targets = np.array([[0.5, 0.2, 1.0], [0.6, 0.3, 370000000000.123], [0.3, -0.5, -2.0]])
    s = rod_ig.solve(targets, threads=1)
    answers = run_cli("solve", [{"target": dict(zip("x y theta".split(), map(float, t)))} for t in targets])
    for i, ans in enumerate(answers):
        assert bool(s.success[i]) == ans["success"]
        assert s.termination[i] == ans["termination"]
        assert s.a[i].tolist() == ans["a"]
        assert s.position_error[i] == ans["position_error"]


def test_solve_inverts_the_forward_map_of_stable_rods() -> None:
    cases = [c for c in oracle() if c["stable"]][:30]
    tips = rod_ig.forward(np.array([c["a"] for c in cases])).tip
    s = rod_ig.solve(tips)
    assert s.success.all(), s.termination
    back = rod_ig.forward(s.a)
    assert back.stable.all()
    assert np.abs(back.tip[:, :2] - tips[:, :2]).max() <= 1e-6
    dtheta = np.angle(np.exp(1j * (back.tip[:, 2] - tips[:, 2])))
    assert np.abs(dtheta).max() <= 1e-6
    assert (s.position_error <= 1e-6).all() and (s.orientation_error <= 1e-6).all()


@settings(max_examples=60, deadline=None)
@given(
    st.floats(-3, 3),
    st.floats(-4, 2),
    st.floats(-4, 2),
    st.sampled_from([-1.0, 0.0, 1.0]),
)
def test_forward_is_consistent_with_shape_on_log_scale_rods(
    a3: float, log_a4: float, log_a5: float, sign: float
) -> None:
    """Log-scale magnitudes, exact zeros and signs: the last shape pose is the tip."""
    a = np.array([a3, sign * 10.0**log_a4, -(10.0**log_a5)])
    r = rod_ig.forward(a)
    poses = rod_ig.shape(a, samples=5)
    assert poses.shape == (5, 3)
    if np.isfinite(r.tip).all():
        assert np.allclose(poses[-1], r.tip, atol=1e-12)
        assert np.allclose(poses[0], 0.0)


def test_3d_forward_and_solve_roundtrip() -> None:
    rng = np.random.default_rng(3)
    a = rng.uniform(-3, 3, size=(8, 6))
    f = rod_ig.forward3d(a)
    assert f.position.shape == (8, 3) and f.quaternion.shape == (8, 4) and f.jacobian.shape == (8, 6, 6)
    assert np.allclose(np.linalg.norm(f.quaternion, axis=-1), 1.0)
    ok = f.stable
    s = rod_ig.solve3d(f.position[ok], f.quaternion[ok])
    assert s.success.all(), s.termination
    back = rod_ig.forward3d(s.a)
    assert np.abs(back.position - f.position[ok]).max() <= 1e-6
    answers = run_cli("forward3d", [{"a": list(map(float, row))} for row in a[:3]])
    for i, ans in enumerate(answers):
        assert f.position[i].tolist() == ans["tip"]["position"]


# --- shapes, broadcasting, errors --------------------------------------------------------------


def test_is_stable_gives_the_forward_maps_verdicts() -> None:
    """The verdict alone agrees with ``forward``'s on the box and on log-scale magnitudes with
    exact zeros (both signs), keeps the batch shape, and rejects what ``forward`` rejects."""
    rng = np.random.default_rng(31)
    box = rng.uniform([-10, -100, -100], [10, 100, 100], size=(3000, 3))
    logs = np.sign(rng.uniform(-1, 1, size=(3000, 3))) * 10 ** rng.uniform(-6, 3, size=(3000, 3))
    logs[rng.uniform(size=logs.shape) < 0.1] = 0.0
    a = np.concatenate([box, logs])
    verdicts = rod_ig.is_stable(a)
    assert verdicts.dtype == np.bool_ and verdicts.shape == (6000,)
    assert np.array_equal(verdicts, rod_ig.forward(a).stable)
    assert 0.2 < verdicts[:3000].mean() < 0.8
    assert rod_ig.is_stable(a.reshape(2, 3000, 3)).shape == (2, 3000)
    assert not rod_ig.is_stable([0.0, 0.0, 0.0])[()]
    with pytest.raises(ValueError, match=r"a must have shape \(\.\.\., 3\)"):
        rod_ig.is_stable(np.zeros((4, 2)))


def test_batch_shapes_and_broadcasting() -> None:
    a = np.zeros((2, 3, 3))
    a[..., 0] = 1.0
    r = rod_ig.forward(a)
    assert r.tip.shape == (2, 3, 3) and r.jacobian.shape == (2, 3, 3, 3) and r.stable.shape == (2, 3)
    assert rod_ig.forward([1.0, 2.0, 3.0]).tip.shape == (3,)
    assert rod_ig.shape(a, samples=7).shape == (2, 3, 7, 3)
    assert rod_ig.forward(np.zeros((0, 3))).tip.shape == (0, 3)
    # One start broadcast against many targets, integer input accepted.
    targets = np.array([[[0.5, 0.2, 1.0]], [[0.4, 0.1, 0.5]]])  # (2, 1, 3)
    s = rod_ig.solve(targets, a0=np.array([[-7.4, -36.0, -15.4]] * 4))  # (4, 3) -> (2, 4)
    assert s.a.shape == (2, 4, 3) and s.success.shape == (2, 4) and s.termination.shape == (2, 4)
    assert rod_ig.forward(np.array([[1, 2, 3]], dtype=np.int32)).tip.shape == (1, 3)
    s = rod_ig.solve([0.5, 0.2, 1.0], all=True, objective="least_energy")
    # One target: its (k, 3) array of solutions itself (a batch gets an object array of them).
    assert s.solutions is not None
    sols = s.solutions
    assert sols.ndim == 2 and sols.shape[1] == 3 and len(sols) >= 1
    assert np.isclose(rod_ig.forward(sols[0]).energy, s.energy)


def test_errors_name_the_argument() -> None:
    with pytest.raises(ValueError, match=r"a must have shape \(\.\.\., 3\)"):
        rod_ig.forward(np.zeros((4, 2)))
    with pytest.raises(TypeError, match="a must hold real numbers"):
        rod_ig.forward([["x", "y", "z"]])
    with pytest.raises(TypeError, match="a must hold real numbers"):
        rod_ig.forward(np.ones((2, 3), dtype=complex))
    bad = np.zeros((5, 3))
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"a is not finite at index \(3, 1\)"):
        rod_ig.forward(bad)
    with pytest.raises(ValueError, match="targets is not finite"):
        rod_ig.solve([0.5, np.inf, 0.0])
    with pytest.raises(ValueError, match="quaternion must have shape"):
        rod_ig.solve3d([0.5, 0.2, 0.1], [0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="do not broadcast"):
        rod_ig.solve(np.zeros((3, 3)), a0=np.zeros((2, 3)))
    with pytest.raises(ValueError, match="tolerance"):
        rod_ig.solve([0.5, 0.2, 1.0], tolerance=1e308)
    with pytest.raises(ValueError, match="max_iterations"):
        rod_ig.solve([0.5, 0.2, 1.0], max_iterations=0)
    with pytest.raises(ValueError, match="method"):
        rod_ig.solve([0.5, 0.2, 1.0], method="magic")
    with pytest.raises(ValueError, match="newton"):
        rod_ig.solve([0.5, 0.2, 1.0], method="newton")
    with pytest.raises(ValueError, match="deadline_ms"):
        rod_ig.solve([0.5, 0.2, 1.0], deadline_ms=-1)
    with pytest.raises(ValueError, match="stiffness"):
        rod_ig.forward3d(np.zeros(6), stiffness=(0.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="samples"):
        rod_ig.shape([1, 2, 3], samples=1)
    with pytest.raises(ValueError, match="threads"):
        rod_ig.forward([1, 2, 3], threads=0)
    r = rod_ig.Planner().plan(
        [0.5, 0.1, 0.1], [0.8, 0.3, 0.5], [{"type": "disc", "center": [1e200, 0.0], "radius": 1.0}]
    )
    assert not r.success and "1e6" in r.reason
    with pytest.raises(ValueError, match="obstacle type"):
        rod_ig.Planner().plan([0.5, 0.1, 0.1], [0.8, 0.3, 0.5], [{"type": "cube"}])


def test_unsolvable_targets_are_data_not_exceptions() -> None:
    s = rod_ig.solve([[2.0, 0.0, 0.0], [0.5, 0.2, 1.0], [0.9, 0.1, 3.0]], deadline_ms=5)
    assert s.success.tolist()[:2] == [False, True]
    assert s.termination[0] == "unreachable"
    assert np.isnan(s.a[0]).all()
    assert s.termination[2] in ("converged", "deadline", "no_stable_solution")


# --- motion and planning -----------------------------------------------------------------------


def test_tracker_follows_and_snaps() -> None:
    """The buckled rod (grippers 0.8 apart) whose tip gripper turns snaps through."""
    s = rod_ig.solve([0.8, 0.0, 0.0], all=True)
    sols = s.solutions[()]
    mid = rod_ig.shape(sols, samples=3)[:, 1, 1]
    energy = rod_ig.forward(sols).energy
    up = sols[np.argmin(np.where(mid > 0, energy, np.inf))]
    t = rod_ig.Tracker(a0=up)
    moves = [t.move([0.8, 0.0, th]) for th in np.arange(1, 31) * 0.05]
    assert all(m.success for m in moves)
    snaps = [m for m in moves if m.event == "snap"]
    assert len(snaps) == 1 and snaps[0].energy_released > 0
    assert snaps[0].critical is not None and abs(snaps[0].critical[0] - 0.8) < 1e-6
    assert t.rod is not None and t.rod.shape == (3,)
    m = t.move([0.8, 0.0, 1.5])
    assert m.event == "none" and m.success


def test_planner_plans_around_a_disc() -> None:
    p = rod_ig.Planner()
    r = p.plan([0.5, 0.1, 0.1], [0.6, 0.4, 1.0], [{"type": "disc", "center": [0.3, 0.6], "radius": 0.08}])
    assert r.success, r.reason
    assert r.rods.shape[1] == 3 and r.gripper.shape == r.rods.shape
    assert r.min_margin > 0 and p.roadmap_size > 0
    assert np.allclose(r.gripper[-1][:2], [0.6, 0.4], atol=1e-6)


# --- concurrency and interruption --------------------------------------------------------------


def test_the_gil_is_released_while_a_batch_runs() -> None:
    """While one thread runs a long one-thread batch, the main thread keeps running Python:
    if the GIL were held, the counter could not move during the call."""
    a = np.tile([[2.0, -10.0, 5.0]], (150_000, 1))
    done = threading.Event()

    def work() -> None:
        rod_ig.forward(a, threads=1)
        done.set()

    worker = threading.Thread(target=work)
    count = 0
    worker.start()
    time.sleep(0.005)
    while not done.is_set():
        count += 1
    worker.join()
    assert count > 1000


def test_two_threads_compute_the_same_as_one() -> None:
    a = np.random.default_rng(1).uniform([-10, -100, -100], [10, 100, 100], size=(2000, 3))
    one = rod_ig.forward(a, threads=1)
    results: list[rod_ig.ForwardResult] = []
    threads = [threading.Thread(target=lambda: results.append(rod_ig.forward(a, threads=1))) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results + [rod_ig.forward(a, threads=3)]:
        assert np.array_equal(r.tip, one.tip, equal_nan=True)
        assert np.array_equal(r.stable, one.stable)


def test_ctrl_c_interrupts_a_long_batch() -> None:
    script = (
        "import numpy as np, rod_ig, sys\n"
        "a = np.tile([[2.0, -10.0, 5.0]], (20_000_000, 1))\n"
        "print('started', flush=True)\n"
        "rod_ig.forward(a, threads=1)\n"
        "print('finished', flush=True)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout is not None
    assert p.stdout.readline().strip() == "started"
    time.sleep(0.3)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=10)
    assert "finished" not in out
    assert "KeyboardInterrupt" in err


# --- beyond one machine: the Dask recipe -------------------------------------------------------


def test_dask_recipe_maps_the_batch_api_over_chunks() -> None:
    import dask.array as da

    from rod_ig.dask import forward_blocks

    rng = np.random.default_rng(7)
    a = rng.uniform([-10, -100, -100], [10, 100, 100], size=(20_000, 3))
    rods = da.from_array(a, chunks=(4_000, 3))
    tip, stable, margin = forward_blocks(rods)
    tip, stable, margin = (x.compute(scheduler="threads") for x in (tip, stable, margin))
    direct = rod_ig.forward(a)
    assert np.array_equal(tip, direct.tip, equal_nan=True)
    assert np.array_equal(stable, direct.stable)
    assert np.array_equal(margin, direct.margin, equal_nan=True)


def test_dask_computes_every_output_of_a_chunk_in_one_native_call(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import dask
    import dask.array as da

    from rod_ig.dask import forward_blocks_full

    calls: list[tuple[int, int | None]] = []
    native = rod_ig.forward

    def counting(a: Any, threads: int | None = None, **kw: Any) -> Any:
        calls.append((len(a), threads))
        return native(a, threads=threads, **kw)

    monkeypatch.setattr(rod_ig, "forward", counting)
    a = np.random.default_rng(3).uniform(-10, 10, size=(6_000, 3))
    f = forward_blocks_full(da.from_array(a, chunks=(2_000, 3)))
    tip, jac, stable, margin, energy = dask.compute(
        f.tip, f.jacobian, f.stable, f.margin, f.energy, scheduler="threads"
    )
    # Three chunks, one call each, one thread each (Dask runs the chunks in parallel).
    assert sorted(calls) == [(2_000, 1)] * 3
    direct = native(a)
    assert np.array_equal(jac, direct.jacobian, equal_nan=True)
    assert np.array_equal(energy, direct.energy, equal_nan=True)
    assert np.array_equal(stable, direct.stable) and tip.shape == (6_000, 3)


def test_version() -> None:
    assert isinstance(rod_ig.__version__, str) and rod_ig.__version__.count(".") == 2


def gravity_cases() -> list[dict]:
    lines = (REPO / "data" / "oracle" / "gravity_public.jsonl").read_text().splitlines()
    return [c for c in map(json.loads, lines) if c["kind"] == "planar"]


def test_weight_matches_the_public_gravity_cases() -> None:
    cases = gravity_cases()
    a = np.array([c["a"] for c in cases])
    w = np.array([c["weight"] for c in cases])
    g = np.array([c["gravity"] for c in cases])
    r = rod_ig.forward(a, weight=w, gravity=g)
    tip = np.array([[c["tip"]["x"], c["tip"]["y"], c["tip"]["theta"]] for c in cases])
    assert np.abs(r.tip - tip).max() < 1e-9
    assert np.abs(r.jacobian - np.array([c["jacobian"] for c in cases])).max() < 1e-6
    assert (r.stable == np.array([c["stable"] for c in cases])).all()
    assert np.allclose(r.energy, [c["energy"] for c in cases], rtol=1e-8, atol=1e-8)
    assert r.elastic_energy is not None and (r.elastic_energy != r.energy).any()
    assert (rod_ig.is_stable(a, weight=w, gravity=g) == r.stable).all()


def test_weight_broadcasts_and_zero_weight_is_the_weightless_rod() -> None:
    a = np.array([[2.0, -10.0, 5.0], [3.0, -2.0, -25.0]])
    plain = rod_ig.forward(a)
    zero = rod_ig.forward(a, weight=0.0)
    assert (plain.tip == zero.tip).all() and (plain.energy == zero.energy).all()
    # A scalar weight, one direction per rod, and a (3, 1) column of weights against 2 rods.
    r = rod_ig.forward(a, weight=50.0, gravity=[[0.0, -1.0], [1.0, 0.0]])
    assert r.tip.shape == (2, 3)
    grid = rod_ig.forward(a, weight=np.array([[1.0], [10.0], [100.0]]))
    assert grid.tip.shape == (3, 2, 3)
    poses = rod_ig.shape(a, samples=7, weight=50.0)
    assert poses.shape == (2, 7, 3)
    assert np.allclose(poses[:, -1], rod_ig.forward(a, weight=50.0).tip, atol=1e-12)


def test_weight_solve_reaches_heavy_targets_and_errors_name_the_argument() -> None:
    rod_ig.warm_up()
    s = rod_ig.solve([0.6, 0.0, 0.0], weight=50.0, objective="least_energy")
    assert bool(s.success)
    assert abs(float(s.a[2]) + 25.0) < 1e-4  # a rod held level: a5 = -w/2 by symmetry
    check = rod_ig.forward(s.a, weight=50.0)
    assert np.abs(check.tip - [0.6, 0.0, 0.0]).max() < 1e-6 and bool(check.stable)
    with pytest.raises(ValueError, match="weight"):
        rod_ig.forward([1.0, 2.0, 3.0], weight=-1.0)
    with pytest.raises(ValueError, match="gravity"):
        rod_ig.forward([1.0, 2.0, 3.0], weight=1.0, gravity=[0.0, 0.0])
    with pytest.raises(ValueError, match="gravity"):
        rod_ig.forward([1.0, 2.0, 3.0], weight=1.0, gravity=[0.0, 0.0, 1.0])
    with pytest.raises(TypeError, match="weight"):
        rod_ig.forward([1.0, 2.0, 3.0], weight="heavy")


def test_a_one_metre_cable_hangs_and_matches_the_long_cable_reference() -> None:
    """w = 2,000 held level 0.8 apart (issue 51): the hanging loop-free rod, on target, whose
    shape sags 0.2676 (the issue's reference); a public long cable to its 46-digit a*."""
    rod_ig.warm_up()
    s = rod_ig.solve([0.8, 0.0, 0.0], weight=2000.0, max_turns=0, deadline_ms=5000.0)
    assert bool(s.success)
    assert abs(float(s.a[2]) + 1000.0) < 1e-6
    poses = rod_ig.shape(s.a, samples=2001, weight=2000.0)
    assert abs(-poses[:, 1].min() - 0.2676) < 1e-4
    assert np.abs(poses[-1, :2] - [0.8, 0.0]).max() < 1e-9
    line = json.loads((REPO / "data" / "oracle" / "long_cables_public.jsonl").read_text().splitlines()[0])
    t = line["target"]
    r = rod_ig.solve([t["x"], t["y"], t["theta"]], weight=line["weight"], gravity=line["gravity"],
                     objective="least_energy", deadline_ms=10_000.0)
    a_star = np.array([float(v) for v in line["a_star"]])
    assert np.abs((r.a - a_star) / (1.0 + np.abs(a_star))).max() < 1e-10
    with pytest.raises(ValueError, match="max_turns"):
        rod_ig.solve([0.8, 0.0, 0.0], weight=2000.0, max_turns=1000)


def test_forward_says_when_an_f64_a_does_not_determine_its_tip() -> None:
    """Issue 51 item 1: at w = 8,000 (a public long cable), an ``a`` one ulp from the reference's
    has a condition figure beyond 1e9 and an undecided verdict, planar and 3-D, never a
    confident answer; a gently bent weightless rod is well conditioned and decided."""
    line = json.loads((REPO / "data" / "oracle" / "long_cables_public.jsonl").read_text().splitlines()[2])
    assert line["weight"] == 8000.0
    a = np.array(line["a"], dtype=float)
    a[1] = np.nextafter(a[1], np.inf)
    r = rod_ig.forward(a, weight=8000.0)
    assert r.condition is not None and float(r.condition) > 1e9
    assert bool(r.uncertain) and not bool(r.stable)
    # The same rod in 3-D (its plane x-z, gravity -z): a = (0, a3, 0, a4, 0, a5) in the
    # 3-D rod's components (a2 bends about e2 as the planar a3 does; forces along e1, e3).
    a3 = np.array([0.0, -a[0], 0.0, a[1], 0.0, a[2]])
    r3 = rod_ig.forward3d(a3, weight=8000.0, gravity=[0.0, 0.0, -1.0])
    assert r3.condition is not None and r3.uncertain is not None
    assert float(r3.condition) > 1e9 and bool(r3.uncertain) and not bool(r3.stable)
    gentle = rod_ig.forward3d([0.0, 0.5, 0.0, 0.0, 0.0, 0.0])
    assert gentle.condition is not None and gentle.uncertain is not None
    assert float(gentle.condition) < 1e3 and not bool(gentle.uncertain) and bool(gentle.stable)


def test_weight_in_3d_matches_the_public_cases_and_solves() -> None:
    lines = (REPO / "data" / "oracle" / "gravity_public.jsonl").read_text().splitlines()
    cases = [c for c in map(json.loads, lines) if c["kind"] == "3d" and c["stiffness"] == [1.0, 1.0, 1.0]]
    assert cases
    a = np.array([c["a"] for c in cases])
    r = rod_ig.forward3d(a, weight=[c["weight"] for c in cases], gravity=[c["gravity"] for c in cases])
    assert np.abs(r.position - np.array([c["tip"]["position"] for c in cases])).max() < 1e-9
    assert (r.stable == np.array([c["stable"] for c in cases])).all()
    # A heavy 3-D rod's own tip, solved back with the same weight.
    s = rod_ig.solve3d(r.position[0], r.quaternion[0], weight=cases[0]["weight"],
                       gravity=cases[0]["gravity"])
    assert bool(s.success)
    back = rod_ig.forward3d(s.a, weight=cases[0]["weight"], gravity=cases[0]["gravity"])
    assert np.abs(back.position - r.position[0]).max() < 1e-6
    with pytest.raises(ValueError, match="gravity"):
        rod_ig.forward3d(a[0], weight=1.0, gravity=[0.0, -1.0])


def test_tracker_with_weight_holds_a_heavy_rod() -> None:
    t = rod_ig.Tracker(weight=50.0)
    m = t.move([0.6, 0.0, 0.0])
    assert m.success and m.event == "none"
    assert t.rod is not None
    check = rod_ig.forward(t.rod, weight=50.0)
    assert np.abs(check.tip[:2] - [0.6, 0.0]).max() < 1e-6 and bool(check.stable)
    # theta is unwrapped (the integral of the curvature): compare modulo 2 pi.
    assert abs(np.angle(np.exp(1j * check.tip[2]))) < 1e-6
    m = t.move([0.55, 0.05, 0.1])
    assert m.success
    with pytest.raises(ValueError, match="weight"):
        rod_ig.Tracker(weight=-2.0)


def test_planner_with_weight_plans_the_heavy_rod() -> None:
    start = [1.7939773444075664, -11.347913785723009, 2.39993152353178]
    goal = [0.2413, -0.7694, -1.5494]
    p = rod_ig.Planner()
    r = p.plan(start, goal, weight=15.0, gravity=(0.0, -1.0))
    assert r.success, r.reason
    # Every rod of the plan is a stable heavy rod, and the last one's tip is the goal.
    check = rod_ig.forward(r.rods, weight=15.0, gravity=(0.0, -1.0))
    assert bool(np.all(check.stable))
    assert np.abs(check.tip[-1, :2] - goal[:2]).max() < 1e-6
    assert np.abs(r.gripper[-1, :2] - goal[:2]).max() < 1e-6
    # Weightless, the last rod's tip is elsewhere: the weight was planned for.
    assert np.abs(rod_ig.forward(r.rods[-1]).tip[:2] - goal[:2]).max() > 1e-2
    with pytest.raises(ValueError, match="weight"):
        p.plan(start, goal, weight=-1.0)


def test_the_boundary_raises_and_names_the_argument() -> None:
    """Issue 42, item 6: integers are integers, threads are bounded, failures say why."""
    a = np.zeros((3, 3)) + [1.0, 2.0, 3.0]
    for bad in (-1, 0):
        with pytest.raises(ValueError, match="threads"):
            rod_ig.forward(a, threads=bad)
    with pytest.raises(TypeError, match="threads"):
        rod_ig.forward(a, threads=1.5)  # type: ignore[arg-type]
    # A huge thread count is capped (no 50,000 threads for 3 rods), and answers as one thread.
    assert (rod_ig.forward(a, threads=50_000).tip == rod_ig.forward(a, threads=1).tip).all()
    with pytest.raises(TypeError, match="samples"):
        rod_ig.shape(a, samples=2.7)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="samples"):
        rod_ig.shape(a, samples="50")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="max_iterations"):
        rod_ig.solve([0.5, 0.2, 1.0], max_iterations=-1)
    s = rod_ig.solve([[0.5, 0.2, 1.0], [2.0, 0.0, 0.0]])
    assert s.reason[0] == "" and "unreachable" in s.reason[1]


def test_an_impossible_output_raises_memory_error() -> None:
    # 2,000 rods × 10⁶ samples × 3 doubles = 48 GB: sized before it is allocated.
    with pytest.raises(MemoryError, match="cannot allocate"):
        rod_ig.shape(np.zeros((2000, 3)), samples=10**6)
    # Above the sample bound, refused by name.
    with pytest.raises(ValueError, match="samples"):
        rod_ig.shape(np.zeros((2, 3)), samples=10**18)
    # The interpreter goes on.
    assert rod_ig.shape(np.zeros((2, 3)), samples=5).shape == (2, 5, 3)


def test_a_search_cut_by_its_deadline_says_it_is_incomplete() -> None:
    target = [-0.3, 0.4, 2.5]
    full = rod_ig.solve(target, objective="least_energy", all=True, deadline_ms=10_000)
    assert full.success and full.complete and full.starts >= 1
    # 0.05 ms cannot try every start: the answer, found or not, says so.
    cut = rod_ig.solve(target, objective="least_energy", all=True, deadline_ms=0.05)
    assert not cut.complete
    assert len(cut.solutions[()]) <= len(full.solutions[()])


def test_tracker_starts_from_the_straight_rod_at_rest() -> None:
    t = rod_ig.Tracker(a0=[0.0, 0.0, 0.0])
    assert t.rod is not None and (t.rod == 0).all()
    m = t.move([0.9, 0.0, 0.0])
    assert m.success and m.event == "buckle"
    assert t.move([0.88, 0.02, 0.05]).event in ("none", "snap")


def test_a_tracker_and_a_planner_are_shared_between_threads_and_pickled() -> None:
    import copy
    import pickle
    from concurrent.futures import ThreadPoolExecutor

    t = rod_ig.Tracker()
    targets = [[0.6 + 0.001 * i, 0.2, 0.4] for i in range(40)]
    with ThreadPoolExecutor(4) as pool:
        moves = list(pool.map(t.move, targets))
    assert all(m.success for m in moves), [m.reason for m in moves if not m.success]
    held = t.rod
    assert held is not None
    for twin in (pickle.loads(pickle.dumps(t)), copy.deepcopy(t), copy.copy(t)):
        assert np.array_equal(twin.rod, held)
        assert twin.move([0.62, 0.2, 0.4]).success
    p = rod_ig.Planner()
    with ThreadPoolExecutor(2) as pool:
        plans = list(pool.map(lambda g: p.plan([0.5, 0.1, 0.1], g), [[0.8, 0.3, 0.5]] * 2))
    assert all(r.success for r in plans), [r.reason for r in plans]
    assert pickle.loads(pickle.dumps(p)).plan([0.5, 0.1, 0.1], [0.8, 0.3, 0.5]).success


def test_one_target_gives_scalars() -> None:
    s = rod_ig.solve([0.5, 0.2, 1.0])
    assert isinstance(s.success, (bool, np.bool_)) and s.success
    assert isinstance(s.energy, (float, np.floating)) and isinstance(s.termination, str)
    assert s.a.shape == (3,)
    f = rod_ig.forward([2.0, -10.0, 5.0])
    assert isinstance(f.stable, (bool, np.bool_)) and isinstance(f.margin, (float, np.floating))
    assert f.tip.shape == (3,) and f.jacobian.shape == (3, 3)
    # Batches keep their arrays.
    assert rod_ig.solve([[0.5, 0.2, 1.0]]).success.shape == (1,)


def test_a_failure_counts_its_starts_and_says_what_was_searched() -> None:
    # Within reach but bent back on itself at full extension: no stable rod gets there.
    r = rod_ig.solve(np.array([0.999, 0.0, 3.0]))
    assert not r.success and r.termination == "no_stable_solution"
    assert r.starts > 0
    assert "Newton starts" in r.reason and "branches followed" in r.reason


def test_gripper_wrenches_balance_the_rod() -> None:
    """Issue 52, item 2: ``base_wrench``/``tip_wrench`` in forward and solve results (what the
    rod exerts on each gripper, in its own frame): the base's is ``a``; without weight the
    tip's balances it in the base frame (forces and moments about the base), with weight the
    grippers carry it; the CLI gives the same numbers."""
    a = np.array([[1.3, -20.0, 4.0], [-0.4, 35.0, -2.5], [2.0, 3.0, 1.0]])
    f = rod_ig.forward(a)
    assert f.base_wrench is not None and f.tip_wrench is not None
    np.testing.assert_array_equal(f.base_wrench.force, a[:, 1:])
    np.testing.assert_array_equal(f.base_wrench.moment, a[:, 0])
    th = f.tip[:, 2]
    fx, fy = f.tip_wrench.force[:, 0], f.tip_wrench.force[:, 1]
    wx, wy = np.cos(th) * fx - np.sin(th) * fy, np.sin(th) * fx + np.cos(th) * fy
    np.testing.assert_allclose(wx, -a[:, 1], atol=1e-9)
    np.testing.assert_allclose(wy, -a[:, 2], atol=1e-9)
    moments = a[:, 0] + f.tip_wrench.moment + f.tip[:, 0] * wy - f.tip[:, 1] * wx
    np.testing.assert_allclose(moments, 0.0, atol=1e-8)
    # With weight 5 along -y, the two grippers carry the whole weight.
    h = rod_ig.forward(a, weight=5.0)
    assert h.tip_wrench is not None
    th = h.tip[:, 2]
    fx, fy = h.tip_wrench.force[:, 0], h.tip_wrench.force[:, 1]
    np.testing.assert_allclose(a[:, 2] + np.sin(th) * fx + np.cos(th) * fy, -5.0, atol=1e-9)
    s = rod_ig.solve([0.5, 0.2, 1.0])
    assert s.base_wrench is not None and s.tip_wrench is not None
    np.testing.assert_array_equal(s.base_wrench.moment, s.a[0])
    cli = run_cli("solve", [{"target": {"x": 0.5, "y": 0.2, "theta": 1.0}}])[0]
    np.testing.assert_allclose(s.tip_wrench.force, cli["tip_wrench"]["force"], rtol=1e-12)
    base, tip = rod_ig.wrenches3d([0.3, -0.8, 1.2, 2.0, -3.0, 1.5])
    np.testing.assert_array_equal(base.moment, [0.3, -0.8, 1.2])
    assert tip.force.shape == (3,)
    # forward3d's, from its own tip (the conserved world wrench), agree with the separate call.
    f3 = rod_ig.forward3d([0.3, -0.8, 1.2, 2.0, -3.0, 1.5])
    assert f3.tip_wrench is not None
    np.testing.assert_allclose(f3.tip_wrench.force, tip.force, atol=1e-6)
    np.testing.assert_allclose(f3.tip_wrench.moment, tip.moment, atol=1e-6)
    # forward's, from its evaluation, equal the separate call's (whose tip skips the closed
    # form's phase: the last bits may differ).
    _, tip2 = rod_ig.wrenches(a)
    np.testing.assert_allclose(f.tip_wrench.moment, tip2.moment, rtol=1e-12, atol=1e-12)
    failed = rod_ig.solve([2.0, 0.0, 0.0])
    assert failed.tip_wrench is not None and np.isnan(failed.tip_wrench.moment)


def test_heavy_solves_report_turns() -> None:
    """Issue 51, item 3: with weight, ``turns`` (full turns of the tangent) as the CLI's: 0 for
    the hanging cable; without weight, None."""
    s = rod_ig.solve([[0.6, 0.0, 0.0], [2.0, 0.0, 0.0]], weight=50.0)
    assert s.turns is not None
    assert s.turns.tolist() == [0, -1]
    cli = run_cli("solve", [{"target": {"x": 0.6, "y": 0.0, "theta": 0.0}, "weight": 50.0}])[0]
    assert cli["turns"] == 0
    assert rod_ig.solve([0.5, 0.2, 1.0]).turns is None


def test_pinned_and_free_ends() -> None:
    """base_condition / tip_condition (issue 52): a free tip hangs from its base (one cable per
    weight, the least-energy stable one of ends_public A-003 and A-000), pinned ends answer a
    position with the base angle (C-002), the released moments are zero; refusals name the
    field."""
    free = rod_ig.solve(
        None,
        tip_condition="free",
        weight=[36.92695280826509, 307.54823911836],
        gravity=[[-1.0, 0.0], [0.0, -1.0]],
        all=True,
        deadline_ms=5000,
    )
    assert free.success.all()
    np.testing.assert_allclose(free.energy, [4.158152069940845, -133.55792759178848], rtol=1e-9)
    assert free.solutions is not None and [len(s) for s in free.solutions] == [2, 2]
    assert free.tip_wrench is not None
    np.testing.assert_allclose(free.tip_wrench.moment, 0.0, atol=1e-9)
    np.testing.assert_allclose(free.tip_wrench.force, 0.0, atol=1e-9)
    pinned = rod_ig.solve(
        [0.8, 0.0], base_condition="pinned", tip_condition="pinned", weight=50.0, deadline_ms=5000
    )
    assert pinned.success
    assert pinned.base_angle is not None
    assert abs(pinned.base_angle + 0.9202652225760789) < 1e-8
    assert abs(pinned.energy + 6.24283394420708) < 1e-8
    assert pinned.a[0] == 0.0 and pinned.position_error < 1e-10
    with pytest.raises(ValueError, match="tip_condition"):
        rod_ig.solve([0.8, 0.0], tip_condition="hinged")
    with pytest.raises(ValueError, match="base_condition"):
        rod_ig.solve(None, base_condition="free", tip_condition="free")
    with pytest.raises(ValueError, match="targets"):
        rod_ig.solve([0.8, 0.0], tip_condition="free")
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 2\)"):
        rod_ig.solve([0.8, 0.0, 0.0], tip_condition="pinned")
    with pytest.raises(ValueError, match="clamped ends only"):
        rod_ig.solve([0.8, 0.0], tip_condition="pinned", a0=[0.0, 1.0, 0.0])


def test_3d_pinned_and_free_ends() -> None:
    """3-D base_condition / tip_condition (issue 52): a cable between two hooks 0.8 apart at
    w = 50 is the planar one (its energy to 1e-8), with no moment at either end, and
    forward3d gives it back from its base orientation; cables hanging from a level gripper
    (free tip) have no tip wrench; a hook off every plane of the base is reached; refusals
    name the argument."""
    both = rod_ig.solve3d(
        [0.8, 0.0, 0.0], base_condition="pinned", tip_condition="pinned", weight=50.0,
        deadline_ms=5000,
    )
    assert both.success
    assert abs(both.energy + 6.24283394420708) < 1e-8
    assert both.base_wrench is not None and both.tip_wrench is not None
    np.testing.assert_allclose(both.base_wrench.moment, 0.0, atol=1e-12)
    np.testing.assert_allclose(both.tip_wrench.moment, 0.0, atol=1e-8)
    assert both.base_quaternion is not None and both.tip is not None
    back = rod_ig.forward3d(
        both.a, base_condition="pinned", tip_condition="pinned",
        base_quaternion=both.base_quaternion, weight=50.0,
    )
    assert back.stable and back.base_quaternion is not None
    np.testing.assert_allclose(back.position, [0.8, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(back.energy, both.energy, rtol=1e-9)
    # J(1): columns the base's turn and a_f (checked against differences in the crate's tests).
    assert np.isfinite(back.jacobian).all() and abs(back.jacobian[3:, 3:]).max() > 0
    free = rod_ig.solve3d(None, tip_condition="free", weight=[5.0, 50.0])
    assert free.success.all() and free.tip_wrench is not None
    np.testing.assert_allclose(free.tip_wrench.force, 0.0, atol=1e-9)
    np.testing.assert_allclose(free.tip_wrench.moment, 0.0, atol=1e-8)
    np.testing.assert_allclose(free.a[:, 3:], [[0.0, 0.0, -5.0], [0.0, 0.0, -50.0]])
    hook = rod_ig.solve3d(
        [0.6, 0.2, -0.3], tip_condition="pinned", weight=10.0, deadline_ms=5000, samples=50
    )
    assert hook.success and hook.position_error < 1e-9
    assert hook.shape is not None and hook.shape.shape == (50, 7)
    np.testing.assert_allclose(hook.shape[0, :3], 0.0, atol=1e-15)
    np.testing.assert_allclose(hook.shape[-1, :3], [0.6, 0.2, -0.3], atol=1e-9)
    # Unit length: the polyline's chords add up to just under 1.
    chords = np.linalg.norm(np.diff(hook.shape[:, :3], axis=0), axis=1).sum()
    assert 0.99 < chords <= 1.0 + 1e-12
    with pytest.raises(ValueError, match="quaternion"):
        rod_ig.solve3d([0.6, 0.2, -0.3], [0.0, 0.0, 0.0, 1.0], tip_condition="pinned")
    gripped = rod_ig.solve3d(
        [0.6, 0.2, -0.3], [0.0, 0.2, 0.0, 0.98], base_condition="pinned", weight=20.0,
        deadline_ms=5000,
    )
    assert gripped.success and gripped.position_error < 1e-9
    assert gripped.base_wrench is not None
    np.testing.assert_allclose(gripped.base_wrench.moment, 0.0, atol=1e-12)
    with pytest.raises(ValueError, match="quaternion"):
        rod_ig.solve3d([0.6, 0.2, -0.3], base_condition="pinned")
    with pytest.raises(ValueError, match="position"):
        rod_ig.solve3d([0.6, 0.2, -0.3], tip_condition="free")
    aniso = rod_ig.solve3d(None, tip_condition="free", weight=5.0, stiffness=(1.0, 1.0, 2.0))
    assert not aniso.success and aniso.termination == "invalid_input"
    assert "stiffness" in str(aniso.reason)


def test_a_tracker_with_held_ends_follows_its_gripper() -> None:
    """Tracker with pinned or free ends (issue 52, held-ends motion in Python): a pinned-pinned
    cable at w = 50 follows its gripper along five steps on its branch (event none, on target
    to 1e-9, the least-energy rod a fresh solve finds at each step); a free tip hangs as
    ``solve`` says; targets of the wrong width and clamped-only arguments raise ValueError."""
    t = rod_ig.Tracker(base_condition="pinned", tip_condition="pinned", weight=50.0, deadline_ms=5000)
    for x in np.linspace(0.8, 0.7, 5):
        m = t.move([x, 0.05])
        assert m.success and m.event == "none", m
        assert m.position_error < 1e-9 and m.a[0] == 0.0 and m.turns == 0
        fresh = rod_ig.solve(
            [x, 0.05], base_condition="pinned", tip_condition="pinned", weight=50.0, deadline_ms=5000
        )
        assert abs(m.energy - float(fresh.energy)) < 1e-8 * max(1.0, abs(m.energy))
        assert fresh.base_angle is not None and m.base_angle is not None
        assert abs(m.base_angle - float(fresh.base_angle)) < 1e-8
    held = t.rod
    assert held is not None and held.shape == (4,)
    copy = pickle.loads(pickle.dumps(t))
    again = copy.move([0.7, 0.05])
    assert again.success and abs(again.energy - m.energy) < 1e-8 * max(1.0, abs(m.energy))

    hanging = rod_ig.Tracker(tip_condition="free", weight=307.54823911836, deadline_ms=5000).move()
    free = rod_ig.solve(None, tip_condition="free", weight=307.54823911836, deadline_ms=5000)
    assert hanging.success and hanging.event == "none"
    assert abs(hanging.energy - float(free.energy)) < 1e-9 * abs(hanging.energy)
    with pytest.raises(ValueError, match="2 components"):
        t.move([0.7, 0.0, 0.0])
    with pytest.raises(ValueError, match="free tip has no target"):
        rod_ig.Tracker(tip_condition="free").move([0.5, 0.0])
    with pytest.raises(ValueError, match="clamped ends only"):
        rod_ig.Tracker(a0=[1.0, 0.0, 0.0], tip_condition="pinned")
    with pytest.raises(ValueError, match="tip_condition"):
        rod_ig.Tracker(tip_condition="hinged")


def test_a_failed_held_solve_in_a_batch_keeps_its_reason_in_place() -> None:
    """Each row of a batched held solve has one reason: a failed row once pushed two, so the
    reasons no longer matched their rows."""
    r = rod_ig.solve(
        [[1.5, 0.0], [0.8, 0.0], [2.0, 0.0]],
        base_condition="pinned",
        tip_condition="pinned",
        weight=50.0,
        deadline_ms=5000,
    )
    assert r.success.tolist() == [False, True, False]
    assert r.reason.shape == (3,) and r.reason[1] == ""
    assert "unreachable" in r.reason[0] and "unreachable" in r.reason[2]
    # Searches that find nothing (cut at once by the deadline): one reason each.
    cut = rod_ig.solve(
        [[0.8, 0.0], [0.7, 0.1], [0.6, -0.1]],
        base_condition="pinned",
        tip_condition="pinned",
        weight=50.0,
        deadline_ms=1e-6,
    )
    assert not cut.success.any() and cut.reason.shape == (3,)
    assert all("no stable equilibrium" in why for why in cut.reason), cut.reason


def test_forward_with_held_ends_gives_back_the_solved_rods() -> None:
    """forward(..., base_condition=, tip_condition=, base_angle=) (issue 52): the rods solve
    returns with pinned or free ends, given back as a (and their base angle), reproduce their
    tips (1e-9), energies (1e-8) and verdicts with the natural conditions, loop-free; a
    weightless rod from a pinned base is the closed form's clamped rod turned by its base angle;
    refusals name the argument."""
    free = rod_ig.solve(None, tip_condition="free", weight=300.0, gravity=[0.0, -1.0],
                        deadline_ms=5000)
    pinned = rod_ig.solve([0.8, 0.0], base_condition="pinned", tip_condition="pinned",
                          weight=50.0, deadline_ms=5000)
    for s, w, base, tip in ((free, 300.0, "clamped", "free"), (pinned, 50.0, "pinned", "pinned")):
        assert s.base_angle is not None and s.tip is not None
        f = rod_ig.forward(s.a, weight=w, base_condition=base, tip_condition=tip,
                           base_angle=s.base_angle)
        assert f.turns is not None and f.base_angle is not None
        np.testing.assert_allclose(f.tip[:2], s.tip[:2], atol=1e-9)
        assert abs(float(f.energy) - float(s.energy)) < 1e-8
        assert bool(f.stable) and float(f.turns) == 0.0
    phi = np.array([0.3, -1.2])
    forces = np.array([[5.0, -2.0], [-3.0, 8.0]])
    a = np.column_stack([np.zeros(2), forces])
    held = rod_ig.forward(a, base_condition="pinned", tip_condition="pinned", base_angle=phi)
    c, s_ = np.cos(phi), np.sin(phi)
    turned = np.column_stack([np.zeros(2), c * forces[:, 0] + s_ * forces[:, 1],
                              -s_ * forces[:, 0] + c * forces[:, 1]])
    clamped = rod_ig.forward(turned)
    x = c * clamped.tip[:, 0] - s_ * clamped.tip[:, 1]
    y = s_ * clamped.tip[:, 0] + c * clamped.tip[:, 1]
    np.testing.assert_allclose(held.tip[:, 0], x, atol=1e-10)
    np.testing.assert_allclose(held.tip[:, 1], y, atol=1e-10)
    with pytest.raises(ValueError, match="a pinned base holds no moment"):
        rod_ig.forward([1.0, 0.0, 0.0], base_condition="pinned", tip_condition="pinned")
    with pytest.raises(ValueError, match="base_condition"):
        rod_ig.forward([0.0, 0.0, 0.0], base_condition="hinged")
