"""A single-query planning problem for a disc robot among static obstacles.

The planner's configuration space is the plane; the robot (a disc of ``radius``) is valid at a
point iff it touches no obstacle and stays inside the arena walls, tested exactly by
:class:`~anyplan.geometry.collision.ObstacleSet`. The arena ``bounds`` are both the walls and the
sampling domain. Straight motions are validated exactly (no resolution).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Shape

__all__ = ["Problem", "MIN_CHECK_RADIUS"]

#: Smallest radius [m] used in collision checks. The exact kernels treat *touching* as free, so
#: a true point robot (radius 0) could pass through an obstacle's interior, which has clearance
#: 0; checks therefore use at least this radius (1 micrometre).
MIN_CHECK_RADIUS = 1e-6


@dataclass(frozen=True)
class Problem:
    """Start, goal and robot radius in an :class:`ObstacleSet` with walls.

    Attributes:
        obstacles: Static obstacles; its ``bounds`` (xmin, ymin, xmax, ymax) [m] are required.
        start: Start position (x, y) [m], shape (2,).
        goal: Goal position (x, y) [m], shape (2,).
        radius: Robot radius [m], >= 0.
    """

    obstacles: ObstacleSet
    start: np.ndarray
    goal: np.ndarray
    radius: float
    check_radius: float = field(init=False)

    def __post_init__(self) -> None:
        if not isinstance(self.obstacles, ObstacleSet):
            raise TypeError(f"obstacles: expected an ObstacleSet, got {type(self.obstacles).__name__}")
        if self.obstacles.bounds is None:
            raise ValueError("obstacles.bounds: the arena bounds are required (they are the "
                             "sampling domain)")
        xmin, ymin, xmax, ymax = self.obstacles.bounds
        if not (xmax > xmin and ymax > ymin):
            raise ValueError(f"obstacles.bounds: empty arena {self.obstacles.bounds}")
        for name in ("start", "goal"):
            v = np.asarray(getattr(self, name), dtype=float).reshape(-1)
            if v.shape != (2,) or not np.all(np.isfinite(v)):
                raise ValueError(f"{name}: expected finite (x, y), got {getattr(self, name)!r}")
            v = v.copy()
            v.setflags(write=False)
            object.__setattr__(self, name, v)
        r = float(self.radius)
        if not (np.isfinite(r) and r >= 0.0):
            raise ValueError(f"radius: must be finite and >= 0, got {self.radius}")
        object.__setattr__(self, "radius", r)
        object.__setattr__(self, "check_radius", max(r, MIN_CHECK_RADIUS))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Arena (xmin, ymin, xmax, ymax) [m]."""
        return self.obstacles.bounds  # type: ignore[return-value]

    @property
    def straight_distance(self) -> float:
        """Euclidean start-goal distance [m] (c_min, the trivial lower bound)."""
        return float(np.hypot(*(self.goal - self.start)))

    def start_valid(self) -> bool:
        """True if the robot fits at the start."""
        return self.obstacles.point_free(self.start, self.check_radius)

    def goal_valid(self) -> bool:
        """True if the robot fits at the goal."""
        return self.obstacles.point_free(self.goal, self.check_radius)

    def path_valid(self, path: np.ndarray) -> bool:
        """True if the polyline ``path`` (N, 2) is collision-free for the robot."""
        return self.obstacles.path_free(path, self.check_radius)

    def with_shapes(self, extra: Iterable[Shape]) -> Problem:
        """The same problem with ``extra`` obstacles added."""
        return Problem(self.obstacles.with_shapes(extra), self.start, self.goal, self.radius)

    @classmethod
    def create(cls, obstacles: ObstacleSet, start: Sequence[float] | np.ndarray,
               goal: Sequence[float] | np.ndarray, radius: float) -> Problem:
        """Build a problem (same as the constructor; arguments converted and validated)."""
        return cls(obstacles, np.asarray(start, dtype=float), np.asarray(goal, dtype=float),
                   radius)
