"""Multi-object tracking quality on recorded pedestrians, the way the field reports it.

Each person of a recording (``read_obsmat``: rows t [s], x [m], y [m]) is replayed linearly
between samples (a ``track`` motion) and seen by the robot's sensor in ``tracked`` mode
(:class:`~anyplan.simulation.perception.Sensor`, the one of the closed-loop runs, here without
a range limit): at ``rate_hz`` with Gaussian noise, each person with probability
``detection_prob``, with ``clutter_rate`` false detections per frame uniform over the scene's
bounding box; the ``named`` or ``anonymous`` detections go to the robot's tracker
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

from anyplan.prediction.tracking import Tracker, TrackerConfig
from anyplan.simulation.perception import Sensor, tracking_configs
from anyplan.world.motion import TrackMotion
from anyplan.world.robot import RobotSpec, RobotState
from anyplan.world.scenario import Scenario
from anyplan.world.schema import MovingObstacle
from anyplan.world.sensing import SensingSpec

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


def _scene(tracks: Mapping[int, np.ndarray], spec: SensingSpec, radius_m: float) -> Scenario:
    """The recording as a scenario for the robot's :class:`~anyplan.simulation.perception.Sensor`:
    each person a disc of ``radius_m`` [m] on its track (a person with one sample, an instant,
    is left out), the arena the people's bounding box, a sensor without a range limit and no
    occluders."""
    people = tuple(MovingObstacle(str(pid), radius_m, TrackMotion(tr))
                   for pid, tr in sorted(tracks.items()) if len(tr) >= 2)
    if not people:
        raise ValueError("no person with two samples or more")
    allp = np.concatenate([o.motion.samples[:, 1:] for o in people])  # type: ignore[attr-defined]
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    centre = 0.5 * (lo + hi)
    robot = RobotSpec(start=(float(centre[0]), float(centre[1]), 0.0),
                      goal=(float(centre[0]), float(centre[1])))
    return Scenario("tracking-eval", float(hi[0] - lo[0]), float(hi[1] - lo[1]), robot,
                    moving_obstacles=people, sensing=spec,
                    origin=(float(lo[0]), float(lo[1])))


def evaluate_tracking(tracks: Mapping[int, np.ndarray], *, association: str = "anonymous",
                      noise_m: float = 0.05, rate_hz: float = 10.0, detection_prob: float = 1.0,
                      clutter_rate: float = 0.0, occlusion: str = "static", seed: int = 0,
                      radius_m: float = 0.25,
                      tracker: TrackerConfig | Mapping[str, float] | None = None,
                      match_m: float = 0.5, t_end: float | None = None) -> MotScores:
    """CLEAR MOT scores of the tracker on ``tracks`` (person id -> rows (t, x, y)) from 0 s to
    ``t_end`` [s] (default: the recording's end). ``tracker``: the tracker's settings as given,
    or as names and values with the defaults of the robot's tracking front end (None: no
    names; :func:`anyplan.simulation.perception.tracking_configs`, which tells it the sensor's
    noise). The detections are those of the robot's sensor
    in ``tracked`` mode seeded by ``seed``, seeing from the scene's centre (``occlusion:
    all``: the people nearer to it hide those behind them; a person hidden counts as missed).

    Raises:
        SensingError: a bad sensing setting (its ``field`` names it).
        ValueError: no person with two samples or more.
    """
    spec = SensingSpec(mode="tracked", noise_m=noise_m, rate_hz=rate_hz, association=association,
                       detection_prob=detection_prob, clutter_rate=clutter_rate,
                       occlusion=occlusion)
    scene = _scene(tracks, spec, radius_m)
    sensor = Sensor(scene, spec, seed)
    viewpoint = RobotState(*scene.robot.start)
    if not isinstance(tracker, TrackerConfig):
        tracker, _ = tracking_configs(tracker or {}, noise_m)
    tr = Tracker(tracker)

    def expected(centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
        """The tracks the sensor should have seen: as the robot's tracking front end."""
        return sensor.view.expected((viewpoint.x, viewpoint.y), centres, radii,
                                    tracker.view_margin_m)

    end = max(o.motion.span[1] for o in scene.moving_obstacles) if t_end is None else t_end
    last: dict[str, str] = {}
    frames = gt = tp = fp = idsw = 0
    dist = 0.0
    for k in range(int(end * rate_hz) + 1):
        t = k / rate_hz
        _, dets = sensor.observe(t, viewpoint)
        tr.update(t, list(dets), expected)
        est = tr.estimates(t)
        present = [o for o in scene.moving_obstacles if o.motion.exists(t)]
        frames += 1
        gt += len(present)
        if est and present:
            e = np.array([x.state[:2] for x in est])
            g = np.array([o.position(t) for o in present])
            d = np.hypot(e[:, None, 0] - g[None, :, 0], e[:, None, 1] - g[None, :, 1])
            rows, cols = linear_sum_assignment(np.where(d <= match_m, d, 1e6))
            pairs = [(r, c) for r, c in zip(rows, cols, strict=True) if d[r, c] <= match_m]
        else:
            pairs = []
        tp += len(pairs)
        fp += len(est) - len(pairs)
        for r, c in pairs:
            dist += float(d[r, c])
            pid = present[c].name
            if pid in last and last[pid] != est[r].name:
                idsw += 1
            last[pid] = est[r].name
    fn = gt - tp
    return MotScores(frames, gt, tp, fn, fp, idsw, 1.0 - (fn + fp + idsw) / max(gt, 1),
                     dist / max(tp, 1), tr.started)
