"""A detection: what a position sensor reports about one moving obstacle at one instant."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Detection"]


@dataclass(frozen=True)
class Detection:
    """A noisy position of an obstacle, with its disc radius.

    Attributes:
        name: Obstacle name with ``named`` association (given, as by a perfect tracker front
            end); None for an ``anonymous`` detection, which may also be a false one (clutter):
            the tracker associates it (:class:`~anyplan.prediction.tracking.Tracker`).
        t: Time of the measurement [s].
        x, y: Measured centre [m] (the true centre plus sensor noise).
        radius: Disc radius [m] (a detector measures the extent of what it sees; given exactly).
    """

    name: str | None
    t: float
    x: float
    y: float
    radius: float
