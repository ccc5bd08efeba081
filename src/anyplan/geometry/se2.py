"""Planar rigid-motion helpers (angles in radians)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["wrap_angle", "unicycle_arc"]


def wrap_angle(a: float | np.ndarray) -> float | np.ndarray:
    """Wrap angle(s) [rad] to [-pi, pi).

    Examples:
        >>> round(wrap_angle(3 * math.pi / 2), 6)
        -1.570796
    """
    return (np.asarray(a) + math.pi) % (2.0 * math.pi) - math.pi if isinstance(a, np.ndarray) \
        else (a + math.pi) % (2.0 * math.pi) - math.pi


def unicycle_arc(x: float, y: float, theta: float, v: float, omega: float,
                 t: float | np.ndarray) -> tuple:
    """Exact pose after moving for ``t`` [s] with constant speed ``v`` [m/s] and turn rate
    ``omega`` [rad/s] from (x [m], y [m], theta [rad]); works on arrays of ``t``.

    Examples:
        >>> [round(float(c), 6) for c in unicycle_arc(0.0, 0.0, 0.0, 1.0, 0.0, 2.0)]
        [2.0, 0.0, 0.0]
    """
    t = np.asarray(t, dtype=float)
    th = theta + omega * t
    if abs(omega) < 1e-9:
        # Second-order expansion keeps the formula smooth as omega -> 0.
        xs = x + v * t * np.cos(theta + 0.5 * omega * t)
        ys = y + v * t * np.sin(theta + 0.5 * omega * t)
    else:
        xs = x + v / omega * (np.sin(th) - math.sin(theta))
        ys = y - v / omega * (np.cos(th) - math.cos(theta))
    if xs.ndim == 0:
        return float(xs), float(ys), float(th)
    return xs, ys, th
