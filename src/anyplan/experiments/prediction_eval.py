"""Prediction accuracy on recorded pedestrians, the way the field reports it on ETH/UCY.

The protocol of Alahi et al. (Social LSTM, CVPR 2016) and Schoeller et al. ("What the constant
velocity model can teach us about pedestrian motion prediction", RA-L 2020): 8 observed frames
(3.2 s), 12 predicted (4.8 s); **ADE** is the mean distance [m] between predicted and true
positions over the predicted frames, **FDE** the distance at the last one. Methods: ``cv`` (the
constant-velocity baseline) and ``imm`` (our tracker with its uncertainty disc, whose
**coverage** is also reported).

Methods and coverage in detail: ``docs/perception.md``, "Prediction accuracy: protocol".
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from anyplan.prediction.base import ConstantTwistPredictor
from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import Tracker, TrackerConfig
from anyplan.prediction.uncertain import UncertaintyModel

__all__ = ["PredictionScores", "trajectory_samples", "evaluate_prediction"]

OBS, PRED, DT = 8, 12, 0.4


@dataclass
class PredictionScores:
    """ADE/FDE [m] of both methods and the coverage of our uncertainty disc."""

    samples: int
    ade_cv: float
    fde_cv: float
    ade_imm: float
    fde_imm: float
    coverage: float
    coverage_by_horizon: list[float] = field(default_factory=list)
    mean_extra_by_horizon: list[float] = field(default_factory=list)

    def as_dict(self) -> dict[str, object]:
        """A JSON-friendly dictionary."""
        return dict(self.__dict__)


def trajectory_samples(tracks: Mapping[int, np.ndarray], stride: int = 1) -> np.ndarray:
    """Runs of 20 consecutive frames (0.4 s apart), shape (S, 20, 3) rows (t, x, y)."""
    out = []
    n = OBS + PRED
    for tr in tracks.values():
        gaps = np.flatnonzero(np.abs(np.diff(tr[:, 0]) - DT) > 1e-6)
        bounds = np.concatenate([[0], gaps + 1, [len(tr)]])
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            for s in range(a, b - n + 1, stride):
                out.append(tr[s:s + n])
    return np.array(out).reshape(-1, n, 3)


def evaluate_prediction(samples: np.ndarray, noise_m: float = 0.0, seed: int = 0,
                        tracker: TrackerConfig | None = None,
                        uncertainty: UncertaintyModel | None = None) -> PredictionScores:
    """Score ``cv`` and ``imm`` on ``samples`` (S, 20, 3)."""
    rng = np.random.default_rng(seed)
    tcfg = tracker or TrackerConfig(sigma_m=max(noise_m, 0.02))
    unc = uncertainty or UncertaintyModel()
    pred = ConstantTwistPredictor(use_announced=False)
    S = len(samples)
    err_cv = np.zeros((S, PRED))
    err_imm = np.zeros((S, PRED))
    extra = np.zeros((S, PRED))
    for i, smp in enumerate(samples):
        t, xy = smp[:, 0], smp[:, 1:]
        obs = xy[:OBS] + (rng.normal(0.0, noise_m, (OBS, 2)) if noise_m > 0 else 0.0)
        fut_t, fut = t[OBS:], xy[OBS:]
        v = (obs[-1] - obs[-2]) / DT
        cv = obs[-1] + v * (fut_t - t[OBS - 1])[:, None]
        err_cv[i] = np.hypot(*(cv - fut).T)
        tr = Tracker(tcfg)
        for k in range(OBS):
            tr.update(float(t[k]), [Detection("p", float(t[k]), float(obs[k, 0]), float(obs[k, 1]), 0.25)])
        o = unc.observations(tr.estimates(float(t[OBS - 1])))[0]
        p = pred.predict([o])[0]
        err_imm[i] = np.hypot(*(p.positions(fut_t) - fut).T)
        extra[i] = p.growth.at(fut_t) if p.growth is not None else 0.0
    inside = err_imm <= extra
    return PredictionScores(
        samples=S, ade_cv=float(err_cv.mean()), fde_cv=float(err_cv[:, -1].mean()),
        ade_imm=float(err_imm.mean()), fde_imm=float(err_imm[:, -1].mean()),
        coverage=float(inside.mean()), coverage_by_horizon=inside.mean(axis=0).tolist(),
        mean_extra_by_horizon=extra.mean(axis=0).tolist())
