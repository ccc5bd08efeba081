"""How the robot perceives the moving obstacles: the scenario's ``sensing:`` block.

Three modes (``docs/scenarios.md``, "Sensing"):

* ``oracle``: every visible obstacle with its pose, twist and full motion model (the paper's
  assumption; the default when a scenario has no ``sensing:`` block);
* ``twist``: the current pose and twist, exact, and no future;
* ``tracked``: noisy positions only (Gaussian, ``noise_m`` [m] standard deviation per axis), at
  ``rate_hz`` [Hz], within ``robot.sensing_range`` and in line of sight; each detection keeps
  the obstacle's name (perfect association) and its radius, nothing else.

The sensor itself lives in :mod:`anyplan.simulation.perception`; this module only holds the
validated settings, so that the scenario loader can parse them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from anyplan.errors import AnyplanError

__all__ = ["MODES", "SensingSpec", "SensingError", "DEFAULT_NOISE_M", "DEFAULT_RATE_HZ"]

#: Known perception modes.
MODES = ("oracle", "twist", "tracked")
#: Default position noise [m] (standard deviation per axis) of ``tracked``.
DEFAULT_NOISE_M = 0.05
#: Default detection rate [Hz] of ``tracked``.
DEFAULT_RATE_HZ = 10.0


class SensingError(AnyplanError, ValueError):
    """A bad perception setting; ``field`` names it (``mode``, ``noise_m`` or ``rate_hz``)."""

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

    Raises:
        SensingError: an unknown mode, a negative or non-finite noise, a rate that is not > 0.
    """

    mode: str = "oracle"
    noise_m: float = DEFAULT_NOISE_M
    rate_hz: float = DEFAULT_RATE_HZ

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

    def to_dict(self) -> dict[str, float | str]:
        """The ``sensing:`` block of the YAML schema."""
        return {"mode": self.mode, "noise_m": self.noise_m, "rate_hz": self.rate_hz}
