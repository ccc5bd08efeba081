"""Predictions with uncertainty: tracked obstacles as discs that grow with the horizon.

A track (:class:`~anyplan.prediction.tracking.TrackEstimate`) is predicted along its mean
constant twist (its turn rate kept only when P(CT) >= ``turn_confidence``), and its disc grows
with the horizon tau [s] by

    extra(tau) = min(k * sqrt(lambda_max(Sigma(tau))) + a_m tau^2 / 2, cap),

Sigma(tau) the position covariance propagated through the coordinated-turn Jacobian, ``a_m`` a
manoeuvre allowance [m/s^2] and ``cap`` [m] the largest extra radius.

Why the turn rate is gated, the knots and the coverage bound: ``docs/perception.md``,
"Uncertain prediction: the growing disc".
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from anyplan.config import setting, validate
from anyplan.prediction.base import ObstacleObservation, RadiusGrowth
from anyplan.prediction.tracking import TrackEstimate, ct_transition

__all__ = ["UncertaintyModel", "UNCERTAINTY_SETTINGS"]


@dataclass(frozen=True)
class UncertaintyModel:
    """How a track's covariance becomes a growing disc.

    Attributes:
        k_sigma: Standard deviations of the position covered.
        accel_allowance: Manoeuvre allowance a_m [m/s^2].
        cap_m: Largest extra radius [m].
        taus: Horizon knots [s] (increasing, from 0; the last is the horizon cap).
        turn_confidence: The track's turn rate is predicted only when its CT model's probability
            is at least this; below it the track is predicted straight.
        tube_cap_m: Largest extra radius [m] of the replan tube: a detection farther from its
            predicted centre than ``min(extra, tube_cap_m)`` plus three noise standard
            deviations has left the tube, and the robot replans (the planned disc keeps the
            whole ``extra``; replanning costs little, a stale plan near a turning obstacle a lot).

    Invalid values raise :class:`~anyplan.config.SettingError` naming the field.
    """

    k_sigma: float = setting(2.0, lo=0.0, hi=100.0, unit="", doc="standard deviations of position covered")
    accel_allowance: float = setting(0.1, lo=0.0, hi=100.0, unit="m/s^2", doc="manoeuvre allowance")
    cap_m: float = setting(1.0, lo=0.0, hi=100.0, unit="m", doc="largest extra radius")
    taus: tuple[float, ...] = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0)
    turn_confidence: float = setting(0.7, lo=0.0, hi=1.0, unit="",
                                     doc="P(CT) from which the turn rate is predicted")
    tube_cap_m: float = setting(0.3, lo=0.0, hi=100.0, unit="m",
                                doc="largest extra radius of the replan tube")

    def __post_init__(self) -> None:
        validate(self)

    def _means(self, estimates: Sequence[TrackEstimate]) -> np.ndarray:
        """Mean states (N, 5), the turn rate kept only when P(CT) >= turn_confidence."""
        x = np.array([e.state for e in estimates]).reshape(-1, 5).copy()
        turn = np.array([e.mode_probs[1] >= self.turn_confidence for e in estimates], dtype=bool)
        x[:, 4] = np.where(turn, [e.turn_rate for e in estimates], 0.0)
        return x

    def extras(self, estimates: Sequence[TrackEstimate]) -> np.ndarray:
        """Extra radii [m] at the knots, shape (N, K)."""
        n, taus = len(estimates), np.asarray(self.taus, dtype=float)
        if n == 0:
            return np.zeros((0, len(taus)))
        x = np.repeat(self._means(estimates), len(taus), axis=0)
        P = np.repeat(np.array([e.cov for e in estimates]), len(taus), axis=0)
        T = np.tile(taus, n)
        _, F = ct_transition(x, T)
        S = np.einsum("nab,nbc,ndc->nad", F[:, :2, :], P, F[:, :2, :])
        # largest eigenvalue of a symmetric 2 x 2 matrix, in closed form
        a, b, c = S[:, 0, 0], S[:, 0, 1], S[:, 1, 1]
        lam = 0.5 * (a + c) + np.sqrt(np.maximum(0.25 * (a - c) ** 2 + b * b, 0.0))
        e = self.k_sigma * np.sqrt(np.maximum(lam, 0.0)) + 0.5 * self.accel_allowance * T * T
        return np.minimum(e, self.cap_m).reshape(n, len(taus))

    def observations(self, estimates: Sequence[TrackEstimate]) -> tuple[ObstacleObservation, ...]:
        """The estimates as observations (pose and twist of the mean) carrying their growth."""
        ex = self.extras(estimates)
        taus = np.asarray(self.taus, dtype=float)
        means = self._means(estimates)
        growths = RadiusGrowth.rows([e.t for e in estimates], taus, ex)
        return tuple(ObstacleObservation(e.name, e.t, float(x[0]), float(x[1]), e.heading, e.speed,
                                         float(x[4]), e.radius, None, g)
                     for e, x, g in zip(estimates, means, growths, strict=True))


#: The model's settings by name: its scalar fields (the horizon knots ``taus`` are its shape,
#: not a setting), what ``--tracker`` may set and a run records.
UNCERTAINTY_SETTINGS: tuple[str, ...] = tuple(
    f.name for f in fields(UncertaintyModel) if f.name != "taus")
