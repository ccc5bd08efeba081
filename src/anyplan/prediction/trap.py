"""Whether a robot is trapped: every place it could be is inside one predicted disc.

:func:`first_trap` bounds where any motion from the robot's state can be ``tau`` seconds later
(within :func:`reach_m` of its position: the speed stays within v_max and changes by at most
a_max, whatever the heading, the turns or the waits) and finds the first time on a grid at
which one predicted disc, grown by the robot's radius and a margin, holds that whole disc.
Then every motion from that state meets that obstacle by that time: the paths of a search,
their waits and timings alike, so a search for a collision-free motion cannot succeed
(``st-bitstar`` skips it, ``docs/spacetime.md``). The test is sufficient, not necessary:
a robot hemmed in by two discs, none of which holds its whole reach, is not reported.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from anyplan.prediction.base import PredictedObstacle

__all__ = ["Trap", "first_trap", "reach_m"]

#: Slack on the robot's limits (a motion may start up to 0.01 m/s off the state's speed) and
#: on the distances [m]: the bound stays a bound under rounding.
_SPEED_SLACK = 0.02
_LIMIT_FACTOR = 1.01
_DIST_SLACK = 1e-3
#: [s] how long before t0 a jump is still taken into account (rounding: a jump at t0 counts).
_JUMP_BEFORE_S = 1e-6


def reach_m(speed: float, v_max: float, a_max: float, tau: np.ndarray) -> np.ndarray:
    """The farthest [m] a robot at ``speed`` [m/s] can be from where it is after ``tau`` [s]
    (N,), its speed bounded by ``v_max`` [m/s] and changing by at most ``a_max`` [m/s^2].

    Examples:
        >>> reach_m(0.0, 1.0, 1.0, np.array([0.0, 0.5, 2.0])).tolist()
        [0.0, 0.125, 1.5]
    """
    v0 = min(abs(float(speed)), float(v_max))
    t_top = (float(v_max) - v0) / float(a_max)
    tau = np.asarray(tau, dtype=float)
    ramp = v0 * tau + 0.5 * a_max * tau * tau
    top = v0 * t_top + 0.5 * a_max * t_top * t_top + v_max * (tau - t_top)
    return np.where(tau <= t_top, ramp, top)


@dataclass(frozen=True)
class Trap:
    """The first time ``t`` [s] at which ``obstacle``'s disc holds every place the robot can be."""

    t: float
    obstacle: str


def first_trap(preds: Sequence[PredictedObstacle], position: tuple[float, float], speed: float,
               t0: float, radius: float, v_max: float, a_max: float, margin: float,
               horizon_s: float, step_s: float = 0.02, reach_cap_m: float = math.inf
               ) -> Trap | None:
    """The first time on a grid of ``step_s`` [s] over [t0, t0 + horizon_s] at which one of
    ``preds`` holds the robot's whole reach (:func:`reach_m` from ``speed`` [m/s] at
    ``position`` [m] at ``t0`` [s]) within its contact distance: the robot's ``radius`` plus
    the disc's radius then plus ``margin`` [m], the distance the collision checks of
    :mod:`anyplan.prediction.collision` use; only while the reach is shorter than
    ``reach_cap_m`` [m] (e.g. while no motion can have ended at a goal, where its check
    stops). None if there is no such time.

    Examples:
        A disc of 0.5 m coming head-on at 1 m/s, 0.2 m from a robot of 0.3 m at rest (contact
        at 0.85 m between centres with a 0.05 m margin): the robot cannot get out of its way.
        From 2 m away it can (it reaches 0.5 m sideways before the disc arrives):

        >>> from anyplan.world.motion import UnicycleMotion
        >>> near = PredictedObstacle("P", 0.5, UnicycleMotion(1.0, 0.0, math.pi, 1.0))
        >>> trap = first_trap([near], (0.0, 0.0), 0.0, 0.0, 0.3, 1.0, 1.0, 0.05, 3.0)
        >>> trap.obstacle, round(trap.t, 2)
        ('P', 0.18)
        >>> far = PredictedObstacle("P", 0.5, UnicycleMotion(2.0, 0.0, math.pi, 1.0))
        >>> first_trap([far], (0.0, 0.0), 0.0, 0.0, 0.3, 1.0, 1.0, 0.05, 3.0) is None
        True
    """
    if not preds:
        return None
    v_hi, a_hi = _LIMIT_FACTOR * v_max, _LIMIT_FACTOR * a_max
    v0 = min(abs(float(speed)) + _SPEED_SLACK, v_hi)
    # No disc can hold a reach wider than the widest contact distance: the grid ends there.
    widest = radius + margin + max(float(getattr(o, "max_radius", o.radius)) for o in preds)
    tau = np.arange(0.0, float(horizon_s) + 0.5 * step_s, step_s)
    d = reach_m(v0, v_hi, a_hi, tau) + _DIST_SLACK
    keep = d < min(widest, float(reach_cap_m))
    tau, d = tau[keep], d[keep]
    if not len(tau):
        return None
    t = t0 + tau
    p = np.array(position, dtype=float)
    best: Trap | None = None
    for o in preds:
        # the disc must come within `widest` of the robot while its reach is that small: from
        # where it is at t0, or, for a motion that jumps, from where it lands at a jump (its
        # speed bound holds only between jumps)
        qx, qy = o.motion.position(t0)  # a straight motion's in scalars
        if math.hypot(qx - p[0], qy - p[1]) - float(o.max_speed) * float(tau[-1]) >= widest + 1e-6 \
                and not _lands_near(o, p, t0, float(t[-1]), float(tau[-1]), widest):
            continue
        q = np.asarray(o.positions(t), dtype=float).reshape(-1, 2)
        r = np.asarray(o.radius_at(t), dtype=float)
        held = np.hypot(q[:, 0] - p[0], q[:, 1] - p[1]) + d < radius + r + margin
        if held.any():
            k = int(np.argmax(held))
            if best is None or t[k] < best.t:
                best = Trap(float(t[k]), str(o.name))
    return best


def _lands_near(o: PredictedObstacle, p: np.ndarray, t0: float, t1: float, span: float,
                widest: float) -> bool:
    """True if ``o``'s motion jumps in [t0, t1] [s] to a place from which it may come within
    ``widest`` [m] of ``p`` [m] in ``span`` [s] (no jump: False). A jump at t0 counts: the
    position there may round to either side of it."""
    if not o.motion.may_jump:
        return False
    v = float(o.max_speed)
    return any(math.hypot(float(j.after[0]) - p[0], float(j.after[1]) - p[1]) - v * span
               < widest + 1e-6 for j in o.motion.jumps(t0 - _JUMP_BEFORE_S, t1))
