"""Immutable planar shapes: circles and simple polygons (all lengths in metres).

Rectangles are polygons built by :func:`rectangle`. Polygons may be convex or not, but must be
simple (no self-intersections); vertices are stored counter-clockwise.

Examples:
    >>> r = rectangle((0.0, 0.0), (2.0, 1.0), 0.0)
    >>> r.vertices.tolist()
    [[-1.0, -0.5], [1.0, -0.5], [1.0, 0.5], [-1.0, 0.5]]
    >>> round(r.area, 6)
    2.0
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from anyplan.geometry.se2 import transform_points

__all__ = ["Circle", "Polygon", "Shape", "rectangle", "square", "regular_polygon"]


@dataclass(frozen=True, eq=False, init=False)
class Circle:
    """A disc.

    Attributes:
        center: Centre (x [m], y [m]), shape (2,).
        radius: Radius [m], > 0.
    """

    center: np.ndarray
    radius: float

    def __init__(self, center: Sequence[float] | np.ndarray, radius: float) -> None:
        c = np.asarray(center, dtype=float).reshape(2)
        c.setflags(write=False)
        object.__setattr__(self, "center", c)
        object.__setattr__(self, "radius", float(radius))
        if not self.radius > 0.0:
            raise ValueError(f"radius must be > 0, got {self.radius}")

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Circle) and self.radius == other.radius
                and bool(np.array_equal(self.center, other.center)))

    def __hash__(self) -> int:
        return hash((self.center.tobytes(), self.radius))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Axis-aligned bounding box (xmin, ymin, xmax, ymax) [m]."""
        x, y = self.center
        r = self.radius
        return (x - r, y - r, x + r, y + r)

    def contains(self, point: np.ndarray) -> bool:
        """True if ``point`` (2,) lies in the closed disc."""
        return bool(np.hypot(*(np.asarray(point, float) - self.center)) <= self.radius)


@dataclass(frozen=True, eq=False)
class Polygon:
    """A simple polygon, vertices counter-clockwise, shape (N, 2) with N >= 3, in metres."""

    vertices: np.ndarray
    _area: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
            raise ValueError(f"a polygon needs at least 3 points (x, y), got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError("polygon points must be finite")
        area2 = float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
        if abs(area2) < 1e-12:
            raise ValueError("polygon has zero area")
        if area2 < 0.0:
            v = v[::-1].copy()
        if _self_intersects(v):
            raise ValueError("polygon edges cross each other (it must be simple)")
        v.setflags(write=False)
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "_area", abs(area2) / 2.0)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Polygon) and bool(np.array_equal(self.vertices, other.vertices))

    def __hash__(self) -> int:
        return hash(self.vertices.tobytes())

    @property
    def area(self) -> float:
        """Area [m^2]."""
        return self._area

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Axis-aligned bounding box (xmin, ymin, xmax, ymax) [m]."""
        lo = self.vertices.min(axis=0)
        hi = self.vertices.max(axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))

    @property
    def edges(self) -> np.ndarray:
        """Edges as (x0, y0, x1, y1), shape (N, 4)."""
        v = self.vertices
        return np.hstack([v, np.roll(v, -1, axis=0)])

    @property
    def is_convex(self) -> bool:
        """True if every turn is to the left (counter-clockwise)."""
        v = self.vertices
        d1 = np.roll(v, -1, axis=0) - v
        d2 = np.roll(d1, -1, axis=0)
        cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        return bool(np.all(cross >= -1e-12))


Shape = Circle | Polygon


def _self_intersects(v: np.ndarray) -> bool:
    n = len(v)
    if n <= 3:
        return False
    a = v
    b = np.roll(v, -1, axis=0)
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # adjacent through the wrap-around
            if _segments_cross(a[i], b[i], a[j], b[j]):
                return True
    return False


def _segments_cross(p1: np.ndarray, p2: np.ndarray, q1: np.ndarray, q2: np.ndarray) -> bool:
    def orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    d1, d2 = orient(q1, q2, p1), orient(q1, q2, p2)
    d3, d4 = orient(p1, p2, q1), orient(p1, p2, q2)
    return (d1 * d2 < 0.0) and (d3 * d4 < 0.0)


def rectangle(center: Sequence[float] | np.ndarray, size: Sequence[float] | np.ndarray,
              angle: float = 0.0) -> Polygon:
    """Rectangle of ``size`` (width [m], height [m]) centred at ``center``, rotated by ``angle`` [rad]."""
    w, h = (float(s) for s in size)
    if not (w > 0.0 and h > 0.0):
        raise ValueError(f"rectangle size must be positive, got {(w, h)}")
    local = np.array([[-w, -h], [w, -h], [w, h], [-w, h]], dtype=float) / 2.0
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    return Polygon(transform_points(local, rot) + np.asarray(center, dtype=float).reshape(2))


def square(center: Sequence[float] | np.ndarray, side: float) -> Polygon:
    """Axis-aligned square of side ``side`` [m] centred at ``center``."""
    return rectangle(center, (side, side), 0.0)


def regular_polygon(center: np.ndarray | tuple[float, float], radius: float, n: int,
                    circumscribed: bool = False, phase: float = 0.0) -> Polygon:
    """Regular n-gon approximating a circle.

    Args:
        center: Centre (x, y) [m].
        radius: Circle radius [m].
        n: Number of vertices, >= 3.
        circumscribed: If True the polygon contains the circle (edges tangent to it);
            otherwise it is inscribed (vertices on the circle).
        phase: Angle of the first vertex [rad].
    """
    if n < 3:
        raise ValueError("n must be >= 3")
    r = radius / np.cos(np.pi / n) if circumscribed else radius
    ang = phase + 2.0 * np.pi * np.arange(n) / n
    c = np.asarray(center, dtype=float).reshape(2)
    return Polygon(np.column_stack([c[0] + r * np.cos(ang), c[1] + r * np.sin(ang)]))
