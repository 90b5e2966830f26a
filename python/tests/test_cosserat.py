"""The cosseratbench plug-in (issue 52, item 3): rod-ig found by the suite's entry point,
run through the suite's own runner, right where its model applies and reported unsupported,
with the reason, where it does not. cosseratbench is installed by CI (scripts/test-all.sh)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cosseratbench import registry

from rod_ig.cosserat import RodIg


def test_the_suite_finds_rod_ig_by_its_entry_point() -> None:
    assert "rod-ig" in registry.names(registry.SOLVERS)
    assert isinstance(registry.load_solver("rod-ig"), RodIg)


def test_the_cantilever_is_the_exact_elastica() -> None:
    """Tip load 7.5e-3 N on a clamped beam (w = 0, P L^2/EI = 0.0955): the suite's reference
    is Euler-Bernoulli's linear deflection F L^3 / 3EI; the exact elastica deflects 4.07e-4
    less (relative), the figure a scipy solve_bvp of the same elastica gives (issue 52), and
    rod-ig's error is that at every element count."""
    experiment = registry.load_experiment("cantilever")
    scenario = experiment.scenario
    for n in (10, 20, 80):
        trajectory = RodIg().run(scenario, n_elements=n, n_frames=3)
        assert trajectory.positions[0].shape == (3, n + 1, 3)
        error = experiment.metrics["tip_deflection_error"](scenario, trajectory)
        assert abs(error - 4.068e-4) < 2e-6, error
        # The directors stay unit and normal to their elements.
        d = trajectory.directors[0][-1]
        e = np.diff(trajectory.positions[0][-1], axis=0)
        assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
        assert np.abs(np.sum(d * e, axis=1)).max() < 1e-9


def test_the_stiff_catenary_matches_the_elastic_catenary() -> None:
    """The catenary at E = 1e7 Pa (w = 157): within the suite's reference by its own metrics
    (the reference stretches by ~0.1 % and ignores bending; rod-ig is inextensible and bends:
    shape 1.66e-3, sag 3.4e-4 measured, asserted 2.5e-3 and 1e-3)."""
    experiment = registry.load_experiment("catenary")
    scenario = experiment.scenario_for(youngs_modulus=1e7)
    trajectory = RodIg().run(scenario, n_elements=50, n_frames=2)
    assert experiment.metrics["shape_error"](scenario, trajectory) < 2.5e-3
    assert experiment.metrics["sag_error"](scenario, trajectory) < 1e-3


def test_what_rod_ig_does_not_model_is_refused_with_the_reason() -> None:
    pendulum = registry.load_experiment("pendulum").scenario
    with pytest.raises(NotImplementedError, match="static equilibria only"):
        RodIg().run(pendulum, n_elements=10, n_frames=2)
    soft = registry.load_experiment("catenary").scenario_for(youngs_modulus=1e5)
    with pytest.raises(NotImplementedError, match="beyond rod-ig's"):
        RodIg().run(soft, n_elements=10, n_frames=2)


def test_the_suites_runner_runs_rod_ig(tmp_path: Path) -> None:
    cli = Path(sys.executable).with_name("cosseratbench")
    out = subprocess.run(
        [str(cli), "run", "cantilever", "pendulum", "-s", "rod-ig", "-o", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    ).stdout
    assert "tip_deflection_error=4.068e-04" in out, out
    assert "unsupported" in out and "static equilibria only" in out, out


def test_the_heavy_elastica_experiment_has_an_exact_reference() -> None:
    """rod-ig's own experiment (entry point heavy_elastica): a cable clamped level at both
    ends, 0.8 apart. Its reference, scipy's solve_bvp of the inextensible heavy elastica at
    tolerance 1e-9, and rod-ig's answer agree to 1e-6 of the length, from the stiff rod
    (w = 1) to the cable (w = 1000) and with gravity tilted by 45 degrees."""
    experiment = registry.load_experiment("heavy_elastica")
    for changes in ({"weight": 1.0}, {"weight": 1000.0}, {"tilt_deg": 45.0}):
        scenario = experiment.scenario_for(**changes)
        trajectory = RodIg().run(scenario, n_elements=50, n_frames=2)
        assert experiment.metrics["shape_error"](scenario, trajectory) < 1e-6, changes
        # Frame 0 is the starting shape, level at both clamps.
        first = trajectory.positions[0][0]
        assert abs(first[1, 2] - first[0, 2]) < 1e-12 and abs(first[-1, 2] - first[-2, 2]) < 1e-12
