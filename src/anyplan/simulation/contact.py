"""Who caused a collision: the robot's approach speed towards what it hit, at first contact.

A collision is **robot-caused** when, at the first contact, the robot's own velocity has a
component of more than :data:`ROBOT_CAUSED_SPEED` (0.05 m/s) *towards* the obstacle it hit:

* a static obstacle or a wall: towards the point of the obstacle nearest to the robot's centre;
* a moving disc: along the line from the robot's centre to the disc's centre.

A robot at rest that is run into, or one swiped from the side while driving past, has no such
component: the contact is not its doing. The classification itself is the pure function
:func:`robot_caused`; :func:`static_contact` and :func:`disc_contact` find the contact instant
inside one simulation step exactly (the robot and the obstacles move along straight chords over
the step, as in the simulator's collision test).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.moving import closest_approach_straight, first_contact_straight
from anyplan.geometry.shapes import Circle, Polygon
from anyplan.world.motion import Jump

__all__ = ["ROBOT_CAUSED_SPEED", "approach_speed", "robot_caused", "nearest_obstacle_point",
           "static_contact", "disc_contact", "step_pieces"]

#: Speed [m/s] towards the obstacle above which a contact counts as robot-caused.
ROBOT_CAUSED_SPEED = 0.05


def approach_speed(robot_velocity: Sequence[float] | np.ndarray,
                   robot_position: Sequence[float] | np.ndarray,
                   obstacle_point: Sequence[float] | np.ndarray) -> float:
    """Component [m/s] of the robot's velocity towards ``obstacle_point``.

    Args:
        robot_velocity: The robot's velocity (vx, vy) [m/s] at contact.
        robot_position: The robot's centre (x, y) [m] at contact.
        obstacle_point: The nearest point of a static obstacle, or a moving disc's centre [m].

    Returns:
        ``v . (q - p) / |q - p|``; positive when the robot moves towards the obstacle, 0 when
        the two points coincide (no direction).
    """
    d = np.asarray(obstacle_point, dtype=float) - np.asarray(robot_position, dtype=float)
    n = math.hypot(d[0], d[1])
    if n <= 0.0:
        return 0.0
    v = np.asarray(robot_velocity, dtype=float)
    return float((v[0] * d[0] + v[1] * d[1]) / n)


def robot_caused(robot_velocity: Sequence[float] | np.ndarray,
                 robot_position: Sequence[float] | np.ndarray,
                 obstacle_point: Sequence[float] | np.ndarray,
                 threshold: float = ROBOT_CAUSED_SPEED) -> bool:
    """True when the robot approached the obstacle at more than ``threshold`` [m/s].

    See :func:`approach_speed` for the arguments.

    Examples:
        >>> robot_caused((0.4, 0.0), (0.0, 0.0), (0.6, 0.0))   # head-on
        True
        >>> robot_caused((0.0, 0.0), (0.0, 0.0), (-0.6, 0.0))  # parked, rear-ended
        False
    """
    return approach_speed(robot_velocity, robot_position, obstacle_point) > threshold


def _nearest_on_polygon(v: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, float]:
    a = v
    b = np.roll(v, -1, axis=0)
    ab = b - a
    ll = np.einsum("ij,ij->i", ab, ab)
    s = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.where(ll > 0.0, ll, 1.0), 0.0, 1.0)
    q = a + s[:, None] * ab
    d = np.hypot(*(q - p).T)
    i = int(np.argmin(d))
    return q[i], float(d[i])


def nearest_obstacle_point(obstacles: ObstacleSet, point: Sequence[float] | np.ndarray
                           ) -> np.ndarray:
    """The point of the static obstacles or walls nearest to ``point`` [m] (outside all of
    them, inside the arena), exactly: projections on circles, polygon edges and the walls."""
    p = np.asarray(point, dtype=float).reshape(2)
    best_d = math.inf
    best = p.copy()
    for s in obstacles.shapes:
        if isinstance(s, Circle):
            d = p - s.center
            n = math.hypot(d[0], d[1])
            q = s.center + (d / n * s.radius if n > 0.0 else np.array([s.radius, 0.0]))
            dist = abs(n - s.radius)
        elif isinstance(s, Polygon):
            q, dist = _nearest_on_polygon(s.vertices, p)
        else:  # pragma: no cover - ObstacleSet admits only these
            continue
        if dist < best_d:
            best_d, best = dist, q
    if obstacles.bounds is not None:
        xmin, ymin, xmax, ymax = obstacles.bounds
        walls = [(p[0] - xmin, (xmin, p[1])), (xmax - p[0], (xmax, p[1])),
                 (p[1] - ymin, (p[0], ymin)), (ymax - p[1], (p[0], ymax))]
        for dist, q in walls:
            if dist < best_d:
                best_d, best = dist, np.array(q, dtype=float)
    return best


def static_contact(obstacles: ObstacleSet, a: np.ndarray, b: np.ndarray, radius: float,
                   iterations: int = 50) -> float:
    """Fraction s in [0, 1] of the chord a -> b [m] where a disc of ``radius`` [m] first touches
    a static obstacle or wall (1.0 if it does not): bisection on the exact clearance of the
    prefix a -> a + s (b - a), which does not increase with s."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if obstacles.clearance(a) <= radius:
        return 0.0
    if obstacles.segment_clearance(a, b) > radius:
        return 1.0
    lo, hi = 0.0, 1.0
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        if obstacles.segment_clearance(a, a + mid * (b - a)) > radius:
            lo = mid
        else:
            hi = mid
    return hi


def disc_contact(p: np.ndarray, u: np.ndarray, q: np.ndarray, w: np.ndarray, reach: float,
                 t0: float, t1: float) -> float:
    """Time [s] in [t0, t1] at which ``p + u t`` and ``q + w t`` first come within ``reach``
    [m]; the time of closest approach if they never do (a contact within the tolerance)."""
    tc = first_contact_straight(p, u, q, w, reach, t0, t1)
    if tc is not None:
        return float(tc)
    return closest_approach_straight(p, u, q, w, t0, t1)[0]


def step_pieces(jumps: tuple[Jump, ...], p_old: np.ndarray, p_new: np.ndarray, j: int,
                t0: float, dt: float, s0: float, s1: float
                ) -> list[tuple[np.ndarray, np.ndarray, float, float]]:
    """The straight pieces of a moving obstacle's motion over one step, as (position at s = 0
    [m], velocity [m/s], s_start, s_end) with s the time [s] since the step's start: one chord
    from ``p_old`` to ``p_new[j]``, or, across a jump (an open DynaBARN track restarting), a
    chord to the position before it and one from the position after it, so that the teleport
    is not tested as a motion. ``p_new[j]`` is set to the position after a jump at the step's
    end (the motion's own position there may round to either side)."""
    if not jumps:
        return [(p_old, (p_new[j] - p_old) / dt, s0, s1)]
    if jumps[-1].time >= t0 + dt - 1e-9:
        p_new[j] = jumps[-1].after
    pieces = []
    start_s, start_p = 0.0, p_old
    for jump in (*jumps, None):
        end_s = dt if jump is None else min(max(jump.time - t0, start_s), dt)
        end_p = p_new[j] if jump is None else jump.before
        a, b = max(start_s, s0), min(end_s, s1)
        if b >= a:
            span = end_s - start_s
            w = (end_p - start_p) / span if span > 1e-12 else np.zeros(2)
            pieces.append((start_p - w * start_s, w, a, b))
        if jump is not None:
            start_s, start_p = end_s, jump.after
    return pieces
