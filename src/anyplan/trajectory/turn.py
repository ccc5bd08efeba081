"""Turning in place: the time-optimal rotation by a given angle under omega_max and alpha_max.

As in the paper (§4.1), the robot accelerates its turn rate toward omega_max at alpha_max, holds
it if there is time, and decelerates to zero so that it stops at the new heading. The rotation
may start from a non-zero turn rate omega_0: a rate pointing the wrong way is first braked, a
rate too high to stop in time overshoots and comes back. The result is a list of constant
angular-acceleration phases, evaluated exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from anyplan.trajectory import _kernels as _k

__all__ = ["RotationProfile", "rotation_profile"]


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
        # elapsed time clamped to its duration (compiled in anyplan.trajectory._kernels).
        th, w = _k.rotation_eval(np.ascontiguousarray(tau.ravel()), float(self.theta0),
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
