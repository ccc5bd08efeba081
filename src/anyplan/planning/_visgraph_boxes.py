"""Visibility-graph nodes for axis-aligned boxes (a map's merged cells), by convex corners.

The boxes of an :class:`~anyplan.geometry.collision.ObstacleSet` (``obstacles.boxes``) are
disjoint or touching; their union is the obstacle. The shortest path of a disc robot of radius
r among the union bends only on the arcs of radius r around the union's *convex* corners: the
corners of a box whose two side-adjacent quadrants are not covered by a box (near a point, each
closed box covers whole quadrants, so a quadrant is covered iff one box covers it). A corner
whose diagonal quadrant is covered is a pinch point of two convex corners and is kept (a point
robot may pass there; for r > 0 its arc lies in the other box and its nodes are filtered out).
Concave corners, corners inside the union and seams between boxes give no node, which prunes
most of the thousands of box corners of a map.

The coverage test probes each quadrant at ``probe`` [m] from the corner with the exact point
clearance of the boxes (0 iff covered); it is exact when no two box edges are closer than the
probe without coinciding, true of grid maps (edges on the lattice of the cell size).
"""

from __future__ import annotations

import math

import numpy as np

from anyplan.geometry.collision import ObstacleSet

__all__ = ["convex_box_corners", "corner_arcs", "inscribed_radius"]

_PROBE = 1e-6


def convex_box_corners(boxes: np.ndarray, probe: float = _PROBE,
                       obstacles: ObstacleSet | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Convex corners of the union of ``boxes`` (M, 4) [m].

    Returns:
        corners (K, 2) [m] and, for each, the unit direction (K, 2) of its free quadrant's
        diagonal (e.g. (-1, -1) / sqrt 2 for a box's lower-left corner).
    """
    b = np.asarray(boxes, dtype=float).reshape(-1, 4)
    if len(b) == 0:
        return np.zeros((0, 2)), np.zeros((0, 2))
    obs = obstacles if obstacles is not None else ObstacleSet([], boxes=b)
    cx = np.concatenate([b[:, 0], b[:, 2], b[:, 2], b[:, 0]])
    cy = np.concatenate([b[:, 1], b[:, 1], b[:, 3], b[:, 3]])
    # direction from the corner into its box: (+,+) lower-left, (-,+) lower-right, ...
    m = len(b)
    qx = np.repeat([1.0, -1.0, -1.0, 1.0], m)
    qy = np.repeat([1.0, 1.0, -1.0, -1.0], m)
    free = np.ones(4 * m, dtype=bool)
    for sx, sy in ((-1.0, 1.0), (1.0, -1.0)):
        pts = np.column_stack([cx + probe * sx * qx, cy + probe * sy * qy])
        free &= obs.clearances(pts) > 0.0
    c = np.column_stack([cx, cy])[free]
    d = -np.column_stack([qx, qy])[free] / math.sqrt(2.0)
    return c, d


def corner_arcs(corners: np.ndarray, dirs: np.ndarray, rad: float, arc_step: float,
                circumscribed: bool, grow: float,
                arc: object) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The chain of graph nodes around each convex corner: (nodes, before, after) where
    ``before``/``after`` continue the chain along the inflated box edges (tangent test).

    ``arc`` is the visibility graph's chain builder ``arc(center, rad, a0, a1, step, circ)``.
    """
    out = []
    for c, d in zip(corners, dirs, strict=True):
        phi = math.atan2(d[1], d[0])
        a0 = phi - math.pi / 4.0
        a1 = phi + math.pi / 4.0
        d_prev = np.array([-math.sin(a0), math.cos(a0)])
        d_next = np.array([-math.sin(a1), math.cos(a1)])
        if rad <= 0.0:
            pts = np.asarray(c, dtype=float)[None, :]
        else:
            pts = arc(c, rad * grow, a0, a1, arc_step, circumscribed)  # type: ignore[operator]
        out.append((pts, pts[0] - d_prev, pts[-1] + d_next))
    return out


def inscribed_radius(rad: float, arc_step: float) -> float:
    """Distance [m] from a corner to the chords of its inscribed 90-degree chain of radius
    ``rad`` (the chain of :func:`corner_arcs` with ``circumscribed=False``)."""
    k = max(1, math.ceil((math.pi / 2.0) / arc_step - 1e-12))
    return rad * math.cos((math.pi / 2.0) / k / 2.0)
