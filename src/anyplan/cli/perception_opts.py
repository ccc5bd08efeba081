"""The perception options shared by ``anyplan run`` and ``anyplan bench``."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from anyplan.errors import UsageError
from anyplan.world.scenario import Scenario
from anyplan.world.sensing import (
    ASSOCIATIONS,
    DEFAULT_NOISE_M,
    DEFAULT_RATE_HZ,
    MODES,
    OCCLUSIONS,
    TRACKED_ONLY,
)

__all__ = ["add_perception_options", "apply_perception", "add_tracker_option", "tracker_settings"]

#: :class:`~anyplan.world.sensing.SensingSpec` fields -> the flags that set them.
_FLAGS = {"mode": "--perception", "noise_m": "--sensor-noise", "rate_hz": "--sensor-rate",
          "association": "--sensor-association", "detection_prob": "--detection-prob",
          "clutter_rate": "--clutter-rate", "occlusion": "--sensor-occlusion"}
#: The same fields -> the ``argparse`` destinations of their flags.
_DESTS = {k: v[2:].replace("-", "_") for k, v in _FLAGS.items()}


def add_perception_options(p: argparse.ArgumentParser) -> None:
    """Add ``--perception``, ``--sensor-noise``, ``--sensor-rate``, ``--sensor-association``,
    ``--detection-prob``, ``--clutter-rate`` and ``--sensor-occlusion`` to ``p``."""
    p.add_argument("--perception", default=None, metavar="MODE",
                   help=f"what the robot knows of the moving obstacles: {' | '.join(MODES)} "
                        "(default: the scenario's sensing block, else oracle; overrides it)")
    p.add_argument("--sensor-noise", type=float, default=None, metavar="M",
                   help=f"tracked: detection noise, standard deviation per axis [m] "
                        f"(default: the scenario's, else {DEFAULT_NOISE_M:g})")
    p.add_argument("--sensor-rate", type=float, default=None, metavar="HZ",
                   help=f"tracked: detection rate [Hz] (default: the scenario's, else "
                        f"{DEFAULT_RATE_HZ:g})")
    p.add_argument("--sensor-association", default=None, metavar="KIND",
                   help=f"tracked: {' | '.join(ASSOCIATIONS)}: detections carry their obstacle's "
                        "name, or no identity (the robot's tracker associates them) (default: "
                        "the scenario's, else named)")
    p.add_argument("--detection-prob", type=float, default=None, metavar="P",
                   help="tracked: probability that a visible obstacle is detected in a frame, "
                        "in (0, 1] (default: the scenario's, else 1)")
    p.add_argument("--clutter-rate", type=float, default=None, metavar="N",
                   help="tracked, anonymous: mean number of false detections per frame "
                        "(default: the scenario's, else 0)")
    p.add_argument("--sensor-occlusion", default=None, metavar="KIND",
                   help=f"tracked: {' | '.join(OCCLUSIONS)}: what hides a moving obstacle, the "
                        "static obstacles or also the other moving obstacles (default: the "
                        "scenario's, else static)")


def apply_perception(command: str, scenarios: Sequence[Scenario],
                     args: argparse.Namespace) -> list[Scenario]:
    """The scenarios with the command line's perception options applied.

    Raises:
        UsageError: a bad setting (an unknown mode or association, a negative noise, a rate
            that is not > 0, ...; exit code 2), naming its flag, or a setting that only
            ``tracked`` perception reads given for a scenario whose perception is not
            ``tracked`` (nothing would read it).
    """
    from anyplan.simulation.perception import override_sensing

    try:
        out = [override_sensing(sc, args.perception, args.sensor_noise, args.sensor_rate,
                                association=args.sensor_association,
                                detection_prob=args.detection_prob,
                                clutter_rate=args.clutter_rate,
                                occlusion=args.sensor_occlusion)
               for sc in scenarios]
    except ValueError as exc:  # a SensingError names its field; the flag is told here
        opt = _FLAGS.get(getattr(exc, "field", ""), "--perception")
        raise UsageError(f"{command}: {opt}: {exc}") from None
    given = [_FLAGS[k] for k in TRACKED_ONLY if getattr(args, _DESTS[k]) is not None]
    if given:
        _only_tracked(command, given[0], "sensor", out)
    return out


def _only_tracked(command: str, flag: str, what: str, scenarios: Sequence[Scenario]) -> None:
    """Refuse ``flag`` (``what`` settings) when one of ``scenarios`` does not perceive
    ``tracked``: nothing would read them."""
    for scenario in scenarios:
        mode = "oracle" if scenario.sensing is None else scenario.sensing.mode
        if mode != "tracked":
            raise UsageError(f"{command}: {flag}: {scenario.name}'s perception is '{mode}'; "
                             f"{what} settings apply to tracked perception only "
                             "(--perception tracked)")


def add_tracker_option(p: argparse.ArgumentParser) -> None:
    """Add ``--tracker KEY=VALUE`` (repeatable) to ``p``."""
    p.add_argument("--tracker", action="append", default=[], metavar="KEY=VALUE",
                   help="tracked: a setting of the robot's tracker or of its uncertain discs, "
                        "e.g. q_cv=0.01 or k_sigma=2 (repeatable; names and defaults in "
                        "docs/perception.md, 'Tracker settings')")


def tracker_settings(command: str, args: argparse.Namespace,
                     scenarios: Sequence[Scenario] = ()) -> tuple[tuple[str, float], ...]:
    """The ``--tracker`` settings as ``(name, value)`` pairs.

    Raises:
        UsageError: a malformed item, an unknown name, a value out of range, or settings with
            one of ``scenarios`` (their perception options applied) whose perception is not
            ``tracked``, where nothing would read them (exit code 2).
    """
    from anyplan.simulation.perception import parse_tracking_settings

    try:
        out = parse_tracking_settings(args.tracker)
    except ValueError as exc:
        raise UsageError(f"{command}: --tracker: {exc}") from None
    if out:
        _only_tracked(command, "--tracker", "tracker", scenarios)
    return out
