"""The robot's tracking front end: noisy detections in, estimated obstacles out, for any agent.

With ``tracked`` perception agents get only :class:`~anyplan.prediction.detection.Detection`
records. :class:`TrackingAgent` wraps any agent: it feeds them to an IMM tracker
(:class:`~anyplan.prediction.tracking.Tracker`) and gives the inner agent an
:class:`~anyplan.agents.base.Observation` whose obstacles are the tracks' estimates (pose and
twist of the mean, no motion model) carrying the growth of their uncertain disc
(:class:`~anyplan.prediction.uncertain.UncertaintyModel`), in the odometry frame whenever the
localizer's pose differs from it. The tracker associates anonymous detections (a young track
near the robot is shown at once, ``TrackerConfig.urgent_gap_m``) and drops a track missed
where the robot's sensor should have seen it (``TrackerConfig.visible_misses``). A detection
outside the tube of the prediction the agent last planned against (its extra radius capped at
``UncertaintyModel.tube_cap_m``, plus 3 noise sigmas) asks the agent to replan
(``request_replan(reason)``). Both in ``docs/perception.md``, "The pipeline in ``tracked`` mode".
"""

from __future__ import annotations

import math
from dataclasses import fields, replace

import numpy as np

from anyplan.agents.base import Agent, AgentStats, Observation
from anyplan.agents.stats import TrackerCounts
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.se2 import carry
from anyplan.prediction.base import ConstantTwistPredictor, ObstacleObservation, PredictedObstacle
from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import Expected, Tracker, TrackerConfig
from anyplan.prediction.uncertain import UNCERTAINTY_SETTINGS, UncertaintyModel
from anyplan.world.robot import Command
from anyplan.world.scenario import Scenario
from anyplan.world.view import FieldOfView, field_of_view

__all__ = ["TrackingAgent"]


class TrackingAgent(Agent):
    """Any agent behind a tracker.

    Args:
        inner: The agent to drive.
        tracker: Tracker settings (``sigma_m`` should be the sensor's noise).
        uncertainty: How covariances become growing discs.
    """

    def __init__(self, inner: Agent, tracker: TrackerConfig | None = None,
                 uncertainty: UncertaintyModel | None = None) -> None:
        self._radius = 0.0  # the robot's [m]
        self._view = FieldOfView(None, ObstacleSet([]))  # the robot's sensor's (set by reset)
        self.inner = inner
        self.tracker_config = tracker or TrackerConfig()
        self.uncertainty = uncertainty or UncertaintyModel()
        self.tracker = Tracker(self.tracker_config)
        self._tube: dict[str, PredictedObstacle] = {}
        self._plans = 0
        self.tube_exits = 0

    @property
    def name(self) -> str:  # type: ignore[override]
        return self.inner.name

    @property
    def stats(self) -> AgentStats:
        return self.inner.stats

    @stats.setter
    def stats(self, value: AgentStats) -> None:
        self.inner.stats = value

    def reset(self, scenario: Scenario, rng: np.random.Generator) -> None:
        self.inner.reset(scenario, rng)
        self._radius = scenario.robot.radius
        self._view = field_of_view(scenario)
        self.tracker = Tracker(self.tracker_config)
        self._tube = {}
        self._plans = 0
        self.tube_exits = 0
        self._predictor = ConstantTwistPredictor(use_announced=False)

    def settings(self) -> dict[str, float]:
        """The tracker's settings and the uncertainty model's scalar ones, by name (what a
        run records to be reproduced)."""
        out = {f.name: float(getattr(self.tracker_config, f.name))
               for f in fields(self.tracker_config)}
        out.update({name: float(getattr(self.uncertainty, name)) for name in UNCERTAINTY_SETTINGS})
        return out

    def _check_tube(self, detections: tuple[Detection, ...]) -> str | None:
        k = 3.0 * max(self.tracker_config.sigma_m, 1e-3)
        cap = self.uncertainty.tube_cap_m
        for d in detections:
            p = None if d.name is None else self._tube.get(d.name)
            if p is None:
                continue
            c = p.positions(np.array([d.t]))[0]
            if math.hypot(d.x - c[0], d.y - c[1]) > min(float(p.radius_at(d.t)) - p.radius, cap) + k:
                return d.name
        return None

    def _expected(self, believed: tuple[float, float, float],
                  odom: tuple[float, float, float] | None) -> Expected:
        """What the sensor should have seen of the tracks (in the tracker's frame, the odometry
        pose's when it differs from the believed one): their centres in view from the robot,
        past the static obstacles and the other tracks' discs, with ``view_margin_m`` to spare
        (:meth:`FieldOfView.expected`)."""
        view, margin = self._view, self.tracker_config.view_margin_m

        def expected(centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
            c = centres if odom is None else _moved(centres, odom, believed)
            return view.expected(believed[:2], c, radii, margin)

        return expected

    def act(self, obs: Observation) -> Command:
        r, o = obs.robot, obs.odom
        believed = (r.x, r.y, r.theta)
        odom = None if o is None or (o.x, o.y, o.theta) == believed else (o.x, o.y, o.theta)
        dets = obs.detections
        if odom is not None and dets:
            q = _moved(np.array([[d.x, d.y] for d in dets]), believed, odom)
            dets = tuple(replace(d, x=float(x), y=float(y)) for d, (x, y) in zip(dets, q, strict=True))
        expected = None
        if (obs.frame or dets) and self.tracker_config.visible_misses > 0.0:
            expected = self._expected(believed, odom)
        labelled = self.tracker.update(obs.t, dets, expected)
        near = None
        gap = self.tracker_config.urgent_gap_m
        if gap > 0.0 and self.tracker.started:
            # young anonymous tracks this close to the robot's disc are shown at once (in the
            # tracker's frame: the odometry pose when it differs)
            c = (r.x, r.y) if odom is None else (odom[0], odom[1])
            near = (c[0], c[1], self._radius + gap)
        seen = self.uncertainty.observations(self.tracker.estimates(obs.t, near))
        if odom is not None and seen:
            seen = _to_frame(seen, odom, believed)
        # the tube is in the believed frame, as the detections given: named by their tracks
        named = tuple(replace(d, name=lab.name) if d.name is None else d
                      for d, lab in zip(obs.detections, labelled, strict=True))
        left = self._check_tube(named) if self._tube else None
        if left is not None:
            self.tube_exits += 1
            self._tube = {}  # one request per plan
            req = getattr(self.inner, "request_replan", None)
            if req is not None:
                req(f"{left} left its predicted tube")
        inner_obs = Observation(obs.t, obs.robot, seen + tuple(obs.obstacles), ())
        cmd = self.inner.act(inner_obs)
        n = len(self.inner.stats.planning_times_s)
        if n != self._plans:
            self._plans = n
            self._tube = {p.name: p for p in self._predictor.predict(seen)}
        tr = self.tracker
        counts = TrackerCounts(len(tr), tr.dropped, self.tube_exits, tr.started, tr.discarded)
        st = self.inner.stats
        if st.record is not None:
            st.record.tracking = counts  # typed agents: the record has the slot
        else:
            st.extra["tracking"] = counts
        return cmd


def _moved(points: np.ndarray, src: tuple[float, float, float],
           dst: tuple[float, float, float]) -> np.ndarray:
    """Points (N, 2) [m] seen from pose ``src`` (x, y, heading) put at the same offsets in the
    body of pose ``dst``."""
    return carry(points, src[:2], dst[:2], dst[2] - src[2])


def _to_frame(obs: tuple[ObstacleObservation, ...], src: tuple[float, float, float],
              dst: tuple[float, float, float]) -> tuple[ObstacleObservation, ...]:
    """Estimated obstacles kept in the frame of pose ``src`` as seen from pose ``dst`` (their
    headings turned with it)."""
    q = _moved(np.array([[o.x, o.y] for o in obs]), src, dst)
    turn = dst[2] - src[2]
    return tuple(replace(o, x=float(x), y=float(y), theta=o.theta + turn)
                 for o, (x, y) in zip(obs, q, strict=True))
