"""Imperfect localization: the robot believes it is a little off where it is.

A robot knows its pose from a localizer (scan matching against the map, AMCL), whose estimate
is off by an error that wanders slowly: :class:`LocalizationError` draws it as a first-order
Gauss-Markov process per axis (x, y [m], heading [rad]; correlation time ``tau_s``;
:class:`~anyplan.simulation.gauss_markov.GaussMarkov`). The agent gets the
estimated pose (its twist stays the drive's, as odometry measures it), so it plans and tracks
in the map from where it believes it is; the simulator moves and tests the true robot. What the
robot's own sensor sees is seen relative to the robot, and so lands in the map where the
estimate puts it (:meth:`LocalizationError.to_map`): a detection is off by the same error as the
robot's pose, near the robot, while the static map is not. Announced motions (``oracle``) come
from outside the robot and stay where they are. Seeded per run, on a stream of its own.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from anyplan.geometry.se2 import carry, wrap_angle
from anyplan.prediction.base import ObstacleObservation
from anyplan.prediction.detection import Detection
from anyplan.simulation.gauss_markov import GaussMarkov
from anyplan.world.robot import RobotState

__all__ = ["LOCALIZATION_STREAM", "LOCALIZATION_TAU_S", "LocalizationError"]

#: The second entry of the localization generator's seed, ``default_rng((seed, LOCALIZATION_STREAM))``.
LOCALIZATION_STREAM = 0x10C

#: Correlation time [s] of the localization error: a localizer's estimate drifts over seconds.
LOCALIZATION_TAU_S = 5.0


class LocalizationError(GaussMarkov):
    """The localization error of one run.

    Args:
        sigma_xy: Stationary standard deviation [m] of the position error, per axis (>= 0).
        sigma_theta: Stationary standard deviation [rad] of the heading error (>= 0).
        seed: The run's seed.
        tau_s: Correlation time [s] of the errors (> 0).

    Examples:
        The estimate is the pose plus the error; a point the robot senses moves with it:

        >>> loc = LocalizationError(0.1, 0.05, seed=1)
        >>> true = RobotState(2.0, 1.0, 0.5, 0.3, 0.0)
        >>> est = loc.estimate(true)
        >>> bool(np.allclose([est.x - true.x, est.y - true.y], loc.error[:2])), est.v == true.v
        (True, True)
        >>> bool(np.allclose(loc.to_map(true, np.array([[2.0, 1.0]])), [[est.x, est.y]]))
        True
    """

    def __init__(self, sigma_xy: float, sigma_theta: float, seed: int,
                 tau_s: float = LOCALIZATION_TAU_S) -> None:
        # the current error: x [m], y [m], heading [rad], drawn from the stationary spread
        super().__init__(("sigma_xy", "sigma_xy", "sigma_theta"), (sigma_xy, sigma_xy, sigma_theta),
                         seed, LOCALIZATION_STREAM, tau_s)
        #: The largest position error [m] so far.
        self.max_position_error_m = float(math.hypot(*self.error[:2]))

    def record(self) -> dict[str, object]:
        """What to store in ``result.extra["localization"]``."""
        return {"sigma_xy_m": float(self.sigma[0]), "sigma_theta_rad": float(self.sigma[2]),
                "tau_s": self.tau_s, "seed": list(self.seed_sequence),
                "max_position_error_m": self.max_position_error_m}

    def step(self, dt: float) -> None:
        """Advance the error by ``dt`` [s]."""
        self.advance(dt)
        self.max_position_error_m = max(self.max_position_error_m, float(math.hypot(*self.error[:2])))

    def estimate(self, state: RobotState) -> RobotState:
        """The pose the robot believes it has when it is at ``state`` (the twist unchanged)."""
        ex, ey, eth = self.error
        return RobotState(state.x + float(ex), state.y + float(ey),
                          float(wrap_angle(state.theta + float(eth))), state.v, state.omega)

    def to_map(self, state: RobotState, points: np.ndarray) -> np.ndarray:
        """Where points (N, 2) [m] that the robot at ``state`` senses land in its map: the same
        offset from the believed pose, turned by the heading error."""
        est = self.estimate(state)
        return carry(points, (state.x, state.y), (est.x, est.y), float(self.error[2]))

    def observed(self, state: RobotState, obs: tuple[ObstacleObservation, ...]
                 ) -> tuple[ObstacleObservation, ...]:
        """Sensed obstacles (pose and twist, no announced motion) as the robot at ``state``
        places them: positions by :meth:`to_map`, headings turned by the heading error. An
        announced motion comes from outside the robot: such an observation is unchanged."""
        sensed = [i for i, o in enumerate(obs) if o.motion is None]
        if not sensed:
            return obs
        p = self.to_map(state, np.array([[obs[i].x, obs[i].y] for i in sensed]))
        out = list(obs)
        for k, i in enumerate(sensed):
            o = obs[i]
            out[i] = replace(o, x=float(p[k, 0]), y=float(p[k, 1]),
                             theta=float(wrap_angle(o.theta + float(self.error[2]))))
        return tuple(out)

    def detected(self, state: RobotState, dets: tuple[Detection, ...]) -> tuple[Detection, ...]:
        """Detections as the robot at ``state`` places them in its map (:meth:`to_map`)."""
        if not dets:
            return dets
        p = self.to_map(state, np.array([[d.x, d.y] for d in dets]))
        return tuple(replace(d, x=float(q[0]), y=float(q[1])) for d, q in zip(dets, p, strict=True))
