"""A detection: what a position sensor reports about one moving obstacle at one instant."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Detection"]


@dataclass(frozen=True)
class Detection:
    """A noisy position of a named obstacle (perfect association), with its disc radius.

    Attributes:
        name: Obstacle name (the association is given, as by a perfect tracker front end).
        t: Time of the measurement [s].
        x, y: Measured centre [m] (the true centre plus sensor noise).
        radius: Disc radius [m] (a detector measures the extent of what it sees; given exactly).
    """

    name: str
    t: float
    x: float
    y: float
    radius: float
