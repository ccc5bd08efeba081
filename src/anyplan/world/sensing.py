"""How the robot perceives the moving obstacles: the scenario's ``sensing:`` block.

Three modes (``docs/scenarios.md``, "Sensing"):

* ``oracle``: every visible obstacle with its pose, twist and full motion model (the paper's
  assumption; the default when a scenario has no ``sensing:`` block);
* ``twist``: the current pose and twist, exact, and no future;
* ``tracked``: noisy positions only (Gaussian, ``noise_m`` [m] standard deviation per axis), at
  ``rate_hz`` [Hz], within ``robot.sensing_range`` and in line of sight; each detection keeps
  its radius and, with ``association: named`` (the default), the obstacle's name (perfect
  association); ``anonymous`` detections carry no identity, a visible obstacle is detected with
  probability ``detection_prob`` and ``clutter_rate`` false detections come per frame; with
  ``occlusion: all`` the moving obstacles hide one another too.

The sensor itself lives in :mod:`anyplan.simulation.perception`; this module only holds the
validated settings, so that the scenario loader can parse them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from anyplan.errors import AnyplanError

__all__ = ["MODES", "ASSOCIATIONS", "OCCLUSIONS", "TRACKED_ONLY", "SensingSpec", "SensingError",
           "DEFAULT_NOISE_M", "DEFAULT_RATE_HZ", "MAX_CLUTTER_RATE", "without_unread_settings"]

#: Known perception modes.
MODES = ("oracle", "twist", "tracked")
#: How ``tracked`` detections are told apart: by the obstacle's name, or not at all.
ASSOCIATIONS = ("named", "anonymous")
#: What hides a moving obstacle from the ``tracked`` sensor: the static obstacles, or also the
#: other moving obstacles' discs.
OCCLUSIONS = ("static", "all")
#: The settings only ``tracked`` perception reads: with ``oracle`` or ``twist`` a scenario's
#: ``sensing:`` block and the command line refuse them.
TRACKED_ONLY = ("noise_m", "rate_hz", "association", "detection_prob", "clutter_rate", "occlusion")
#: Largest mean number of false detections per frame.
MAX_CLUTTER_RATE = 1000.0
#: Default position noise [m] (standard deviation per axis) of ``tracked``.
DEFAULT_NOISE_M = 0.05
#: Default detection rate [Hz] of ``tracked``.
DEFAULT_RATE_HZ = 10.0


class SensingError(AnyplanError, ValueError):
    """A bad perception setting; ``field`` names it (``mode``, ``noise_m``, ``rate_hz``,
    ``association``, ``detection_prob``, ``clutter_rate`` or ``occlusion``)."""

    def __init__(self, field: str, message: str) -> None:
        self.field = field
        super().__init__(message)


@dataclass(frozen=True)
class SensingSpec:
    """Perception settings.

    Attributes:
        mode: ``oracle``, ``twist`` or ``tracked``.
        noise_m: Standard deviation [m] of the detection noise on x and on y (``tracked``).
        rate_hz: Detection rate [Hz] (``tracked``).
        association: ``named`` (each detection carries its obstacle's name: perfect
            association) or ``anonymous`` (no identity: the robot's tracker associates them,
            ``docs/perception.md``, "Anonymous detections") (``tracked``).
        detection_prob: Probability that a visible obstacle is detected in a frame, in (0, 1]
            (``tracked``).
        clutter_rate: Mean number of false detections per frame (Poisson), >= 0; only with
            ``anonymous`` association (a named detection is a real obstacle) (``tracked``).
        occlusion: ``static`` (the static obstacles hide what is behind them) or ``all`` (the
            moving obstacles' discs too: a person behind a person is not detected)
            (``tracked``).

    Raises:
        SensingError: an unknown mode, association or occlusion, a negative or non-finite
            noise, a rate that is not > 0, a detection probability outside (0, 1], a negative
            clutter rate or clutter with named detections.
    """

    mode: str = "oracle"
    noise_m: float = DEFAULT_NOISE_M
    rate_hz: float = DEFAULT_RATE_HZ
    association: str = "named"
    detection_prob: float = 1.0
    clutter_rate: float = 0.0
    occlusion: str = "static"

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise SensingError("mode", f"unknown perception mode '{self.mode}' (known: {', '.join(MODES)})")
        from anyplan.world.limits import MAX_SENSOR_RATE_HZ, MAX_SIZE_M

        if not (math.isfinite(self.noise_m) and 0.0 <= self.noise_m <= MAX_SIZE_M):
            raise SensingError("noise_m", f"sensor noise must be >= 0 m and <= {MAX_SIZE_M:g} m, got "
                             f"{self.noise_m:g}")
        if not (math.isfinite(self.rate_hz) and 0.0 < self.rate_hz <= MAX_SENSOR_RATE_HZ):
            raise SensingError("rate_hz", f"sensor rate must be > 0 Hz and <= {MAX_SENSOR_RATE_HZ:g} Hz, got "
                             f"{self.rate_hz:g}")
        if self.association not in ASSOCIATIONS:
            raise SensingError("association", f"unknown association '{self.association}' "
                                              f"(known: {', '.join(ASSOCIATIONS)})")
        if not (math.isfinite(self.detection_prob) and 0.0 < self.detection_prob <= 1.0):
            raise SensingError("detection_prob", "detection probability must be > 0 and <= 1, "
                                                 f"got {self.detection_prob:g}")
        if not (math.isfinite(self.clutter_rate) and 0.0 <= self.clutter_rate <= MAX_CLUTTER_RATE):
            raise SensingError("clutter_rate", "clutter rate must be >= 0 and <= "
                                               f"{MAX_CLUTTER_RATE:g} per frame, got {self.clutter_rate:g}")
        if self.occlusion not in OCCLUSIONS:
            raise SensingError("occlusion", f"unknown occlusion '{self.occlusion}' "
                                            f"(known: {', '.join(OCCLUSIONS)})")
        if self.clutter_rate > 0.0 and self.association != "anonymous":
            raise SensingError("clutter_rate", "false detections need association: anonymous "
                                               "(a named detection is a real obstacle)")

    def to_dict(self) -> dict[str, float | str]:
        """The ``sensing:`` block of the YAML schema: the mode alone unless ``tracked``, whose
        association keys are written only when not their defaults."""
        if self.mode != "tracked":
            return {"mode": self.mode}
        return self.identity()

    def identity(self) -> dict[str, float | str]:
        """Every setting that tells this spec from another, also the ones ``oracle`` and
        ``twist`` do not read (the block as :meth:`to_dict` wrote it for every mode before those
        were refused): what :meth:`~anyplan.world.scenario.Scenario.content_hash` hashes, so
        that a scenario's hash, and the stored runs found by it, stay the same."""
        out: dict[str, float | str] = {"mode": self.mode, "noise_m": self.noise_m,
                                       "rate_hz": self.rate_hz}
        if self.association != "named":
            out["association"] = self.association
        if self.detection_prob != 1.0:
            out["detection_prob"] = self.detection_prob
        if self.clutter_rate != 0.0:
            out["clutter_rate"] = self.clutter_rate
        if self.occlusion != "static":
            out["occlusion"] = self.occlusion
        return out


def without_unread_settings(block: Any) -> Any:
    """A ``sensing:`` block (as earlier versions wrote it, e.g. into a results database) without
    the :data:`TRACKED_ONLY` keys when its mode is not ``tracked`` (nothing read them); anything
    else unchanged."""
    if not isinstance(block, dict) or block.get("mode") == "tracked":
        return block
    return {k: v for k, v in block.items() if k not in TRACKED_ONLY}
