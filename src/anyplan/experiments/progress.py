"""A dependency-free progress bar with an estimate of the time left, written to stderr."""

from __future__ import annotations

import sys
import time
from typing import TextIO

__all__ = ["ProgressBar", "format_duration"]


def format_duration(seconds: float) -> str:
    """``h:mm:ss`` or ``m:ss`` for a duration [s]; ``--:--`` if unknown."""
    if seconds != seconds or seconds < 0 or seconds == float("inf"):
        return "--:--"
    s = int(round(seconds))
    h, rem = divmod(s, 3600)
    m, s = divmod(rem, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


class ProgressBar:
    """Progress over ``total`` items with elapsed time and ETA.

    On a terminal the bar is redrawn in place; otherwise (a log file, a test) a line is written
    at most every ``min_interval`` seconds and at the end. The ETA is the mean wall time per
    finished item (which already reflects the parallelism) times the items left.

    Args:
        total: Number of items.
        stream: Where to write (default ``sys.stderr``).
        enabled: False writes nothing.
        min_interval: Seconds between lines when not on a terminal.
    """

    def __init__(self, total: int, stream: TextIO | None = None, enabled: bool = True,
                 min_interval: float = 5.0, width: int = 28) -> None:
        self.total = max(int(total), 0)
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.min_interval = min_interval
        self.width = width
        self.done = 0
        self.t0 = time.monotonic()
        self._last = -1e9
        self._tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.note = ""

    def eta(self) -> float:
        """Estimated seconds left (NaN before the first item)."""
        if self.done == 0:
            return float("nan")
        return (time.monotonic() - self.t0) / self.done * (self.total - self.done)

    def render(self) -> str:
        """The current status line."""
        frac = self.done / self.total if self.total else 1.0
        fill = int(round(frac * self.width))
        bar = "#" * fill + "." * (self.width - fill)
        el = time.monotonic() - self.t0
        return (f"[{bar}] {self.done}/{self.total} {100 * frac:3.0f}%  elapsed "
                f"{format_duration(el)}  ETA {format_duration(self.eta())}"
                + (f"  {self.note}" if self.note else ""))

    def update(self, n: int = 1, note: str | None = None) -> None:
        """Count ``n`` more finished items and redraw."""
        self.done += n
        if note is not None:
            self.note = note
        if not self.enabled:
            return
        now = time.monotonic()
        if self._tty:
            self.stream.write("\r" + self.render() + "\x1b[K")
            self.stream.flush()
        elif now - self._last >= self.min_interval or self.done >= self.total:
            self.stream.write(self.render() + "\n")
            self.stream.flush()
            self._last = now

    def close(self) -> None:
        """End the line on a terminal."""
        if self.enabled and self._tty:
            self.stream.write("\n")
            self.stream.flush()
