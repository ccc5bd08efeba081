"""Planar rigid-motion helpers (angles in radians)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["wrap_angle", "unicycle_arc", "carry", "dot2", "dot2_rows", "transform_points"]


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
    # Chord form of the arc: exact, and well conditioned as omega -> 0.
    half = 0.5 * omega * t
    chord = v * t * np.sinc(half / math.pi)
    xs = x + chord * np.cos(theta + half)
    ys = y + chord * np.sin(theta + half)
    if xs.ndim == 0:
        return float(xs), float(ys), float(th)
    return xs, ys, th


def carry(points: np.ndarray, src: tuple[float, float], dst: tuple[float, float],
          turn: float) -> np.ndarray:
    """Points (N, 2) [m] at their offsets from ``src`` (x, y) [m], placed at the same offsets
    from ``dst``, turned by ``turn`` [rad]: what a robot at one pose sees, as a robot that
    believes it is at another (``turn`` = the heading difference) places it.

    Examples:
        >>> carry(np.array([[2.0, 0.0]]), (1.0, 0.0), (0.0, 0.0), math.pi / 2).round(6).tolist()
        [[0.0, 1.0]]
    """
    c, s = math.cos(turn), math.sin(turn)
    d = np.asarray(points, dtype=float).reshape(-1, 2) - (src[0], src[1])
    return np.column_stack([dst[0] + c * d[:, 0] - s * d[:, 1], dst[1] + s * d[:, 0] + c * d[:, 1]])


# numpy's ``@`` (and ``np.dot``, ``np.linalg``) call BLAS, whose kernel is chosen for the CPU
# (OpenBLAS's DYNAMIC_ARCH) and may fuse a multiply and an add: the same --deterministic run
# then differed between two machines (DynaBARN `tracked`, 249 against 247 of 400 reached). The
# products below are written out, the same IEEE operations in the same order on every machine.


def dot2(a: np.ndarray, b: np.ndarray) -> float:
    """The dot product of two planar vectors, ``a[0] b[0] + a[1] b[1]`` (the same bits on every
    machine, unlike ``a @ b``).

    Examples:
        >>> dot2(np.array([1.0, 2.0]), np.array([3.0, -1.0]))
        1.0
    """
    return float(a[0]) * float(b[0]) + float(a[1]) * float(b[1])


def dot2_rows(p: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Each row of ``p`` (N, 2) dotted with the planar vector ``b``, written out."""
    return p[:, 0] * float(b[0]) + p[:, 1] * float(b[1])


def transform_points(points: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``points @ m.T`` for points (N, 2) and a 2 x 2 matrix ``m`` (e.g. a rotation), written
    out: row i is ``(m00 x + m01 y, m10 x + m11 y)``."""
    x, y = points[:, 0], points[:, 1]
    return np.column_stack([x * float(m[0, 0]) + y * float(m[0, 1]),
                            x * float(m[1, 0]) + y * float(m[1, 1])])
