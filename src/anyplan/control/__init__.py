"""Tracking control: Kanayama's law (ICRA 1990) following a reference :class:`Trajectory`."""

from anyplan.control.kanayama import KanayamaController, KanayamaGains, tracking_errors

__all__ = ["KanayamaController", "KanayamaGains", "tracking_errors"]
