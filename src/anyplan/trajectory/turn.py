"""Turning in place: the time-optimal rotation by a given angle under omega_max and alpha_max.

As in the paper (Roy, Harchowdhury & Vachhani, §4.1), the robot accelerates its turn rate
toward omega_max at alpha_max, holds it if there is time, and decelerates to zero so that it
stops at the new heading. The rotation may start from a non-zero turn rate omega_0: a rate
pointing the wrong way is first braked, a rate too high to stop in time overshoots and comes
back. The result is a list of constant angular-acceleration phases, evaluated exactly by the
compiled :func:`rotation_eval`; :class:`TurnSegment` turns in place at a fixed position.
Notation: theta heading [rad], omega turn rate [rad/s], alpha angular acceleration [rad/s^2].
See ``docs/motion.md`` ("``plan_motion`` and ``Trajectory``").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from anyplan.trajectory.kinds import SegmentKind
from anyplan.trajectory.segment import Sample, Segment

__all__ = ["RotationProfile", "TurnSegment", "rotation_eval", "rotation_profile"]


@njit(cache=True)
def rotation_eval(tau: np.ndarray, theta0: float, omega0: float, durations: np.ndarray,
                  alphas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(heading, turn rate) of constant angular-acceleration phases at times ``tau`` (the last
    phase started by tau applies, its elapsed time clamped to its duration)."""
    n = tau.shape[0]
    th = np.empty(n)
    w = np.empty(n)
    for j in range(n):
        tj = tau[j]
        thj = theta0
        wj = omega0
        t0 = 0.0
        th0 = theta0
        w0 = omega0
        for k in range(durations.shape[0]):
            d = durations[k]
            a = alphas[k]
            if tj >= t0:
                dt = min(max(tj - t0, 0.0), d)
                thj = th0 + w0 * dt + 0.5 * a * dt * dt
                wj = w0 + a * dt
            th0 += w0 * d + 0.5 * a * d * d
            w0 += a * d
            t0 += d
        th[j] = thj
        w[j] = wj
    return th, w


@dataclass(frozen=True)
class RotationProfile:
    """Heading as a function of time: phases of constant angular acceleration.

    Attributes:
        theta0: Start heading [rad].
        omega0: Start turn rate [rad/s].
        durations: Phase durations [s].
        alphas: Phase angular accelerations [rad/s^2].
    """

    theta0: float
    omega0: float
    durations: tuple[float, ...]
    alphas: tuple[float, ...]

    @property
    def duration(self) -> float:
        """Total time [s]."""
        return float(sum(self.durations))

    def at_time(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(heading [rad], turn rate [rad/s]) at times ``tau`` [s] since the start (clamped)."""
        tau = np.asarray(tau, dtype=float)
        # Phase by phase: the last phase that has started at tau gives the state, with its
        # elapsed time clamped to its duration (compiled: rotation_eval).
        th, w = rotation_eval(np.ascontiguousarray(tau.ravel()), float(self.theta0),
                                 float(self.omega0), np.asarray(self.durations, dtype=float),
                                 np.asarray(self.alphas, dtype=float))
        return th.reshape(tau.shape), w.reshape(tau.shape)


def _rest_phases(dist: float, w0: float, wmax: float, amax: float) -> list[tuple[float, float]]:
    """Phases from rate w0 >= 0 covering exactly ``dist`` >= w0^2 / 2 amax, ending at rest."""
    peak = min(wmax, math.sqrt(max(amax * dist + 0.5 * w0 * w0, 0.0)))
    peak = max(peak, w0)
    t_up = (peak - w0) / amax
    t_down = peak / amax
    cruise_dist = dist - (peak * peak - w0 * w0) / (2.0 * amax) - peak * peak / (2.0 * amax)
    t_cruise = max(cruise_dist, 0.0) / peak if peak > 0.0 else 0.0
    return [(t_up, amax), (t_cruise, 0.0), (t_down, -amax)]


def rotation_profile(theta0: float, dtheta: float, omega_max: float, alpha_max: float,
                     omega0: float = 0.0) -> RotationProfile:
    """Time-optimal rotation by ``dtheta`` [rad] ending at rest, from turn rate ``omega0``.

    Args:
        theta0: Start heading [rad].
        dtheta: Signed rotation [rad] (not wrapped: the caller chooses the direction).
        omega_max: Turn-rate limit [rad/s].
        alpha_max: Angular acceleration limit [rad/s^2].
        omega0: Current turn rate [rad/s], |omega0| <= omega_max.

    Returns:
        The :class:`RotationProfile`.
    """
    sgn = 1.0 if dtheta >= 0.0 else -1.0
    d, w0 = abs(dtheta), sgn * omega0
    phases: list[tuple[float, float]] = []
    if w0 < 0.0:  # turning the wrong way: brake first
        t = -w0 / alpha_max
        phases.append((t, alpha_max))
        d += w0 * w0 / (2.0 * alpha_max)
        w0 = 0.0
    stop = w0 * w0 / (2.0 * alpha_max)
    if stop > d:  # too fast to stop at the target: brake, then come back
        phases.append((w0 / alpha_max, -alpha_max))
        back = stop - d
        phases.extend((t, -a) for t, a in _rest_phases(back, 0.0, omega_max, alpha_max))
    else:
        phases.extend(_rest_phases(d, w0, omega_max, alpha_max))
    phases = [(t, a) for t, a in phases if t > 0.0]
    return RotationProfile(theta0=float(theta0), omega0=float(omega0),
                           durations=tuple(t for t, _ in phases),
                           alphas=tuple(sgn * a for _, a in phases))


class TurnSegment(Segment):
    """Turning in place at (x, y) [m] following ``rotation``, from absolute time ``t0`` [s]."""

    kind = SegmentKind.TURN

    def __init__(self, x: float, y: float, rotation: RotationProfile, t0: float) -> None:
        self.x, self.y, self.rotation = float(x), float(y), rotation
        self.t0 = float(t0)
        self.t1 = self.t0 + rotation.duration
        self.max_speed = 0.0
        self.length = 0.0

    def sample(self, t: np.ndarray) -> Sample:
        t = np.asarray(t, dtype=float)
        th, w = self.rotation.at_time(t - self.t0)
        return (np.full(t.shape, self.x), np.full(t.shape, self.y), th, np.zeros(t.shape), w)

    def xy(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        shape = np.shape(t)
        return np.full(shape, self.x), np.full(shape, self.y)

    def path_points(self, step: float) -> np.ndarray:
        return np.array([[self.x, self.y]])
