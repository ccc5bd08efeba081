"""Occupancy-grid maps in ROS ``map_server`` format: a YAML file and a PGM or PNG image.

The YAML keys of ROS's ``map_server`` (and Nav2's): ``image`` (PGM ``P2``/``P5`` or PNG),
``resolution`` [m/pixel], ``origin`` [x, y, yaw] (only yaw = 0), ``negate``,
``occupied_thresh``, ``free_thresh`` and ``mode`` (``trinary``, ``scale`` or ``raw``). Cell
values follow map_server; a cell is **free** only when its value is known and its occupancy is
below ``free_thresh``: every other cell, occupied, uncertain or unknown, is a static obstacle.

Keys and how pixel shades become cell values: ``docs/scenarios.md``, "Maps: cell values".
"""

from __future__ import annotations

import hashlib
import math
import struct
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from anyplan.errors import ScenarioError, shorten
from anyplan.geometry.cells import cell_boxes, merge_cells
from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Shape
from anyplan.world.limits import MAX_COORD_M
from anyplan.world.schema import Ctx
from anyplan.world.yaml_load import YamlLimitError, load_yaml

__all__ = ["OccupancyMap", "load_map", "read_pgm", "read_image", "MAX_CELLS", "MIN_RESOLUTION_M"]

#: Largest map accepted, in cells (a 100 m x 100 m map at 0.02 m is 25 million cells); an image
#: whose header declares more pixels is refused before its pixels are read.
MAX_CELLS = 64_000_000
#: Smallest cell side [m]: finer cells near the coordinate limit would round to empty boxes.
MIN_RESOLUTION_M = 1e-6
_PNG_MAGIC = b"\x89PNG\r\n\x1a\n"

_MODES = ("trinary", "scale", "raw")
_REQUIRED = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")
_OPTIONAL = ("mode",)


@dataclass(frozen=True, eq=False)
class OccupancyMap:
    """A loaded map. Row 0 of the arrays is the *bottom* row of cells (smallest y).

    Attributes:
        source: The map YAML file.
        image: The image file.
        resolution: Cell side [m].
        origin: (x, y) [m] of the lower-left corner of cell (0, 0).
        values: int8 (ny, nx): 0 free, 100 occupied, -1 unknown, 1..99 (scale/raw) uncertain.
        blocked: bool (ny, nx): the cells that are static obstacles.
        mode, negate, occupied_thresh, free_thresh: as in the YAML file.
    """

    source: str
    image: str
    resolution: float
    origin: tuple[float, float]
    values: np.ndarray
    blocked: np.ndarray
    mode: str = "trinary"
    negate: bool = False
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196
    _cache: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    @property
    def shape(self) -> tuple[int, int]:
        """(ny, nx) cells."""
        return (int(self.values.shape[0]), int(self.values.shape[1]))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """The map's extent (xmin, ymin, xmax, ymax) [m]."""
        ny, nx = self.shape
        x0, y0 = self.origin
        return (x0, y0, x0 + nx * self.resolution, y0 + ny * self.resolution)

    @property
    def n_blocked(self) -> int:
        """Number of obstacle cells."""
        return int(self.blocked.sum())

    @property
    def rects(self) -> np.ndarray:
        """The blocked cells merged into disjoint rectangles, (M, 4) cell ranges (cached)."""
        if "rects" not in self._cache:
            self._cache["rects"] = merge_cells(self.blocked)
        return self._cache["rects"]

    @property
    def boxes(self) -> np.ndarray:
        """The merged rectangles as boxes (xmin, ymin, xmax, ymax) [m], (M, 4) (cached)."""
        if "boxes" not in self._cache:
            b = cell_boxes(self.rects, self.origin, self.resolution)
            b.setflags(write=False)
            self._cache["boxes"] = b
        return self._cache["boxes"]

    def obstacle_set(self, shapes: Sequence[Shape] = (),
                     bounds: Sequence[float] | None = None) -> ObstacleSet:
        """The merged boxes with ``shapes`` and the walls ``bounds``, as an (indexed)
        :class:`~anyplan.geometry.collision.ObstacleSet`; cached per (shapes, bounds)."""
        key = (tuple(shapes), None if bounds is None else tuple(float(b) for b in bounds))
        cache = self._cache.setdefault("obstacle_sets", {})
        if key not in cache:
            cache[key] = ObstacleSet(key[0], bounds=key[1], boxes=self.boxes)
        return cache[key]

    def cell_of(self, x: float, y: float) -> tuple[int, int] | None:
        """(row, col) of the cell containing (x, y) [m], None outside the map."""
        ny, nx = self.shape
        i = math.floor((x - self.origin[0]) / self.resolution)
        j = math.floor((y - self.origin[1]) / self.resolution)
        return (j, i) if 0 <= i < nx and 0 <= j < ny else None

    def digest(self) -> str:
        """SHA-256 (hex, 16 chars) of the cells, resolution and origin."""
        if "digest" not in self._cache:
            h = hashlib.sha256()
            h.update(np.ascontiguousarray(self.blocked).tobytes())
            h.update(repr((self.shape, self.resolution, self.origin)).encode())
            self._cache["digest"] = h.hexdigest()[:16]
        return self._cache["digest"]

    def __eq__(self, other: object) -> bool:
        return isinstance(other, OccupancyMap) and self.digest() == other.digest()

    def __hash__(self) -> int:
        return hash(self.digest())


# --------------------------------------------------------------------------------------------
# Images
# --------------------------------------------------------------------------------------------
def _pgm_tokens(data: bytes, n: int) -> tuple[list[bytes], int]:
    """The first ``n`` whitespace-separated header tokens (comments skipped) and the offset
    just after the last one."""
    toks: list[bytes] = []
    i = 0
    while len(toks) < n:
        while i < len(data) and data[i:i + 1].isspace():
            i += 1
        if i < len(data) and data[i:i + 1] == b"#":
            while i < len(data) and data[i:i + 1] not in (b"\n", b"\r"):
                i += 1
            continue
        j = i
        while j < len(data) and not data[j:j + 1].isspace() and data[j:j + 1] != b"#":
            j += 1
        if j == i:
            raise ValueError("truncated PGM header")
        toks.append(data[i:j])
        i = j
    return toks, i


def read_pgm(path: str | Path) -> tuple[np.ndarray, int]:
    """A PGM image (P2 ASCII or P5 binary): (pixels (H, W) int, top row first; maxval)."""
    data = Path(path).read_bytes()
    magic = data[:2]
    if magic not in (b"P2", b"P5"):
        raise ValueError(f"not a PGM image (magic {magic!r}; expected P2 or P5)")
    toks, off = _pgm_tokens(data[2:], 3)
    try:
        w, h, maxval = (int(t) for t in toks)
    except ValueError:
        raise ValueError("bad PGM header (width, height, maxval must be integers)") from None
    if w <= 0 or h <= 0:
        raise ValueError(f"image size {w} x {h} is empty")
    if not 0 < maxval < 65536:
        raise ValueError(f"PGM maxval {maxval} is outside 1..65535")
    if w * h > MAX_CELLS:
        raise ValueError(f"image {w} x {h} has more than {MAX_CELLS} pixels")
    body = data[2 + off:]
    if magic == b"P5":
        body = body[1:]  # the single whitespace after maxval
        dt = np.dtype(">u2") if maxval > 255 else np.dtype("u1")
        need = w * h * dt.itemsize
        if len(body) < need:
            raise ValueError(f"image data has {len(body)} bytes, {w} x {h} pixels need {need}")
        px = np.frombuffer(body[:need], dtype=dt).astype(np.int64).reshape(h, w)
    else:
        try:
            vals = np.array(body.split(), dtype=np.int64)
        except OverflowError:  # an integer beyond int64 (numpy raises this, not ValueError)
            raise ValueError(f"pixel values outside 0..{maxval}") from None
        except ValueError:
            raise ValueError("bad P2 pixel data (not integers)") from None
        if len(vals) != w * h:
            raise ValueError(f"image data has {len(vals)} pixels, {w} x {h} need {w * h}")
        px = vals.reshape(h, w)
    if px.size and (px.min() < 0 or px.max() > maxval):
        raise ValueError(f"pixel values outside 0..{maxval}")
    return px, maxval


def read_image(path: str | Path) -> tuple[np.ndarray, np.ndarray | None]:
    """Shade (H, W) float in [0, 255] (mean of the colour channels; top row first) and alpha
    (H, W) in [0, 255] or None, from a PGM or PNG file."""
    p = Path(path)
    with p.open("rb") as f:
        head = f.read(8)
    if head[:2] in (b"P2", b"P5"):
        px, maxval = read_pgm(p)
        return px.astype(float) * (255.0 / maxval), None
    if head != _PNG_MAGIC:
        raise ValueError("unsupported image format (expected PGM P2/P5 or PNG)")
    w, h = _png_size(p)
    if w * h > MAX_CELLS:  # refused from the header, before Pillow reads (or warns about) it
        raise ValueError(f"image {w} x {h} has more than {MAX_CELLS} pixels")
    try:
        from PIL import Image  # Pillow: matplotlib's own image dependency
    except ImportError:  # pragma: no cover - Pillow is a dependency
        raise ValueError("reading PNG maps needs Pillow (pip install pillow)") from None
    with warnings.catch_warnings():
        # MAX_CELLS is the limit here: Pillow's own (lowered by someone) neither warns nor raises
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)
        try:
            return _read_png(Image.open(p))
        except Image.DecompressionBombError:  # only with Pillow's limit lowered below 2 x MAX_CELLS
            raise ValueError(f"image {w} x {h} is beyond Pillow's size limit") from None


def _png_size(path: str | Path) -> tuple[int, int]:
    """(width, height) declared by a PNG file's header (its first chunk, IHDR)."""
    with Path(path).open("rb") as f:
        head = f.read(24)
    if len(head) < 24 or head[:8] != _PNG_MAGIC or head[12:16] != b"IHDR":
        raise ValueError("bad PNG header (no IHDR chunk after the signature)")
    w, h = struct.unpack(">II", head[16:24])
    return int(w), int(h)


def _read_png(opened: Any) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`read_image` of an opened Pillow image (closed on return; its size was checked
    from the file's header)."""
    from PIL import Image

    with opened:
        im: Image.Image = opened
        mode = im.mode
        if mode == "P" or mode == "PA":
            im = im.convert("RGBA")
            mode = "RGBA"
        elif mode == "1":
            im = im.convert("L")
            mode = "L"
        a = np.asarray(im)
    if mode in ("I;16", "I;16B", "I;16L", "I"):
        return a.astype(float) * (255.0 / 65535.0), None
    if mode == "L":
        return a.astype(float), None
    if mode == "LA":
        return a[..., 0].astype(float), a[..., 1].astype(float)
    if mode == "RGB":
        return a[..., :3].astype(float).mean(axis=2), None
    if mode == "RGBA":
        return a[..., :3].astype(float).mean(axis=2), a[..., 3].astype(float)
    raise ValueError(f"unsupported PNG pixel mode {mode}")


def cell_values(shade: np.ndarray, alpha: np.ndarray | None, *, mode: str, negate: bool,
                occupied_thresh: float, free_thresh: float) -> np.ndarray:
    """map_server's cell values (int8, same shape as ``shade``): 0 free, 100 occupied, -1
    unknown, 1..99 uncertain (see the module docstring)."""
    v = 255.0 - shade if negate else shade
    out = np.empty(v.shape, dtype=np.int8)
    if mode == "raw":
        r = np.rint(v)
        out[:] = np.where(r <= 100.0, r, -1).astype(np.int8)
        return out
    occ = (255.0 - v) / 255.0
    out[:] = -1
    mid = (occ <= occupied_thresh) & (occ >= free_thresh)
    if mode == "scale":
        opaque = np.ones(v.shape, dtype=bool) if alpha is None else alpha >= 255.0
        ratio = (occ - free_thresh) / (occupied_thresh - free_thresh)
        sc = (1.0 + np.rint(98.0 * ratio)).clip(1, 99).astype(np.int8)
        out[mid & opaque] = sc[mid & opaque]
    out[occ > occupied_thresh] = 100
    out[occ < free_thresh] = 0
    return out


# --------------------------------------------------------------------------------------------
# The YAML file
# --------------------------------------------------------------------------------------------
def _num(src: str, obj: Any, fld: str, **limits: Any) -> float:
    """A finite number, checked as the scenario's numbers are (one beyond the float range is
    refused, not an OverflowError); ``limits`` as :meth:`~anyplan.world.schema.Ctx.number`."""
    return Ctx(src).number(obj, fld, **limits)


def load_map(path: str | Path) -> OccupancyMap:
    """Load a map_server YAML file and its image.

    Raises:
        ScenarioError: naming the map file (or its image) and the field at fault.
    """
    src = str(path)
    p = Path(path)
    if not p.is_file():
        raise ScenarioError(src, "", "no such map file")
    try:
        data = load_yaml(p.read_text())
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(src, "", f"cannot read file ({exc.__class__.__name__})") from None
    except YamlLimitError as exc:  # malformed, duplicate keys, limits (strict, as scenarios)
        raise ScenarioError(src, "", str(exc)) from None
    if not isinstance(data, Mapping):
        raise ScenarioError(src, "", "expected a mapping of map_server keys (image, resolution, "
                                     "origin, negate, occupied_thresh, free_thresh)")
    import difflib

    known = _REQUIRED + _OPTIONAL
    for key in data:
        if key not in known:
            close = difflib.get_close_matches(str(key), known, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise ScenarioError(src, str(key), f"unknown key{hint} (known: {', '.join(known)})")
    for key in _REQUIRED:
        if key not in data:
            raise ScenarioError(src, key, "missing required key")
    image = data["image"]
    if not isinstance(image, str) or not image:
        raise ScenarioError(src, "image", "expected a file name")
    res = _num(src, data["resolution"], "resolution", positive=True, lo=MIN_RESOLUTION_M)
    org = data["origin"]
    if not isinstance(org, list | tuple) or len(org) != 3:
        raise ScenarioError(src, "origin", "expected [x, y, yaw]")
    ox, oy = (_num(src, v, f"origin[{i}]", hi=MAX_COORD_M) for i, v in enumerate(org[:2]))
    yaw = _num(src, org[2], "origin[2]")
    if yaw != 0.0:
        raise ScenarioError(src, "origin[2]", f"yaw {yaw:g} rad is not supported: rotate the "
                                              "image instead (only yaw = 0)")
    neg = data["negate"]  # 0 or 1, or a YAML boolean (Nav2 reads an int, else a bool)
    if not isinstance(neg, bool) and (not isinstance(neg, int) or neg not in (0, 1)):
        raise ScenarioError(src, "negate", f"expected 0 or 1 (or true/false), got {shorten(neg)}")
    occ_t = _num(src, data["occupied_thresh"], "occupied_thresh")
    free_t = _num(src, data["free_thresh"], "free_thresh")
    if not 0.0 <= occ_t <= 1.0:
        raise ScenarioError(src, "occupied_thresh", f"must be in [0, 1], got {occ_t:g}")
    if not 0.0 <= free_t <= 1.0:
        raise ScenarioError(src, "free_thresh", f"must be in [0, 1], got {free_t:g}")
    if not free_t < occ_t:
        raise ScenarioError(src, "free_thresh", f"must be < occupied_thresh ({occ_t:g}), "
                                                f"got {free_t:g}")
    mode = data.get("mode", "trinary")
    if mode not in _MODES:
        close = difflib.get_close_matches(str(mode), _MODES, n=1)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        raise ScenarioError(src, "mode", f"unknown mode '{mode}'{hint} (known: {', '.join(_MODES)})")
    img = Path(image) if Path(image).is_absolute() else p.parent / image
    if not img.is_file():
        raise ScenarioError(src, "image", f"no such file {img}")
    try:
        shade, alpha = read_image(img)
    except (OSError, ValueError) as exc:
        raise ScenarioError(src, "image", f"{img}: {exc}") from None
    if shade.size == 0:
        raise ScenarioError(src, "image", f"{img}: the image is empty")
    ny, nx = shade.shape
    x1, y1 = ox + nx * res, oy + ny * res
    if not max(abs(x1), abs(y1)) <= MAX_COORD_M:
        raise ScenarioError(src, "resolution", f"the map's far corner ({x1:g}, {y1:g}) is beyond the "
                                               f"coordinate limit +-{MAX_COORD_M:g} m (origin + {nx} x "
                                               f"{ny} cells of {res:g} m)")
    vals = cell_values(shade, alpha, mode=mode, negate=bool(neg), occupied_thresh=occ_t,
                       free_thresh=free_t)[::-1].copy()
    # free: known and value / 100 < free_thresh (trinary, scale: exactly the value-0 cells)
    blocked = (vals < 0) | (vals.astype(float) / 100.0 >= free_t) if mode == "raw" else vals != 0
    vals.setflags(write=False)
    blocked.setflags(write=False)
    return OccupancyMap(source=src, image=str(img), resolution=res, origin=(ox, oy), values=vals,
                        blocked=blocked, mode=mode, negate=bool(neg), occupied_thresh=occ_t,
                        free_thresh=free_t)
