"""The robot's sensor: what each perception mode lets an agent see of the moving obstacles.

Modes (:class:`~anyplan.world.sensing.SensingSpec`): ``oracle`` (exact pose, twist and motion
model within ``robot.sensing_range``, the paper's assumption), ``twist`` (the same without the
motion model) and ``tracked`` (noisy position detections of the visible obstacles at the sensor
rate). An obstacle is visible when its centre is in range and in line of sight past the static
obstacles (``occlusion: all``: and past the other moving discs, :mod:`anyplan.world.view`); it
exists only within its motion's span. Noise comes from a Generator seeded with
``(seed, NOISE_STREAM)``: the same seed, the same noise. Anonymous detections (no names, in
the order of their x), missed detections and false ones (clutter) draw from a second Generator,
``(seed, CLUTTER_STREAM)``.

Frames, visibility and seeding: ``docs/perception.md``, "Perception modes: what the sensor
sees".
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import fields, replace
from typing import Any

import numpy as np

from anyplan.agents.base import Agent
from anyplan.agents.perceiving import TrackingAgent
from anyplan.errors import UnknownNameError
from anyplan.prediction.base import ObstacleObservation
from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import TrackerConfig
from anyplan.prediction.uncertain import UNCERTAINTY_SETTINGS, UncertaintyModel
from anyplan.world.robot import RobotState
from anyplan.world.scenario import Scenario
from anyplan.world.sensing import SensingSpec
from anyplan.world.view import field_of_view

__all__ = ["NOISE_STREAM", "CLUTTER_STREAM", "Sensor", "observe_exact", "effective_sensing",
           "override_sensing", "with_tracking", "tracking_setting_names", "tracking_configs",
           "parse_tracking_settings"]

#: Second entry of the noise generator's seed sequence ``(run seed, NOISE_STREAM)``.
NOISE_STREAM = 0x5E45
#: Second entry of the seed sequence of the missed and false detections.
CLUTTER_STREAM = 0xC1A7
#: Draws per false detection before one in the visible region is given up (a region that is
#: nearly all hidden).
_CLUTTER_TRIES = 50


def observe_exact(scenario: Scenario, t: float, robot: RobotState,
                  announce: bool = True) -> tuple[ObstacleObservation, ...]:
    """The moving obstacles that exist at time ``t`` [s] within the sensing range (if any), with
    their exact pose and twist; with ``announce`` each carries the obstacle's motion model."""
    rng_limit = scenario.robot.sensing_range
    out = []
    for o in scenario.moving_obstacles:
        if not o.motion.exists(t):
            continue
        x, y, th, v, w = o.motion.state(t)
        if rng_limit is not None and math.hypot(x - robot.x, y - robot.y) > rng_limit:
            continue
        out.append(ObstacleObservation(o.name, t, x, y, th, v, w, o.radius,
                                       o.motion if announce else None))
    return tuple(out)


def effective_sensing(scenario: Scenario, announce_motions: bool = True) -> SensingSpec:
    """The scenario's sensing (``oracle`` when it has none); ``announce_motions=False`` (the older
    switch of :class:`~anyplan.simulation.simulator.SimConfig`) turns ``oracle`` into ``twist``."""
    spec = scenario.sensing or SensingSpec()
    if spec.mode == "oracle" and not announce_motions:
        spec = replace(spec, mode="twist")
    return spec


class Sensor:
    """The sensor of one run.

    Args:
        scenario: The full scenario (the sensor reads the truth; the agent gets only its output).
        spec: Perception settings.
        seed: The run's seed; the noise generator is ``default_rng((seed, NOISE_STREAM))``.
    """

    def __init__(self, scenario: Scenario, spec: SensingSpec, seed: int) -> None:
        self.scenario = scenario
        self.spec = spec
        self.seed_sequence = (int(seed), NOISE_STREAM)
        self.rng = np.random.default_rng(list(self.seed_sequence))
        self.clutter_seed = (int(seed), CLUTTER_STREAM)
        self.clutter_rng = np.random.default_rng(list(self.clutter_seed))
        #: What the sensor sees from the robot: its range and the static obstacles' shadows.
        self.view = field_of_view(scenario)
        radii = [o.radius for o in scenario.moving_obstacles]
        #: Radius [m] a false detection reports: the median of the moving obstacles'.
        self.clutter_radius = float(np.median(radii)) if radii else 0.25
        self.period = 1.0 / spec.rate_hz
        self._frame = 0
        self.frames = 0
        self.detections = 0
        self.missed = 0
        self.false_detections = 0

    def record(self) -> dict[str, object]:
        """What to store in ``result.extra["perception"]``: the mode alone for ``oracle`` and
        ``twist``, which read none of the sensor's other settings (nor draw noise)."""
        if self.spec.mode != "tracked":
            return {"mode": self.spec.mode}
        out: dict[str, object] = {
            "mode": self.spec.mode, "noise_m": self.spec.noise_m, "rate_hz": self.spec.rate_hz,
            "noise_seed": list(self.seed_sequence), "frames": self.frames,
            "detections": self.detections}
        sp = self.spec
        if (sp.association, sp.detection_prob, sp.clutter_rate) != ("named", 1.0, 0.0):
            out.update(association=sp.association, detection_prob=sp.detection_prob,
                       clutter_rate=sp.clutter_rate, clutter_seed=list(self.clutter_seed),
                       missed=self.missed, false_detections=self.false_detections)
        if sp.occlusion != "static":
            out.update(occlusion=sp.occlusion)
        return out

    def visible(self, robot: RobotState, centres: np.ndarray) -> np.ndarray:
        """Mask (N,): centres (N, 2) [m] in line of sight of the robot's centre (exact)."""
        return self.view.line_of_sight((robot.x, robot.y), centres)

    def observe(self, t: float, robot: RobotState
                ) -> tuple[tuple[ObstacleObservation, ...], tuple[Detection, ...]]:
        """(exact observations, detections) at time ``t`` [s]; one of the two is empty."""
        mode = self.spec.mode
        if mode != "tracked":
            return observe_exact(self.scenario, t, robot, mode == "oracle"), ()
        if t < self._frame * self.period - 1e-9:
            return (), ()
        while self._frame * self.period <= t + 1e-9:
            self._frame += 1
        self.frames += 1
        spec = self.spec
        movers = [o for o in self.scenario.moving_obstacles if o.motion.exists(t)]
        if not movers and spec.clutter_rate == 0.0:
            return (), ()
        p = np.array([o.position(t) for o in movers]).reshape(-1, 2)
        if spec.occlusion == "all":  # the other discs hide what is behind them
            radii = np.array([o.radius for o in movers])
            idx = np.flatnonzero(self.view.expected((robot.x, robot.y), p, radii))
        else:
            idx = np.flatnonzero(self.view.visible((robot.x, robot.y), p))
        if spec.detection_prob < 1.0 and len(idx):
            hit = self.clutter_rng.random(len(idx)) < spec.detection_prob
            self.missed += int((~hit).sum())
            idx = idx[hit]
        noise = self.rng.normal(0.0, spec.noise_m, size=(len(idx), 2)) \
            if spec.noise_m > 0.0 else np.zeros((len(idx), 2))
        named = spec.association == "named"
        out = [Detection(movers[i].name if named else None, t, float(p[i, 0] + e[0]),
                         float(p[i, 1] + e[1]), movers[i].radius)
               for i, e in zip(idx, noise, strict=True)]
        if spec.clutter_rate > 0.0:
            false = self._clutter(robot)
            self.false_detections += len(false)
            out += [Detection(None, t, float(x), float(y), self.clutter_radius) for x, y in false]
        if not named:  # no identity, not even the scenario's order
            out.sort(key=lambda d: (d.x, d.y))
        self.detections += len(out)
        return (), tuple(out)

    def _clutter(self, robot: RobotState) -> np.ndarray:
        """This frame's false detections (K, 2) [m]: a Poisson number (mean ``clutter_rate``)
        of points uniform over what the sensor sees: within ``robot.sensing_range`` of the
        robot (the arena without one), inside the arena and in line of sight."""
        rng, sc = self.clutter_rng, self.scenario
        k = int(rng.poisson(self.spec.clutter_rate))
        x0, y0 = sc.origin
        x1, y1 = x0 + sc.width, y0 + sc.height
        r = sc.robot.sensing_range
        if r is not None:
            x0, y0 = max(x0, robot.x - r), max(y0, robot.y - r)
            x1, y1 = min(x1, robot.x + r), min(y1, robot.y + r)
        out = []
        for _ in range(k):
            for _ in range(_CLUTTER_TRIES):
                q = np.array([rng.uniform(x0, x1), rng.uniform(y0, y1)])
                if r is not None and math.hypot(q[0] - robot.x, q[1] - robot.y) > r:
                    continue
                if self.visible(robot, q[None, :])[0]:
                    out.append(q)
                    break
        return np.array(out).reshape(-1, 2)


def override_sensing(scenario: Scenario, mode: str | None = None, noise_m: float | None = None,
                     rate_hz: float | None = None, *, association: str | None = None,
                     detection_prob: float | None = None, clutter_rate: float | None = None,
                     occlusion: str | None = None) -> Scenario:
    """The scenario with its sensing settings overridden where given (None keeps the
    scenario's, or the defaults when it has no ``sensing:`` block).

    Raises:
        SensingError: a bad setting (:class:`~anyplan.world.sensing.SensingSpec`; its
            ``field`` names it).
    """
    given: dict[str, Any] = {
        "mode": mode, "noise_m": noise_m, "rate_hz": rate_hz, "association": association,
        "detection_prob": detection_prob, "clutter_rate": clutter_rate, "occlusion": occlusion}
    given = {k: (v if isinstance(v, str) else float(v)) for k, v in given.items() if v is not None}
    if not given:
        return scenario
    return replace(scenario, sensing=replace(scenario.sensing or SensingSpec(), **given))


def tracking_setting_names() -> tuple[str, ...]:
    """The names a tracking setting may have: the fields of
    :class:`~anyplan.prediction.tracking.TrackerConfig` (the tracker) and the scalar fields of
    :class:`~anyplan.prediction.uncertain.UncertaintyModel` (the growing disc)."""
    return tuple(f.name for f in fields(TrackerConfig)) + UNCERTAINTY_SETTINGS


def tracking_configs(settings: Mapping[str, float], noise_m: float
                     ) -> tuple[TrackerConfig, UncertaintyModel]:
    """The tracker's settings and its uncertainty model from ``settings`` (name -> value; see
    :func:`tracking_setting_names`), the defaults elsewhere; the tracker's measurement noise
    ``sigma_m`` is the sensor's ``noise_m`` [m] unless ``settings`` gives it (a robot may not
    know its sensor's noise exactly).

    Raises:
        UnknownNameError: a name that is neither (with the nearest known one).
        SettingError: a value out of its field's range (naming the field).
    """
    known = tracking_setting_names()
    for name in settings:
        if name not in known:
            raise UnknownNameError("tracker setting", name, list(known))
    tracker = {k: float(v) for k, v in settings.items() if k not in UNCERTAINTY_SETTINGS}
    tracker.setdefault("sigma_m", float(noise_m))
    disc = {k: float(v) for k, v in settings.items() if k in UNCERTAINTY_SETTINGS}
    return TrackerConfig(**tracker), UncertaintyModel(**disc)  # type: ignore[arg-type]


def parse_tracking_settings(items: Sequence[str]) -> tuple[tuple[str, float], ...]:
    """``KEY=VALUE`` strings (``--tracker``) as sorted ``(name, value)`` pairs, checked by
    :func:`tracking_configs`.

    Raises:
        ValueError: an item without ``=`` or with a value that is not a finite number, an unknown
            name or a value out of range; the message is one line naming the setting.
    """
    out: dict[str, float] = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ValueError(f"expected KEY=VALUE, got '{item}'")
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"{key}: expected a number, got '{text}'") from None
        if not math.isfinite(value):
            raise ValueError(f"{key}: expected a finite number, got '{text}'")
        out[key] = value
    try:
        tracking_configs(out, 0.05)
    except UnknownNameError as exc:
        raise ValueError(str(exc)) from None
    return tuple(sorted(out.items()))


def with_tracking(agent: Agent, spec: SensingSpec,
                  settings: Mapping[str, float] | None = None) -> Agent:
    """``agent`` behind the tracking front end (:class:`~anyplan.agents.perceiving.TrackingAgent`,
    its tracker told the sensor's noise and the tracking ``settings``,
    :func:`tracking_configs`) when ``spec`` is ``tracked``, unless the agent handles detections
    itself (``agent.handles_detections``) or is wrapped already."""
    if spec.mode != "tracked" or getattr(agent, "handles_detections", False) \
            or isinstance(agent, TrackingAgent):
        return agent
    return TrackingAgent(agent, *tracking_configs(settings or {}, spec.noise_m))
