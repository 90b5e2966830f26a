"""Type stubs of the native module (Rust, PyO3). Arrays are flat float64; ``rod_ig`` checks
shapes and reshapes."""

from typing import Any

import numpy as np
import numpy.typing as npt

__version__: str

def forward(
    a: npt.NDArray[np.float64],
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> dict[str, Any]: ...
def forward_held(
    a: npt.NDArray[np.float64],
    base_angle: npt.NDArray[np.float64],
    base_condition: str,
    tip_condition: str,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
    tip_load: tuple[float, float] | None = None,
) -> dict[str, Any]: ...
def is_stable(
    a: npt.NDArray[np.float64],
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> npt.NDArray[np.bool_]: ...
def shape(
    a: npt.NDArray[np.float64],
    samples: int,
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> npt.NDArray[np.float64]: ...
def solve(
    targets: npt.NDArray[np.float64],
    a0: npt.NDArray[np.float64] | None = None,
    objective: str = "first",
    method: str = "robust",
    deadline_ms: float | None = None,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    alpha: float | None = None,
    all: bool = False,
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
    max_turns: int = 0,
) -> dict[str, Any]: ...
def solve_held(
    n: int,
    targets: npt.NDArray[np.float64] | None = None,
    base_condition: str = "clamped",
    tip_condition: str = "clamped",
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
    all: bool = False,
    deadline_ms: float | None = None,
    max_turns: int = 0,
    threads: int | None = None,
    tip_load: tuple[float, float] | None = None,
    samples: int = 0,
) -> dict[str, Any]: ...
def solve_held3d(
    n: int,
    positions: npt.NDArray[np.float64] | None = None,
    base_condition: str = "clamped",
    tip_condition: str = "free",
    stiffness: tuple[float, ...] = (1.0, 1.0, 1.0),
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
    all: bool = False,
    deadline_ms: float | None = None,
    max_turns: int = 0,
    threads: int | None = None,
    quaternions: npt.NDArray[np.float64] | None = None,
    samples: int = 0,
) -> dict[str, Any]: ...
def forward_held3d(
    a: npt.NDArray[np.float64],
    base_condition: str,
    tip_condition: str,
    base_quaternion: npt.NDArray[np.float64] | None = None,
    stiffness: tuple[float, ...] = (1.0, 1.0, 1.0),
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> dict[str, Any]: ...
def wrenches(
    a: npt.NDArray[np.float64],
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> dict[str, Any]: ...
def turns(
    a: npt.NDArray[np.float64],
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> npt.NDArray[np.int64]: ...
def wrenches3d(
    a: npt.NDArray[np.float64],
    stiffness: tuple[float, ...] = (1.0, 1.0, 1.0),
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> dict[str, Any]: ...
def forward3d(
    a: npt.NDArray[np.float64],
    stiffness: tuple[float, ...] = (1.0, 1.0, 1.0),
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> dict[str, Any]: ...
def solve3d(
    position: npt.NDArray[np.float64],
    quaternion: npt.NDArray[np.float64],
    a0: npt.NDArray[np.float64] | None = None,
    objective: str = "first",
    method: str = "robust",
    deadline_ms: float | None = None,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    alpha: float | None = None,
    stiffness: tuple[float, ...] = (1.0, 1.0, 1.0),
    all: bool = False,
    threads: int | None = None,
    weight: npt.NDArray[np.float64] | None = None,
    gravity: npt.NDArray[np.float64] | None = None,
) -> dict[str, Any]: ...
def warm_up() -> int: ...

class Tracker:
    def __init__(
        self,
        a0: list[float] | None = None,
        deadline_ms: float | None = None,
        tolerance: float | None = None,
        weight: float = 0.0,
        gravity: tuple[float, float] = (0.0, -1.0),
    ) -> None: ...
    def move(self, target: list[float]) -> dict[str, Any]: ...
    @property
    def rod(self) -> list[float] | None: ...

class HeldTracker:
    def __init__(
        self,
        base_condition: str,
        tip_condition: str,
        deadline_ms: float | None = None,
        weight: float = 0.0,
        gravity: tuple[float, float] = (0.0, -1.0),
        max_turns: int = 0,
        tip_load: tuple[float, float] | None = None,
    ) -> None: ...
    def move(self, target: list[float] | None = None) -> dict[str, Any]: ...
    @property
    def rod(self) -> list[float] | None: ...

class Planner:
    def __init__(self) -> None: ...
    def plan(
        self,
        start: list[float],
        goal: list[float],
        obstacles: list[dict[str, Any]] = ...,
        deadline_ms: float = 500.0,
        weight: float = 0.0,
        gravity: tuple[float, float] = (0.0, -1.0),
    ) -> dict[str, Any]: ...
    @property
    def roadmap_size(self) -> int: ...
def _time_evaluate(a: npt.NDArray[np.float64]) -> float: ...
