"""What the robot's sensor can see from where it stands: range, line of sight, discs in the way.

A centre is *in view* from a viewpoint when it lies within the sensing range (None: any
distance) and the segment to it clears every occluder (the static obstacles; an exact segment
test, :meth:`~anyplan.geometry.collision.ObstacleSet.segments_clearance`). The simulated sensor
(:class:`anyplan.simulation.perception.Sensor`) detects what is in view; a tracker uses the same
rule, with the moving discs it believes in as occluders too (:meth:`FieldOfView.expected`), to
tell a track the sensor should have seen from one it could not (negative information).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from anyplan.geometry.collision import ObstacleSet

if TYPE_CHECKING:
    from anyplan.world.scenario import Scenario

__all__ = ["FieldOfView", "field_of_view"]


def field_of_view(scenario: Scenario) -> FieldOfView:
    """The view of the scenario's robot: ``robot.sensing_range``, and the static obstacles and
    an occupancy map's blocked cells (merged boxes, indexed) as occluders; the arena's walls do
    not occlude (everything is inside them)."""
    shapes = [o.shape for o in scenario.static_obstacles]
    occluders = ObstacleSet(shapes) if scenario.static_map is None \
        else scenario.static_map.obstacle_set(shapes)
    return FieldOfView(scenario.robot.sensing_range, occluders)


@dataclass(frozen=True)
class FieldOfView:
    """A sensor's view: ``range_m`` [m] (None: unlimited) and the static ``occluders``."""

    range_m: float | None
    occluders: ObstacleSet

    def line_of_sight(self, origin: tuple[float, float], centres: np.ndarray,
                      margin_m: float = 0.0) -> np.ndarray:
        """Mask (N,): centres (N, 2) [m] whose segment from ``origin`` (x, y) [m] clears every
        occluder by more than ``margin_m`` [m] (exact)."""
        n = len(centres)
        if n == 0 or len(self.occluders) == 0:
            return np.ones(n, dtype=bool)
        a = np.tile(np.asarray(origin, dtype=float), (n, 1))
        return self.occluders.segments_clearance(a, centres) > margin_m

    def visible(self, origin: tuple[float, float], centres: np.ndarray,
                margin_m: float = 0.0) -> np.ndarray:
        """Mask (N,): centres (N, 2) [m] in range of ``origin`` (x, y) [m] and in line of sight,
        with ``margin_m`` [m] to spare (inside the range by it, clear of occluders by more)."""
        c = np.asarray(centres, dtype=float).reshape(-1, 2)
        keep = np.ones(len(c), dtype=bool)
        if self.range_m is not None:
            keep &= np.hypot(c[:, 0] - origin[0], c[:, 1] - origin[1]) <= self.range_m - margin_m
        idx = np.flatnonzero(keep)
        keep[idx] = self.line_of_sight(origin, c[idx], margin_m)
        return keep

    def expected(self, origin: tuple[float, float], centres: np.ndarray,
                 radii: np.ndarray, margin_m: float = 0.0) -> np.ndarray:
        """Mask (N,): the discs (centres (N, 2), radii (N,) [m]) whose centre is in view and
        whose line of sight no other of these discs crosses (the other disc nearer to
        ``origin`` and its centre less than its radius from the segment: exact), with
        ``margin_m`` [m] to spare on each test (:meth:`visible`; the other discs grown by it).
        What a tracker may expect its sensor to detect, a person hidden behind another person
        not included; a tracker's centres are predictions, and the margin keeps those near the
        view's edges, where the truth may lie on the other side, out of its expectations."""
        c = np.asarray(centres, dtype=float).reshape(-1, 2)
        r = np.asarray(radii, dtype=float) + margin_m
        out = self.visible(origin, c, margin_m)
        if len(c) < 2 or not out.any():
            return out
        o = np.asarray(origin, dtype=float)
        d = c - o                                   # (N, 2) segments origin -> centre i
        L2 = np.maximum(d[:, 0] ** 2 + d[:, 1] ** 2, 1e-18)
        # (i, j): where on the segment to centre i the centre j projects, clipped to it
        s = (d[None, :, 0] * d[:, None, 0] + d[None, :, 1] * d[:, None, 1]) / L2[:, None]
        s = np.clip(s, 0.0, 1.0)
        px = o[0] + s * d[:, None, 0] - c[None, :, 0]
        py = o[1] + s * d[:, None, 1] - c[None, :, 1]
        crosses = np.hypot(px, py) < r[None, :]
        dist = np.hypot(d[:, 0], d[:, 1])
        nearer = dist[None, :] < dist[:, None]  # (i, j): j nearer to the origin than i
        blocked = crosses & nearer
        np.fill_diagonal(blocked, False)
        return out & ~blocked.any(axis=1)
