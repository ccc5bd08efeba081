"""Observations of moving obstacles and constant-twist prediction."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from anyplan.world.motion import Motion, UnicycleMotion, positions_of

__all__ = ["ObstacleObservation", "PredictedObstacle", "Predictor", "ConstantTwistPredictor",
           "RadiusGrowth", "centres_of", "jump_times_of", "continuous_pieces_of"]


def _normalised(taus: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knots [s] checked (increasing, as many as each row of ``values`` (n, K) [m]), the rows
    made nonnegative and nondecreasing, and each row's largest slope [m/s] (0 with one knot)."""
    k = np.asarray(taus, dtype=float)
    if k.ndim != 1 or len(k) < 1 or values.shape[1] != len(k) or np.any(np.diff(k) <= 0.0):
        raise ValueError("taus must be increasing and as long as values")
    v = np.maximum.accumulate(np.maximum(values, 0.0), axis=1)
    return k, v, _slopes(k, v)


def _slopes(k: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Each row's largest slope [m/s] over the knots ``k`` [s], at least 0 (0 with one knot)."""
    if len(k) < 2:
        return np.zeros(len(v))
    return np.maximum(np.max(np.diff(v, axis=1) / np.diff(k), axis=1), 0.0)


@dataclass(frozen=True)
class RadiusGrowth:
    """Extra radius [m] of an uncertain prediction as a function of the horizon.

    ``extra(t) = interp(t - t0, taus, values)``: piecewise linear in the horizon ``t - t0`` [s],
    nondecreasing, constant before the first and after the last knot (the horizon cap). Its
    slope never exceeds :attr:`rate` [m/s], which certified contact searches add to the relative
    speed bound, so that they stay exact for the growing disc.
    """

    t0: float
    taus: np.ndarray
    values: np.ndarray
    _rate: float = field(init=False, repr=False, compare=False, default=0.0)

    def __post_init__(self) -> None:
        if np.ndim(self.values) != 1:
            raise ValueError("taus must be increasing and as long as values")
        k, v, rates = _normalised(self.taus, np.asarray(self.values, dtype=float)[None, :])
        object.__setattr__(self, "taus", k)
        object.__setattr__(self, "values", v[0])
        object.__setattr__(self, "_rate", float(rates[0]))  # asked for in every contact search

    @classmethod
    def rows(cls, t0: Sequence[float], taus: np.ndarray, values: np.ndarray) -> list[RadiusGrowth]:
        """One growth per row of ``values`` (n, len(taus)) [m], from ``t0[i]`` [s] on, on the
        shared knots ``taus`` [s]: the same objects as ``RadiusGrowth(t0[i], taus,
        values[i])`` one by one, checked and normalised for all rows at once (a tracker builds
        one per obstacle at every detection)."""
        v = np.asarray(values, dtype=float)
        if v.ndim != 2 or len(t0) != len(v):
            raise ValueError("taus must be increasing and as long as values, one row per t0")
        k, v, rates = _normalised(taus, v)
        out = []
        for t, row, rate in zip(t0, v, rates, strict=True):
            g = object.__new__(cls)
            object.__setattr__(g, "t0", t)
            object.__setattr__(g, "taus", k)
            object.__setattr__(g, "values", row)
            object.__setattr__(g, "_rate", float(rate))
            out.append(g)
        return out

    def capped(self, cap: float) -> RadiusGrowth:
        """This growth with its extra radius capped at ``cap`` [m] (>= 0): the same object as
        ``RadiusGrowth(t0, taus, np.minimum(values, cap))``, built without checking again what
        this one's construction checked (a capped row stays nonnegative and nondecreasing);
        st-bitstar caps every uncertain prediction at every replanning."""
        if not cap >= 0.0:
            raise ValueError(f"cap must be >= 0, got {cap!r}")
        v = np.minimum(self.values, cap)
        g = object.__new__(type(self))
        object.__setattr__(g, "t0", self.t0)
        object.__setattr__(g, "taus", self.taus)
        object.__setattr__(g, "values", v)
        object.__setattr__(g, "_rate", float(_slopes(self.taus, v[None, :])[0]))
        return g

    def at(self, t: np.ndarray | float) -> np.ndarray:
        """Extra radius [m] at absolute times ``t`` [s]."""
        return np.interp(np.asarray(t, dtype=float) - self.t0, self.taus, self.values)

    @property
    def rate(self) -> float:
        """Upper bound on d extra / dt [m/s]."""
        return self._rate

    @property
    def max_extra(self) -> float:
        """The largest extra radius [m] (at the horizon cap)."""
        return float(self.values[-1])


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
        growth: For an estimated obstacle (tracked from noisy detections), the extra radius of
            its prediction as a function of the horizon; None when the pose is exact.
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
    growth: RadiusGrowth | None = None


@dataclass(frozen=True)
class PredictedObstacle:
    """A predicted moving disc: ``motion.positions(t)`` for absolute times t [s].

    With ``growth``, the disc's radius at time t is ``radius + growth.at(t)`` (an uncertain
    prediction whose disc grows with the horizon, up to a cap); the certified collision checks
    (:mod:`anyplan.prediction.collision`) honour it exactly. ``until`` [s] is the prediction's
    horizon: after it the obstacle is not predicted at all (no disc; ``radius_at`` is -inf), so
    the checks end there for it (a receding-horizon planner replans before it).
    """

    name: str
    radius: float
    motion: Motion
    growth: RadiusGrowth | None = None
    until: float = math.inf

    def radius_at(self, t: np.ndarray | float) -> np.ndarray | float:
        """Disc radius [m] at absolute times ``t`` [s] (-inf after :attr:`until`)."""
        if self.growth is None:
            r = self.radius if np.ndim(t) == 0 else np.full(np.shape(t), self.radius)
        else:
            r = self.radius + self.growth.at(t)
        if self.until == math.inf:
            return r
        if np.ndim(t) == 0:
            return r if float(t) <= self.until else -math.inf
        return np.where(np.asarray(t, dtype=float) <= self.until, r, -math.inf)

    @property
    def max_radius(self) -> float:
        """The largest radius [m] the disc reaches."""
        return self.radius + (0.0 if self.growth is None else self.growth.max_extra)

    def positions(self, t: np.ndarray) -> np.ndarray:
        """Predicted centres at times ``t`` (N,) [s], shape (N, 2) [m]."""
        return self.motion.positions(t)

    @property
    def max_speed(self) -> float:
        """Upper bound on the predicted speed [m/s]."""
        return self.motion.max_speed


def centres_of(preds: Sequence[PredictedObstacle], t: np.ndarray) -> np.ndarray:
    """Every prediction's centres (len(preds), len(t), 2) [m] at times ``t`` (T,) [s], row k
    bit for bit ``preds[k].positions(t)`` (straight motions at once:
    :func:`~anyplan.world.motion.positions_of`); any object with ``positions`` may stand in
    for a prediction."""
    return positions_of([o.motion if type(o) is PredictedObstacle else o for o in preds], t)


def _jumping_motion(o: Any) -> Any:
    m = getattr(o, "motion", None)
    return m if m is not None and getattr(m, "may_jump", False) else None


def jump_times_of(o: Any, t0: float, t1: float) -> list[float]:
    """Times [s] in (t0, t1] at which the position of prediction ``o`` jumps (an open track's
    periods, :meth:`~anyplan.world.motion.Motion.jump_times`); none for a motion that never
    jumps, or for a stand-in without a motion."""
    m = _jumping_motion(o)
    return [] if m is None else m.jump_times(t0, t1)


def continuous_pieces_of(o: Any, t0: float, t1: float) -> list[tuple[float, float]]:
    """[t0, t1] [s] cut at the jumps of prediction ``o``'s position
    (:meth:`~anyplan.world.motion.Motion.continuous_pieces`: a speed bound holds on each);
    ``[(t0, t1)]`` for a motion that never jumps, or for a stand-in without a motion."""
    m = _jumping_motion(o)
    return [(t0, t1)] if m is None else m.continuous_pieces(t0, t1)


class Predictor(Protocol):
    """Maps observations to predicted obstacle motions."""

    def predict(self, observations: Sequence[ObstacleObservation]) -> list[PredictedObstacle]:
        """Predicted motions of the observed obstacles."""
        ...


class ConstantTwistPredictor:
    """Assumes each obstacle keeps its observed (v, omega): a line or a circle.

    This is exact for the paper's obstacles, whose motion has constant v and omega. When an
    observation carries a full motion model (``observation.motion``) and ``use_announced`` is
    True, that model is used instead. With ``horizon_s``, a prediction extrapolated from the
    current twist (no announced motion) ends ``horizon_s`` seconds after its observation
    (:attr:`PredictedObstacle.until`); announced motions are kept in full.
    """

    def __init__(self, use_announced: bool = True, horizon_s: float | None = None,
                 manoeuvre_accel: float = 0.0, manoeuvre_cap_m: float = 1.0) -> None:
        if horizon_s is not None and not horizon_s > 0.0:
            raise ValueError(f"horizon_s: must be > 0 or None, got {horizon_s!r}")
        if not manoeuvre_accel >= 0.0:
            raise ValueError(f"manoeuvre_accel: must be >= 0, got {manoeuvre_accel!r}")
        if not manoeuvre_cap_m >= 0.0:
            raise ValueError(f"manoeuvre_cap_m: must be >= 0, got {manoeuvre_cap_m!r}")
        self.use_announced = use_announced
        self.horizon_s = horizon_s
        self.manoeuvre_accel = float(manoeuvre_accel)
        self.manoeuvre_cap_m = float(manoeuvre_cap_m)

    def predict(self, observations: Sequence[ObstacleObservation]) -> list[PredictedObstacle]:
        """Predicted motions, with times measured on the same clock as the observations."""
        out = []
        for o in observations:
            until = math.inf
            growth = o.growth
            if self.use_announced and o.motion is not None:
                motion: Motion = o.motion
            else:
                motion = _shifted_unicycle(o)
                if self.horizon_s is not None:
                    until = o.t + self.horizon_s
                if growth is None and self.manoeuvre_accel > 0.0:
                    growth = manoeuvre_growth(o.t, self.manoeuvre_accel, self.manoeuvre_cap_m)
            out.append(PredictedObstacle(o.name, o.radius, motion, growth, until))
        return out


#: Horizon knots [s] of :func:`manoeuvre_growth`.
_MANOEUVRE_TAUS = np.array([0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0])


def manoeuvre_growth(t0: float, accel: float, cap_m: float) -> RadiusGrowth:
    """The extra radius of an exact pose and twist whose future is unknown: an obstacle that
    may leave its constant twist with an acceleration of up to ``accel`` [m/s^2] is, after
    tau [s], within ``accel tau^2 / 2`` of its extrapolated centre; capped at ``cap_m`` [m].

    The knots interpolate the parabola linearly from above (it is convex), so the disc always
    contains the bound.

    Examples:
        >>> g = manoeuvre_growth(10.0, 2.0, 1.0)
        >>> float(g.at(10.0)), float(g.at(10.5)), float(g.at(11.0)), float(g.at(20.0))
        (0.0, 0.25, 1.0, 1.0)
    """
    return RadiusGrowth(t0, _MANOEUVRE_TAUS,
                        np.minimum(0.5 * accel * _MANOEUVRE_TAUS ** 2, cap_m))


def _shifted_unicycle(o: ObstacleObservation) -> Motion:
    """Constant-twist motion through the observed pose at time o.t, valid for t >= o.t."""
    # A UnicycleMotion starts at ``start_time``; expressing it from the observation time keeps
    # positions(t) in absolute time. For t < o.t it returns the observed pose.
    return UnicycleMotion(o.x, o.y, o.theta, o.v, o.omega, start_time=o.t)
