"""Checks of command-line values made before any long work starts.

* ``argparse`` types (:func:`seed`, :func:`time_limit`, :func:`sim_step`, ...) refuse a bad option
  value while parsing, with exit code 2 and one line that states the limit;
* :func:`writable_file` and :func:`writable_folder` prove that an output can be written (the folder
  exists or can be made, the target is not a folder, and opening it for writing succeeds) before
  a simulation whose result would otherwise be lost;
* :func:`safe_name` turns a name (a scenario's, a planner's) into one path component, so default
  output paths derived from names stay under ``runs/``;
* :func:`flag_message` reports a library error that names a settings field
  (:class:`~anyplan.config.SettingError`) with the flag that sets the field.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
from pathlib import Path

from anyplan.config import SettingError
from anyplan.errors import AnyplanError, one_line, shorten
from anyplan.world import limits as L

__all__ = [
    "seed", "time_limit", "sim_step", "actuation_noise", "localization_noise", "positive_seconds", "count",
    "nonempty", "playback_speed", "writable_file", "writable_folder", "safe_name", "PLOT_SUFFIXES",
    "MAX_RUNS", "MAX_TASKS", "MAX_JOBS", "MAX_PLAN_TIME_S", "MAX_ACTUATION_SIGMA", "MAX_LOCALIZATION_SIGMA",
    "SPEED_RANGE", "SIM_FLAGS",
    "flag_message"]

#: :class:`~anyplan.simulation.SimConfig` fields and the flags of ``run`` and ``bench`` that set them.
SIM_FLAGS = {"dt": "--dt", "time_limit": "--time-limit"}


def flag_message(exc: BaseException, flags: dict[str, str]) -> str:
    """``exc`` as a command-line message: a :class:`~anyplan.config.SettingError` of a field in
    ``flags`` is told with its flag (``--dt must be in [0.001, 0.05] s, got 0.5``)."""
    if isinstance(exc, SettingError) and exc.field in flags:
        return f"{flags[exc.field]} {exc.problem}"
    return str(exc)

#: Picture formats the plots can be written in (matplotlib's, without optional back ends).
PLOT_SUFFIXES = (".png", ".pdf", ".svg", ".svgz", ".jpg", ".jpeg", ".eps", ".ps", ".tif", ".tiff",
                 ".webp")
#: Most runs per (scenario, planner) of a bench.
MAX_RUNS = 10_000
#: Most runs of one bench in all (runs x scenarios x planners).
MAX_TASKS = 200_000
#: Most worker processes.
MAX_JOBS = 256
#: Longest planning budget of ``anyplan plan`` / ``bench-planning`` [s].
MAX_PLAN_TIME_S = 3600.0
#: Range of the animation's playback speed (x real time).
SPEED_RANGE = (0.01, 1000.0)


class OutputError(AnyplanError):
    """An output path cannot be written."""


def _number(text: str, what: str) -> float:
    try:
        x = float(text)
    except (ValueError, OverflowError):
        raise argparse.ArgumentTypeError(f"expected {what}, got {shorten(text)}") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"expected {what}, finite, got {shorten(text)}")
    return x


def seed(text: str) -> int:
    """A random seed: an integer in [0, 2**63 - 1]."""
    try:
        s = int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid int value: {shorten(text)}") from None
    if not 0 <= s <= L.MAX_SEED:
        raise argparse.ArgumentTypeError(f"a seed must be in [0, 2**63 - 1], got {shorten(text)}")
    return s


def time_limit(text: str) -> float:
    """A simulated time limit [s] in (0, MAX_TIME_LIMIT_S]."""
    x = _number(text, "a time in seconds")
    if not 0.0 < x <= L.MAX_TIME_LIMIT_S:
        raise argparse.ArgumentTypeError(f"time limit must be in (0, {L.MAX_TIME_LIMIT_S:g}] s, "
                                         f"got {x:g}")
    return x


def sim_step(text: str) -> float:
    """A simulation step [s] in [MIN_DT_S, 0.05]."""
    x = _number(text, "a step in seconds")
    if not L.MIN_DT_S <= x <= 0.05:
        raise argparse.ArgumentTypeError(f"dt must be in [{L.MIN_DT_S:g}, 0.05] s, got {x:g}")
    return x


#: Largest execution-error spread accepted on the command line (m/s or rad/s).
MAX_ACTUATION_SIGMA = 10.0
#: Largest localization-error spread accepted on the command line (m or rad).
MAX_LOCALIZATION_SIGMA = 10.0


def _spread_pair(text: str, names: str, units: str, most: float) -> tuple[float, float]:
    """Two comma-separated spreads, each in [0, most]."""
    parts = text.split(",")
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"expected {names} ({units}), got {shorten(text)}")
    a, b = (_number(p.strip(), f"a spread in {units.replace(', ', ' or ')}") for p in parts)
    for x in (a, b):
        if not 0.0 <= x <= most:
            raise argparse.ArgumentTypeError(f"spreads must be in [0, {most:g}], got {x:g}")
    return a, b


def actuation_noise(text: str) -> tuple[float, float]:
    """``SIGMA_V,SIGMA_OMEGA``: the robot's execution-error spreads [m/s, rad/s], each in
    [0, MAX_ACTUATION_SIGMA]."""
    return _spread_pair(text, "SIGMA_V,SIGMA_OMEGA", "m/s, rad/s", MAX_ACTUATION_SIGMA)


def localization_noise(text: str) -> tuple[float, float]:
    """``SIGMA_XY,SIGMA_THETA``: the robot's localization-error spreads [m per axis, rad], each
    in [0, MAX_LOCALIZATION_SIGMA]."""
    return _spread_pair(text, "SIGMA_XY,SIGMA_THETA", "m, rad", MAX_LOCALIZATION_SIGMA)


def positive_seconds(text: str) -> float:
    """A planning time budget [s] in (0, MAX_PLAN_TIME_S]."""
    x = _number(text, "a time in seconds")
    if not 0.0 < x <= MAX_PLAN_TIME_S:
        raise argparse.ArgumentTypeError(f"must be in (0, {MAX_PLAN_TIME_S:g}] s, got {x:g}")
    return x


def count(most: int):  # noqa: ANN201 - an argparse type
    """An argparse type: an integer in [1, most]."""
    def parse(text: str) -> int:
        try:
            n = int(text, 10)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {shorten(text)}") from None
        if not 1 <= n <= most:
            raise argparse.ArgumentTypeError(f"must be in [1, {most}], got {shorten(text)}")
        return n

    parse.__name__ = "count"
    return parse


def nonempty(what: str):  # noqa: ANN201 - an argparse type
    """An argparse type: a string that is not empty (nor only spaces), which would otherwise
    read as the current folder or as "not given"; ``what`` says what is expected."""
    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError(f"empty; expected {what}")
        return text

    parse.__name__ = "nonempty"
    return parse


def playback_speed(text: str) -> float:
    """Animation playback speed (x real time) in SPEED_RANGE."""
    x = _number(text, "a number")
    lo, hi = SPEED_RANGE
    if not lo <= x <= hi:
        raise argparse.ArgumentTypeError(f"must be in [{lo:g}, {hi:g}] x real time, got {x:g}")
    return x


def safe_name(name: str, limit: int = 80) -> str:
    """``name`` as one harmless path component: characters other than letters, digits, ``.``,
    ``_``, ``-`` and ``+`` become ``_``, leading dots are dropped, and it is at most ``limit``
    characters; never empty, ``.`` or ``..``."""
    s = re.sub(r"[^A-Za-z0-9._+-]", "_", str(name)).lstrip(".")[:limit]
    return s or "_"


def _mkdir(folder: Path, opt: str) -> None:
    if folder.is_dir():
        return
    if folder.exists():
        raise OutputError(f"{opt} {one_line(folder, 120)}: exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{opt} {one_line(folder, 120)}: cannot create folder "
                          f"({exc.strerror or exc})") from None


def _guarded(fn):  # noqa: ANN001, ANN202
    """Any OSError of a path test (a name too long, a loop of links...) is an OutputError."""
    import functools

    @functools.wraps(fn)
    def wrapper(path, opt, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
        try:
            return fn(path, opt, *args, **kwargs)
        except OutputError:
            raise
        except (OSError, ValueError) as exc:  # ValueError: an embedded NUL byte
            reason = getattr(exc, "strerror", None) or str(exc)
            raise OutputError(f"{opt} {one_line(path, 120)}: cannot write ({one_line(reason, 80)})") \
                from None

    return wrapper


@_guarded
def writable_folder(folder: str | Path, opt: str) -> Path:
    """Create ``folder`` if needed and prove a file can be created in it.

    Raises:
        OutputError: it is a file, cannot be created, or is not writable.
    """
    folder = Path(folder)
    _mkdir(folder, opt)
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{opt} {one_line(folder, 120)}: folder is not writable")
    return folder


@_guarded
def writable_file(path: str | Path, opt: str, suffixes: tuple[str, ...] | None = None,
                  make_parent: bool = True) -> Path:
    """Prove that ``path`` can be written, without changing an existing file.

    Args:
        path: The output file.
        opt: The option's name for the message (``--json``).
        suffixes: Accepted file name endings, or None for any.
        make_parent: Create a missing parent folder (else a missing one is an error).

    Raises:
        OutputError: a wrong suffix, a folder, a missing or unwritable folder, or a file that
            cannot be opened for writing.
    """
    path = Path(path)
    shown = one_line(path, 120)
    if suffixes is not None and path.suffix.lower() not in suffixes:
        kind = f"unknown file type {shorten(path.suffix, 12)}" if path.suffix else "no file type"
        raise OutputError(f"{opt} {shown}: {kind} (known: {', '.join(suffixes)})")
    if path.is_dir():
        raise OutputError(f"{opt} {shown}: is a folder, expected a file name")
    parent = path.parent
    if make_parent:
        _mkdir(parent, opt)
    elif not parent.is_dir():
        raise OutputError(f"{opt} {shown}: folder {one_line(parent, 120)} does not exist")
    existed = path.exists()
    try:
        # Append mode writes nothing: an existing file keeps its content.
        with open(path, "ab"):
            pass
    except OSError as exc:
        raise OutputError(f"{opt} {shown}: cannot write ({exc.strerror or exc})") from None
    if not existed:
        with contextlib.suppress(OSError):
            path.unlink()
    return path
