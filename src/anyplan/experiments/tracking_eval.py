"""Multi-object tracking quality on recorded pedestrians, the way the field reports it.

Each person of a recording (``read_obsmat``: rows t [s], x [m], y [m]) is replayed linearly
between samples and detected at ``rate_hz`` with Gaussian noise, each visible person with
probability ``detection_prob``, with ``clutter_rate`` false detections per frame uniform over
the scene's bounding box; ``named`` or ``anonymous`` detections go to the robot's tracker
(:class:`~anyplan.prediction.tracking.Tracker`). Every frame its confirmed tracks are matched to
the people present (an optimal assignment within ``match_m``), and the CLEAR MOT figures
(Bernardin & Stiefelhagen, EURASIP JIVP 2008) are counted: misses (FN), false tracks (FP),
identity switches (a person matched to another track than last time), **MOTA** = 1 - (FN + FP
+ IDSW) / (people-frames) and **MOTP**, the mean distance [m] of the matches.

Protocol and figures: ``docs/perception.md``, "Anonymous detections".
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import Tracker, TrackerConfig

__all__ = ["MotScores", "evaluate_tracking"]


@dataclass(frozen=True)
class MotScores:
    """CLEAR MOT counts over the frames (people-frames ``gt``; ``tp`` matched, ``fn`` missed,
    ``fp`` confirmed tracks matched to no one, ``id_switches``), MOTA, MOTP [m], and the tracks
    the tracker started (``started``)."""

    frames: int
    gt: int
    tp: int
    fn: int
    fp: int
    id_switches: int
    mota: float
    motp_m: float
    started: int

    def as_dict(self) -> dict[str, float]:
        """A JSON-friendly dictionary."""
        return dict(self.__dict__)


def _positions(tracks: Mapping[int, np.ndarray], t: float) -> dict[int, np.ndarray]:
    """The people present at ``t`` [s] (between their first and last sample), linear between
    samples: id -> (x, y) [m]."""
    out = {}
    for pid, tr in tracks.items():
        if tr[0, 0] - 1e-9 <= t <= tr[-1, 0] + 1e-9:
            out[pid] = np.array([np.interp(t, tr[:, 0], tr[:, 1]), np.interp(t, tr[:, 0], tr[:, 2])])
    return out


def evaluate_tracking(tracks: Mapping[int, np.ndarray], *, association: str = "anonymous",
                      noise_m: float = 0.05, rate_hz: float = 10.0, detection_prob: float = 1.0,
                      clutter_rate: float = 0.0, seed: int = 0, radius_m: float = 0.25,
                      tracker: TrackerConfig | None = None, match_m: float = 0.5,
                      t_end: float | None = None) -> MotScores:
    """CLEAR MOT scores of the tracker on ``tracks`` (person id -> rows (t, x, y)) from 0 s to
    ``t_end`` [s] (default: the recording's end), seeded by ``seed``."""
    if association not in ("named", "anonymous"):
        raise ValueError(f"unknown association '{association}'")
    rng = np.random.default_rng(seed)
    tr = Tracker(tracker or TrackerConfig(sigma_m=noise_m))
    allp = np.concatenate([v[:, 1:] for v in tracks.values()])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    end = max(float(v[-1, 0]) for v in tracks.values()) if t_end is None else t_end
    last: dict[int, str] = {}
    frames = gt = tp = fp = idsw = 0
    dist = 0.0
    for k in range(int(end * rate_hz) + 1):
        t = k / rate_hz
        truth = _positions(tracks, t)
        dets = []
        for pid, p in truth.items():
            if detection_prob < 1.0 and rng.random() >= detection_prob:
                continue
            z = p + rng.normal(0.0, noise_m, 2)
            dets.append(Detection(str(pid) if association == "named" else None, t,
                                  float(z[0]), float(z[1]), radius_m))
        for _ in range(int(rng.poisson(clutter_rate)) if clutter_rate > 0.0 else 0):
            z = rng.uniform(lo, hi)
            dets.append(Detection(None, t, float(z[0]), float(z[1]), radius_m))
        if association == "anonymous":
            dets.sort(key=lambda d: (d.x, d.y))
        tr.update(t, dets)
        est = tr.estimates(t)
        frames += 1
        gt += len(truth)
        ids = list(truth)
        if est and ids:
            e = np.array([x.state[:2] for x in est])
            g = np.array([truth[i] for i in ids])
            d = np.hypot(e[:, None, 0] - g[None, :, 0], e[:, None, 1] - g[None, :, 1])
            rows, cols = linear_sum_assignment(np.where(d <= match_m, d, 1e6))
            pairs = [(r, c) for r, c in zip(rows, cols, strict=True) if d[r, c] <= match_m]
        else:
            pairs = []
        tp += len(pairs)
        fp += len(est) - len(pairs)
        for r, c in pairs:
            dist += float(d[r, c])
            pid = ids[c]
            if pid in last and last[pid] != est[r].name:
                idsw += 1
            last[pid] = est[r].name
    fn = gt - tp
    return MotScores(frames, gt, tp, fn, fp, idsw, 1.0 - (fn + fp + idsw) / max(gt, 1),
                     dist / max(tp, 1), tr.started)
