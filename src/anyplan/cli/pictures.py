"""Picture files of the commands that draw: PNG, SVG or PDF, from a suffix or ``--format``."""

from __future__ import annotations

from pathlib import Path

from anyplan.errors import UsageError

__all__ = ["picture_path", "FORMATS"]

#: Picture formats the commands write.
FORMATS = ("png", "svg", "pdf")


def picture_path(target: str, fmt: str | None, command: str, option: str) -> Path:
    """The picture file of ``option`` ``target`` in format ``fmt`` (default: its suffix)."""
    from anyplan.errors import shorten

    path = Path(target)
    shown = shorten(target, 120)
    suffix = path.suffix.lower().lstrip(".")
    if fmt is not None and suffix in FORMATS and suffix != fmt:
        raise UsageError(f"{command}: {option} {shown}: the suffix says {suffix}, --format says {fmt}")
    if fmt is None and suffix not in FORMATS:
        kind = f"unknown file type {shorten(path.suffix, 12)}" if path.suffix else "no file type"
        raise UsageError(f"{command}: {option} {shown}: {kind}; a picture must end in .png, .svg "
                         "or .pdf (or give --format)")
    return path if fmt is None or suffix == fmt else path.with_name(path.name + "." + fmt)
