"""A cosseratbench experiment with an exact reference (issue 52, item 3): the heavy elastica
clamped at both ends, entry point ``heavy_elastica`` of ``cosseratbench.experiments``.

A 1 m cable clamped level at both ends, 0.8 m apart, sags under its own weight. The
dimensionless weight w = rho*A*g*L^3/EI runs from 1 (a stiff rod, barely sagging) to 1,000 (a
cable with boundary layers at the clamps); gravity is vertical ("level") or turned by
``tilt_deg`` in the rod's plane. No scenario of the suite has this case with an exact
answer: the reference is the inextensible, unshearable Kirchhoff rod's equilibrium, solved
here by scipy's ``solve_bvp`` (tolerance 1e-9) from a start given by rod-ig, so it checks
rod-ig as much as any other solver. The cable is stiff in stretch (EA/EI = 1.6e5 m^-2): the
stretch under its weight is rho*g*L/E, 0.6 % at w = 1,000.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

import rod_ig

FloatArray = npt.NDArray[np.float64]

LENGTH = 1.0
SPAN = 0.8
RADIUS = 0.005
DENSITY = 1000.0
GRAVITY = 9.81


def _second_moment() -> float:
    return float(np.pi * RADIUS**4 / 4.0)


def _area() -> float:
    return float(np.pi * RADIUS**2)


def _youngs_modulus(weight: float) -> float:
    """E that gives the cable the dimensionless weight ``weight``."""
    ei = DENSITY * _area() * GRAVITY * LENGTH**3 / weight
    return ei / _second_moment()


# Length of the straight, level piece at each end of the starting shape: every solver's first
# and last element then starts level (clamps hold an end as it starts) down to 20 elements.
FLAT = 0.05


def _initial_centerline(n_points: int = 201) -> FloatArray:
    """A smooth start of length 1 between the clamps, straight and level over its first and
    last ``FLAT``, between them z = -A (1 - cos(2 pi u / b)) / 2 over the base b = d - 2 FLAT,
    A chosen by bisection so that the whole is the cable's length (not the answer)."""
    base = SPAN - 2.0 * FLAT
    u = np.linspace(0.0, base, 4001)

    def length(a: float) -> float:
        dz = a * np.pi / base * np.sin(2.0 * np.pi * u / base)
        return float(np.trapezoid(np.hypot(1.0, dz), u)) + 2.0 * FLAT

    lo, hi = 0.0, 1.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if length(mid) < LENGTH else (lo, mid)
    amplitude = 0.5 * (lo + hi)
    us = np.linspace(0.0, base, n_points)
    z = -amplitude * (1.0 - np.cos(2.0 * np.pi * us / base)) / 2.0
    middle = np.stack([FLAT + us, np.zeros_like(us), z], axis=1)
    return np.vstack([[0.0, 0.0, 0.0], middle, [SPAN, 0.0, 0.0]])


def build(weight: float, tilt_deg: float) -> Any:
    """The scenario: clamped level at both ends, gravity turned by ``tilt_deg`` about y."""
    from cosseratbench.scenario import EndCondition, Material, Rod, Scenario

    e = _youngs_modulus(weight)
    tilt = np.radians(tilt_deg)
    return Scenario(
        rods=(
            Rod(
                centerline=tuple(map(tuple, _initial_centerline())),
                radius=RADIUS,
                material=Material(youngs_modulus=e, shear_modulus=e / 3.0, density=DENSITY),
                normal=(0.0, 1.0, 0.0),
                start=EndCondition.CLAMPED,
                end=EndCondition.CLAMPED,
            ),
        ),
        duration=5.0,
        gravity=(GRAVITY * float(np.sin(tilt)), 0.0, -GRAVITY * float(np.cos(tilt))),
        quasi_static=True,
        self_contact=False,  # a cable hanging between two level clamps cannot reach itself
    )


def _rhs(load: FloatArray) -> Any:
    """The inextensible heavy rod in arc length, state (x, z, theta, kappa, n_x, n_z)."""

    def f(s: FloatArray, y: FloatArray) -> FloatArray:
        x, z, th, k, nx, nz = y
        c, sn = np.cos(th), np.sin(th)
        return np.vstack(
            [c, sn, k, nx * sn - nz * c, -load[0] * np.ones_like(s), -load[1] * np.ones_like(s)]
        )

    return f


def reference_curve(scenario: Any, n_points: int = 2001) -> FloatArray:
    """The exact equilibrium of ``scenario`` (module docs), metres, world frame."""
    from scipy.integrate import solve_bvp  # type: ignore[import-untyped]

    rod = scenario.rods[0]
    # The polyline's length (a hair under 1 m), as every solver reads it.
    length = rod.length
    span = SPAN / length
    ei = rod.material.youngs_modulus * rod.second_moment_of_area
    g = np.asarray(scenario.gravity, float)
    w = rod.material.density * rod.area * float(np.linalg.norm(g)) * length**3 / ei
    # The rod's plane is x-z: base frame x = world x, y = world z.
    direction = (g[0] / np.linalg.norm(g), g[2] / np.linalg.norm(g))
    start = rod_ig.solve(
        [[span, 0.0, 0.0]],
        weight=[w],
        gravity=[direction],
        objective="least_energy",
        deadline_ms=5000.0,
    )
    if not bool(np.asarray(start.success).all()):
        raise RuntimeError(f"no start for the reference: {np.asarray(start.reason).ravel()[0]}")
    a = np.asarray(start.a).reshape(3)
    s = np.linspace(0.0, 1.0, 401)
    shape = np.asarray(rod_ig.shape(a, samples=len(s), weight=w, gravity=direction)).reshape(-1, 3)
    load = w * np.asarray(direction)
    n0 = np.array([a[1], a[2]])
    n = n0[:, None] - load[:, None] * s[None, :]
    kappa = np.gradient(shape[:, 2], s)
    guess = np.vstack([shape[:, 0], shape[:, 1], shape[:, 2], kappa, n[0], n[1]])

    def bc(ya: FloatArray, yb: FloatArray) -> FloatArray:
        return np.array([ya[0], ya[1], ya[2], yb[0] - span, yb[1], yb[2]])

    sol = solve_bvp(_rhs(load), bc, s, guess, tol=1e-9, max_nodes=200_000)
    if not sol.success:
        raise RuntimeError(f"the reference did not converge: {sol.message}")
    t = np.linspace(0.0, 1.0, n_points)
    y = sol.sol(t)
    return np.stack([y[0] * length, np.zeros_like(t), y[1] * length], axis=1)


def shape_error(scenario: Any, trajectory: Any) -> float:
    """Largest distance from a final node to the exact equilibrium, in rod lengths."""
    from cosseratbench.metrics import max_distance_to_curve

    reference = reference_curve(scenario)
    return max_distance_to_curve(trajectory.positions[0][-1], reference) / LENGTH


def sag_error(scenario: Any, trajectory: Any) -> float:
    """Relative error of the lowest point's depth."""
    reference = reference_curve(scenario)[:, 2].min()
    return float(abs(trajectory.positions[0][-1][:, 2].min() - reference) / abs(reference))


def _make() -> Any:
    from cosseratbench.experiment import Experiment, Parameter
    from cosseratbench.metrics import settling_residual

    return Experiment(
        name="heavy_elastica",
        description="Cable clamped level at both ends sagging under its weight, "
        "w = 1 ... 1000, against the exact inextensible equilibrium.",
        build=build,
        parameters=(
            Parameter(
                "weight",
                default=100.0,
                values=(1.0, 10.0, 100.0, 1000.0),
                description="rho*A*g*L^3/EI: a stiff rod at 1, a cable with boundary layers "
                "at the clamps at 1000.",
            ),
            Parameter(
                "tilt_deg",
                default=0.0,
                values=(0.0, 45.0),
                unit="deg",
                description="Gravity turned in the rod's plane: the sag leans to one side.",
            ),
        ),
        reference=lambda scenario: (reference_curve(scenario),),
        metrics={
            "shape_error": shape_error,
            "sag_error": sag_error,
            "settling_residual": settling_residual,
        },
        notes=(
            "A cable clamped level at both ends, 0.8 of its length apart, sags under its "
            "weight. At w = 1000 the clamps hold it in boundary layers a few percent of its "
            "length wide: an element count that does not resolve them bends it wrongly there. "
            "The reference is exact for an inextensible rod; the cable stretches by "
            "rho*g*L/E under its weight (0.6 % at w = 1000), which solvers that model stretch "
            "show as a slightly deeper sag."
        ),
    )


def __getattr__(name: str) -> Any:
    """``heavy_elastica``, the Experiment (built on first use: cosseratbench is optional)."""
    if name == "heavy_elastica":
        return _make()
    raise AttributeError(name)
