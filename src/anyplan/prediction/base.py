"""Observations of moving obstacles and constant-twist prediction."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from anyplan.world.motion import Motion, UnicycleMotion

__all__ = ["ObstacleObservation", "PredictedObstacle", "Predictor", "ConstantTwistPredictor"]


@dataclass(frozen=True)
class ObstacleObservation:
    """A moving obstacle as seen at time ``t`` [s].

    Attributes:
        name: Obstacle name.
        t: Observation time [s].
        x, y: Centre [m].
        theta: Heading [rad].
        v: Speed [m/s].
        omega: Turn rate [rad/s].
        radius: Disc radius [m].
        motion: The obstacle's announced motion model over time, when it is known in full
            (e.g. a published track); None when only the current twist is known.
    """

    name: str
    t: float
    x: float
    y: float
    theta: float
    v: float
    omega: float
    radius: float
    motion: Motion | None = None


@dataclass(frozen=True)
class PredictedObstacle:
    """A predicted moving disc: ``motion.positions(t)`` for absolute times t [s]."""

    name: str
    radius: float
    motion: Motion

    def positions(self, t: np.ndarray) -> np.ndarray:
        """Predicted centres at times ``t`` (N,) [s], shape (N, 2) [m]."""
        return self.motion.positions(t)

    @property
    def max_speed(self) -> float:
        """Upper bound on the predicted speed [m/s]."""
        return self.motion.max_speed


class Predictor(Protocol):
    """Maps observations to predicted obstacle motions."""

    def predict(self, observations: Sequence[ObstacleObservation]) -> list[PredictedObstacle]:
        """Predicted motions of the observed obstacles."""
        ...


class ConstantTwistPredictor:
    """Assumes each obstacle keeps its observed (v, omega): a line or a circle.

    This is exact for the paper's obstacles, whose motion has constant v and omega. When an
    observation carries a full motion model (``observation.motion``) and ``use_announced`` is
    True, that model is used instead.
    """

    def __init__(self, use_announced: bool = True) -> None:
        self.use_announced = use_announced

    def predict(self, observations: Sequence[ObstacleObservation]) -> list[PredictedObstacle]:
        """Predicted motions, with times measured on the same clock as the observations."""
        out = []
        for o in observations:
            if self.use_announced and o.motion is not None:
                motion: Motion = o.motion
            else:
                motion = _shifted_unicycle(o)
            out.append(PredictedObstacle(o.name, o.radius, motion))
        return out


def _shifted_unicycle(o: ObstacleObservation) -> Motion:
    """Constant-twist motion through the observed pose at time o.t, valid for t >= o.t."""
    # A UnicycleMotion starts at ``start_time``; expressing it from the observation time keeps
    # positions(t) in absolute time. For t < o.t it returns the observed pose.
    return UnicycleMotion(o.x, o.y, o.theta, o.v, o.omega, start_time=o.t)
