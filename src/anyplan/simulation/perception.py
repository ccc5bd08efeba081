"""The robot's sensor: what each perception mode lets an agent see of the moving obstacles.

Modes (:class:`~anyplan.world.sensing.SensingSpec`): ``oracle`` (exact pose, twist and motion
model within ``robot.sensing_range``, the paper's assumption), ``twist`` (the same without the
motion model) and ``tracked`` (noisy position detections of the visible obstacles at the sensor
rate). An obstacle is visible when its centre is in range and in line of sight past the static
obstacles; it exists only within its motion's span. Noise comes from a Generator seeded with
``(seed, NOISE_STREAM)``: the same seed, the same noise.

Frames, visibility and seeding: ``docs/perception.md``, "Perception modes: what the sensor
sees".
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import fields, replace

import numpy as np

from anyplan.agents.base import Agent
from anyplan.agents.perceiving import TrackingAgent
from anyplan.errors import UnknownNameError
from anyplan.geometry.collision import ObstacleSet
from anyplan.prediction.base import ObstacleObservation
from anyplan.prediction.detection import Detection
from anyplan.prediction.tracking import TrackerConfig
from anyplan.prediction.uncertain import UNCERTAINTY_SETTINGS, UncertaintyModel
from anyplan.world.robot import RobotState
from anyplan.world.scenario import Scenario
from anyplan.world.sensing import SensingSpec

__all__ = ["NOISE_STREAM", "Sensor", "observe_exact", "effective_sensing", "override_sensing",
           "with_tracking", "tracking_setting_names", "tracking_configs", "parse_tracking_settings"]

#: Second entry of the noise generator's seed sequence ``(run seed, NOISE_STREAM)``.
NOISE_STREAM = 0x5E45


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
        spec = SensingSpec("twist", spec.noise_m, spec.rate_hz)
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
        self.occluders = ObstacleSet([o.shape for o in scenario.static_obstacles])
        self.period = 1.0 / spec.rate_hz
        self._frame = 0
        self.frames = 0
        self.detections = 0

    def record(self) -> dict[str, object]:
        """What to store in ``result.extra["perception"]``."""
        return {"mode": self.spec.mode, "noise_m": self.spec.noise_m, "rate_hz": self.spec.rate_hz,
                "noise_seed": list(self.seed_sequence), "frames": self.frames,
                "detections": self.detections}

    def visible(self, robot: RobotState, centres: np.ndarray) -> np.ndarray:
        """Mask (N,): centres (N, 2) [m] in line of sight of the robot's centre (exact)."""
        n = len(centres)
        if n == 0 or len(self.occluders) == 0:
            return np.ones(n, dtype=bool)
        a = np.tile([robot.x, robot.y], (n, 1))
        return self.occluders.segments_clearance(a, centres) > 0.0

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
        movers = [o for o in self.scenario.moving_obstacles if o.motion.exists(t)]
        if not movers:
            return (), ()
        p = np.array([o.position(t) for o in movers]).reshape(-1, 2)
        keep = np.ones(len(movers), dtype=bool)
        rng_limit = self.scenario.robot.sensing_range
        if rng_limit is not None:
            keep &= np.hypot(p[:, 0] - robot.x, p[:, 1] - robot.y) <= rng_limit
        idx = np.flatnonzero(keep)
        idx = idx[self.visible(robot, p[idx])]
        noise = self.rng.normal(0.0, self.spec.noise_m, size=(len(idx), 2)) \
            if self.spec.noise_m > 0.0 else np.zeros((len(idx), 2))
        out = tuple(Detection(movers[i].name, t, float(p[i, 0] + e[0]), float(p[i, 1] + e[1]),
                              movers[i].radius) for i, e in zip(idx, noise, strict=True))
        self.detections += len(out)
        return (), out


def override_sensing(scenario: Scenario, mode: str | None = None, noise_m: float | None = None,
                     rate_hz: float | None = None) -> Scenario:
    """The scenario with its sensing settings overridden where given (None keeps the
    scenario's, or the defaults when it has no ``sensing:`` block).

    Raises:
        ValueError: an unknown mode, a negative noise or a rate that is not > 0.
    """
    if mode is None and noise_m is None and rate_hz is None:
        return scenario
    base = scenario.sensing or SensingSpec()
    spec = SensingSpec(base.mode if mode is None else mode,
                       base.noise_m if noise_m is None else float(noise_m),
                       base.rate_hz if rate_hz is None else float(rate_hz))
    return replace(scenario, sensing=spec)


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
