"""Figure style for papers: print sizes, fonts, palettes, readable labels and saving.

Every anyplan figure is made at its *print size*: :data:`TEXT_WIDTH_IN` (a figure across both
columns of a two-column paper, 7.16 in as in IEEE templates) or :data:`COLUMN_WIDTH_IN` (one
column, 3.5 in). Font sizes are therefore the printed sizes, and none is below
:data:`MIN_FONT_PT` (8 pt). :func:`layout_problems` checks a drawn figure for text outside the
figure, overlapping text boxes and fonts below that size; the tests use it on every figure.

This module never selects a matplotlib backend (only the command line does).
"""

from __future__ import annotations

import colorsys
import contextlib
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib
import numpy as np
from matplotlib import patheffects
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.transforms import Bbox

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType

__all__ = ["COLUMN_WIDTH_IN", "TEXT_WIDTH_IN", "MIN_FONT_PT", "FORMATS", "PAPER_RC", "paper_style",
           "qualitative_colors", "halo", "LabelPlacer", "save_figure", "figure_path",
           "layout_problems", "text_boxes", "new_figure", "tight"]

#: Width [in] of one column of a two-column paper.
COLUMN_WIDTH_IN = 3.5
#: Width [in] of a figure across both columns.
TEXT_WIDTH_IN = 7.16
#: Smallest font size [pt] at print size.
MIN_FONT_PT = 8.0
#: File formats the figures can be written in.
FORMATS = ("png", "svg", "pdf")

PAPER_RC: dict[RcKeyType, Any] = {
    "font.size": 8.0, "axes.titlesize": 8.0, "axes.labelsize": 8.0, "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0, "legend.fontsize": 8.0, "legend.title_fontsize": 8.0,
    "figure.titlesize": 9.0, "axes.linewidth": 0.6, "xtick.major.width": 0.6,
    "ytick.major.width": 0.6, "lines.linewidth": 1.2, "legend.handlelength": 1.6,
    "legend.borderaxespad": 0.3, "savefig.dpi": 300, "pdf.fonttype": 42, "ps.fonttype": 42,
}

#: First colours for moving obstacles (tab10 without its blue and green, which mean the robot and
#: the goal here).
_BASE = ["#d62728", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f"]


@contextlib.contextmanager
def paper_style() -> Iterator[None]:
    """Context in which new figures use the paper fonts and line widths."""
    with matplotlib.rc_context(PAPER_RC):
        yield


def qualitative_colors(n: int) -> list[str]:
    """``n`` colours for obstacles: eight distinct tab10 hues, then hues spread by the golden
    angle with alternating saturation and value, so that neighbours in the list always differ
    (draw names at the obstacles too when there are many)."""
    out = list(_BASE[:n])
    k = 0
    while len(out) < n:
        h = (0.07 + k * 0.6180339887) % 1.0
        s = (0.9, 0.55, 0.75)[k % 3]
        v = (0.75, 0.55, 0.9)[(k // 3) % 3]
        r, g, b = colorsys.hsv_to_rgb(h, s, v)
        out.append(f"#{int(r * 255):02x}{int(g * 255):02x}{int(b * 255):02x}")
        k += 1
    return out


def halo(color: str = "white", width: float = 2.2) -> list[Any]:
    """Path effects drawing a ``color`` outline under text (readable on any background)."""
    return [patheffects.withStroke(linewidth=width, foreground=color)]


# Label offsets [pt] tried in order: beside, above, below, then diagonals, then further out.
_OFFSETS = [(1, 0), (0, 1), (0, -1), (-1, 0), (1, 1), (-1, 1), (1, -1), (-1, -1)]


class LabelPlacer:
    """Places text labels on an axes so that their boxes overlap neither each other nor the
    figure's other text, and stay inside the axes; a label with no free place is left out.

    Requests are kept: :meth:`layout` (re)places all of them, so call it again after the
    figure's layout changed (:func:`save_figure` does).
    """

    def __init__(self, ax: Any) -> None:
        self.ax = ax
        self.requests: list[tuple[tuple[float, float], str, float, dict[str, Any], bool]] = []
        self.artists: list[Text] = []

    def add(self, xy: Sequence[float] | np.ndarray, text: str, *, gap_pt: float = 3.0, center: bool = False,
            **kw: Any) -> None:
        """Ask for ``text`` near the data point ``xy``: centred on it if ``center`` (and it fits),
        else beside it, ``gap_pt`` points away (plus further out if needed)."""
        self.requests.append(((float(xy[0]), float(xy[1])), text, gap_pt, kw, center))

    def layout(self) -> list[Text]:
        """Place every request in order (earlier requests win); returns the placed texts."""
        for a in self.artists:
            a.remove()
        self.artists = []
        fig = self.ax.figure
        renderer = _renderer(fig)
        pad = 2.0 * fig.dpi / 72.0  # keep labels 2 pt apart
        area = self.ax.get_window_extent(renderer)
        taken = [t.get_window_extent(renderer) for t in _visible_texts(fig)
                 if t not in self.artists]
        for xy, text, gap, kw, center in self.requests:
            tries = [(0.0, 0.0)] if center else []
            tries += [(dx * gap * m, dy * gap * m) for m in (1.0, 3.0) for dx, dy in _OFFSETS]
            for dx, dy in tries:
                ha = "center" if dx == 0 else ("left" if dx > 0 else "right")
                va = "center" if dy == 0 else ("bottom" if dy > 0 else "top")
                t = self.ax.annotate(text, xy, xytext=(dx, dy), textcoords="offset points",
                                     ha=ha, va=va, annotation_clip=False, **kw)
                box = t.get_window_extent(renderer)
                padded = box.padded(pad)
                if _inside(box, area) and not any(_overlap(padded, b) for b in taken):
                    taken.append(box)
                    self.artists.append(t)
                    break
                t.remove()
        return self.artists


def new_figure(figsize: tuple[float, float]) -> Figure:
    """A figure of ``figsize`` [in] on an Agg canvas of its own: no pyplot, no global backend
    (so it works the same in scripts, notebooks and the command line)."""
    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig


def tight(fig: Any, rect: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 1.0), **kw: Any) -> None:
    """``fig.tight_layout(rect=rect)``, twice: the first pass moves axes of fixed aspect, the
    second fits the titles and labels around where they ended up."""
    for _ in range(2):
        fig.tight_layout(rect=rect, **kw)


def _renderer(fig: Any) -> Any:
    if not hasattr(fig.canvas, "get_renderer"):
        FigureCanvasAgg(fig)
    return fig.canvas.get_renderer()


def _inside(box: Bbox, area: Bbox, tol: float = 0.5) -> bool:
    return (box.x0 >= area.x0 - tol and box.y0 >= area.y0 - tol and box.x1 <= area.x1 + tol
            and box.y1 <= area.y1 + tol)


def _overlap(a: Bbox, b: Bbox, tol: float = 0.5) -> bool:
    return a.x0 < b.x1 - tol and b.x0 < a.x1 - tol and a.y0 < b.y1 - tol and b.y0 < a.y1 - tol


def _hidden_tick_labels(fig: Any) -> set[int]:
    """Ids of the tick labels matplotlib does not draw (ticks outside the view interval)."""
    out: set[int] = set()
    for ax in fig.get_axes():
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            tol = 1e-9 * max(abs(lo), abs(hi), 1.0)
            for tick in [*axis.get_major_ticks(), *axis.get_minor_ticks()]:
                loc = tick.get_loc()
                if loc is None or not lo - tol <= loc <= hi + tol:
                    out.update((id(tick.label1), id(tick.label2)))
    return out


def _visible_texts(fig: Any) -> list[Text]:
    out = []
    hidden = _hidden_tick_labels(fig)
    for t in fig.findobj(Text):
        if not t.get_visible() or not t.get_text().strip() or id(t) in hidden:
            continue
        if t.axes is not None and not t.axes.get_visible():
            continue
        out.append(t)
    return out


def text_boxes(fig: Any) -> list[tuple[Text, Bbox]]:
    """Every visible, non-empty text of ``fig`` with its box in display coordinates (the figure
    is drawn first so that tick labels and layouts are final)."""
    renderer = _renderer(fig)
    fig.draw(renderer)
    return [(t, t.get_window_extent(renderer)) for t in _visible_texts(fig)]


def layout_problems(fig: Any, min_font_pt: float = MIN_FONT_PT) -> list[str]:
    """What is wrong with the text of ``fig`` at its print size: texts (partly) outside the
    figure, pairs of overlapping text boxes, fonts below ``min_font_pt``. Empty if none."""
    boxes = text_boxes(fig)
    frame = fig.bbox
    problems = []
    for t, b in boxes:
        if not _inside(b, frame, tol=1.0):
            problems.append(f"outside the figure: {t.get_text()!r}")
        size = float(t.get_fontsize())  # Text reports points (the stubs also allow names)
        if size < min_font_pt - 1e-9:
            problems.append(f"font {size:g} pt < {min_font_pt:g} pt: {t.get_text()!r}")
    for i, (t1, b1) in enumerate(boxes):
        for t2, b2 in boxes[i + 1:]:
            if _overlap(b1, b2, tol=1.0):
                problems.append(f"overlapping: {t1.get_text()!r} and {t2.get_text()!r}")
    return problems


def figure_path(path: str | Path, fmt: str | None = None) -> Path:
    """``path`` with the suffix of ``fmt`` (png, svg or pdf); without ``fmt``, ``path``'s own
    suffix must be one of those. Raises ValueError otherwise."""
    path = Path(path)
    if fmt is None:
        fmt = path.suffix.lower().lstrip(".")
        if fmt not in FORMATS:
            raise ValueError(f"{path.name}: a figure must end in .png, .svg or .pdf")
        return path
    fmt = fmt.lower()
    if fmt not in FORMATS:
        raise ValueError(f"unknown figure format '{fmt}' (one of {', '.join(FORMATS)})")
    return path.with_suffix("." + fmt)


def save_figure(fig: Any, path: str | Path, *, placers: Sequence[LabelPlacer] = (),
                dpi: int = 300, png_copy: Any = None) -> Path:
    """Freeze ``fig``'s layout, (re)place the labels of ``placers`` and write ``path`` (PNG, SVG
    or PDF by its suffix); returns the path. ``png_copy`` (a binary file object), if given, also
    receives the figure as a 120 dpi PNG (for web pages)."""
    path = figure_path(path)
    fig.draw(_renderer(fig))
    fig.set_layout_engine("none")
    for p in placers:
        p.layout()
    fig.savefig(path, dpi=dpi, format=path.suffix[1:].lower())
    if png_copy is not None:
        fig.savefig(png_copy, dpi=120, format="png")
    return path
