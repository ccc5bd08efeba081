"""Generated floor plans written as ROS map_server maps (PGM + YAML), and scenarios on them.

* :func:`office`: outer walls, a corridor along the middle, rooms on both sides (random widths)
  with a door each onto the corridor, and furniture (desks, cabinets) in the rooms, kept off
  the doorways.
* :func:`warehouse`: outer walls, rows of racks along x separated by aisles, and cross aisles
  cut through the racks.

The grids are boolean (row 0 at the bottom), 0.05 m cells by default. :func:`write_map` writes
one as a P5 PGM (0 occupied, 254 free) and its map_server YAML; :func:`map_scenario` writes a
scenario file that uses it (``static_map:``), with optional walkers: discs that walk back and
forth along a corridor or aisle (looping ``waypoints`` motions). Everything is drawn from one
``numpy.random.Generator``, so a seed gives the same map.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from anyplan.world.yaml_load import dump_yaml

__all__ = ["FloorPlan", "office", "warehouse", "roughen", "write_map", "map_scenario", "walkers"]

#: Robot of the map scenarios: a 0.3 m disc at 1 m/s (an indoor service robot).
ROBOT = {"radius": 0.3, "v_max": 1.0, "omega_max": 1.5, "a_max": 1.0, "alpha_max": 3.0,
         "goal_tolerance": 0.2}


@dataclass
class FloorPlan:
    """A generated plan: the grid, its cell size [m], a start and goal [m], and the corridor
    lanes (x0, y, x1, y) [m] along which walkers may walk."""

    kind: str
    occ: np.ndarray
    resolution: float
    start: tuple[float, float, float]
    goal: tuple[float, float]
    lanes: list[tuple[float, float, float, float]] = field(default_factory=list)
    seed: int | None = None

    @property
    def size_m(self) -> tuple[float, float]:
        """(width, height) [m]."""
        return (self.occ.shape[1] * self.resolution, self.occ.shape[0] * self.resolution)


def _cells(v: float, res: float) -> int:
    return int(round(v / res))


def _box(occ: np.ndarray, res: float, x0: float, y0: float, x1: float, y1: float,
         value: bool = True) -> None:
    ny, nx = occ.shape
    i0, i1 = max(_cells(x0, res), 0), min(_cells(x1, res), nx)
    j0, j1 = max(_cells(y0, res), 0), min(_cells(y1, res), ny)
    if i1 > i0 and j1 > j0:
        occ[j0:j1, i0:i1] = value


def office(width: float = 30.0, height: float = 20.0, resolution: float = 0.05, *,
           rng: np.random.Generator | int | None = 0, corridor: float = 2.0,
           wall: float = 0.15, door: float = 1.0, furniture: int = 3) -> FloorPlan:
    """An office: a corridor along x through the middle, rooms 3-6 m wide on both sides.

    The task goes from 1 m inside the door of the first room on the south side to 1 m inside
    the door of the last room on the north side (those spots are kept free of furniture).

    Args:
        width, height: Outer size [m].
        resolution: Cell side [m].
        rng: Generator or seed.
        corridor: Corridor width [m] (between the wall faces).
        wall: Wall thickness [m].
        door: Door width [m].
        furniture: Up to this many pieces per room.
    """
    seed = rng if isinstance(rng, int) else None
    g = np.random.default_rng(rng)
    nx, ny = _cells(width, resolution), _cells(height, resolution)
    occ = np.zeros((ny, nx), dtype=bool)
    res = resolution
    # outer walls
    _box(occ, res, 0, 0, width, wall)
    _box(occ, res, 0, height - wall, width, height)
    _box(occ, res, 0, 0, wall, height)
    _box(occ, res, width - wall, 0, width, height)
    yc0 = height / 2 - corridor / 2 - wall    # lower corridor wall: [yc0, yc0 + wall]
    yc1 = height / 2 + corridor / 2           # upper corridor wall: [yc1, yc1 + wall]
    _box(occ, res, wall, yc0, width - wall, yc0 + wall)
    _box(occ, res, wall, yc1, width - wall, yc1 + wall)
    doors: list[list[tuple[float, float]]] = [[], []]   # a point 1 m inside each door
    for lo, hi, wall_y0, side in ((wall, yc0, yc0, -1), (yc1 + wall, height - wall, yc1, +1)):
        x = wall
        while x < width - wall - 1e-9:
            w = float(g.uniform(3.0, 6.0))
            x1 = width - wall if width - wall - (x + w) < 3.0 else x + w
            if x1 < width - wall:
                _box(occ, res, x1, lo, x1 + wall, hi)   # wall between rooms
            # the door, somewhere along the room's corridor wall
            dx = float(g.uniform(x + 0.3, max(x + 0.3, x1 - 0.3 - door)))
            _box(occ, res, dx, wall_y0, dx + door, wall_y0 + wall, value=False)
            doors[side > 0].append((dx + door / 2, wall_y0 - 1.0 if side < 0 else wall_y0 + wall + 1.0))
            # furniture, off the doorway (a 1.5 m deep clear zone in front of the door)
            for _ in range(int(g.integers(0, furniture + 1))):
                fw, fh = float(g.uniform(0.6, 1.6)), float(g.uniform(0.5, 0.9))
                if g.random() < 0.5:
                    fw, fh = fh, fw
                fx = float(g.uniform(x + wall + 0.1, max(x + wall + 0.1, x1 - 0.1 - fw)))
                fy = float(g.uniform(lo + 0.1, max(lo + 0.1, hi - 0.1 - fh)))
                near_door = (fx < dx + door + 0.5 and fx + fw > dx - 0.5
                             and (fy < wall_y0 + 1.5 if side > 0 else fy + fh > wall_y0 - 1.5))
                if not near_door:
                    _box(occ, res, fx, fy, fx + fw, fy + fh)
            x = x1 + wall
    ym = height / 2
    # from the first room on the south side to the last room on the north side, through
    # both doors and the corridor
    sx, sy = doors[0][0]
    start = (round(sx, 3), round(sy, 3), float(np.pi / 2))
    gx, gy = doors[1][-1]
    goal = (round(gx, 3), round(gy, 3))
    lanes = [(1.5, ym - corridor / 4, width - 1.5, ym - corridor / 4),
             (width - 1.5, ym + corridor / 4, 1.5, ym + corridor / 4)]
    return FloorPlan("office", occ, res, start, goal, lanes, seed)


def warehouse(width: float = 60.0, height: float = 40.0, resolution: float = 0.05, *,
              rng: np.random.Generator | int | None = 0, wall: float = 0.2,
              rack: float = 1.0, aisle: float = 2.5, cross: int = 3) -> FloorPlan:
    """A warehouse: racks along x (``rack`` [m] deep) between aisles (``aisle`` [m]), with
    ``cross`` cross aisles cut through at random x, and a 3 m free band at both ends."""
    seed = rng if isinstance(rng, int) else None
    g = np.random.default_rng(rng)
    nx, ny = _cells(width, resolution), _cells(height, resolution)
    occ = np.zeros((ny, nx), dtype=bool)
    res = resolution
    _box(occ, res, 0, 0, width, wall)
    _box(occ, res, 0, height - wall, width, height)
    _box(occ, res, 0, 0, wall, height)
    _box(occ, res, width - wall, 0, width, height)
    y = wall + aisle
    rows = []
    while y + rack + aisle < height - wall:
        _box(occ, res, 3.0, y, width - 3.0, y + rack)
        rows.append(y)
        y += rack + aisle
    for _ in range(cross):
        cx = float(g.uniform(6.0, width - 8.0))
        _box(occ, res, cx, wall, cx + 2.0, height - wall, value=False)
    # keep the outer walls whole
    _box(occ, res, 0, 0, width, wall)
    _box(occ, res, 0, height - wall, width, height)
    start = (1.5, 1.5 + wall, float(np.pi / 2))
    goal = (width - 1.5, height - 1.5 - wall)
    lanes = [(3.5, r - aisle / 2, width - 3.5, r - aisle / 2) for r in rows[1::2]]
    return FloorPlan("warehouse", occ, res, start, goal, lanes, seed)


def roughen(plan: FloorPlan, bumps: float = 0.3, speckles: int = 0, *,
            rng: np.random.Generator | int | None = 0, keep_clear: float = 1.0) -> FloorPlan:
    """A SLAM-like copy of ``plan``: each free cell next to an obstacle becomes occupied with
    probability ``bumps`` (ragged walls), plus ``speckles`` isolated occupied cells (sensor
    noise), none within ``keep_clear`` [m] of the start or the goal."""
    g = np.random.default_rng(rng)
    occ = plan.occ.copy()
    ny, nx = occ.shape
    pad = np.pad(occ, 1)
    edge = ~occ & (pad[:-2, 1:-1] | pad[2:, 1:-1] | pad[1:-1, :-2] | pad[1:-1, 2:])
    occ |= edge & (g.random(occ.shape) < bumps)
    if speckles:
        occ[g.integers(0, ny, speckles), g.integers(0, nx, speckles)] = True
    res = plan.resolution
    jj, ii = np.mgrid[0:ny, 0:nx]
    for px, py in (plan.start[:2], plan.goal):
        near = np.hypot((ii + 0.5) * res - px, (jj + 0.5) * res - py) < keep_clear
        occ[near & ~plan.occ] = False
    return FloorPlan(plan.kind, occ, res, plan.start, plan.goal, list(plan.lanes), plan.seed)


def write_map(plan: FloorPlan, stem: str | Path) -> Path:
    """Write ``stem.pgm`` (P5: 0 occupied, 254 free) and ``stem.yaml`` (map_server); returns
    the YAML path."""
    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    img = np.where(plan.occ[::-1], 0, 254).astype(np.uint8)
    ny, nx = img.shape
    pgm = stem.with_suffix(".pgm")
    pgm.write_bytes(f"P5\n# anyplan {plan.kind} seed {plan.seed}\n{nx} {ny}\n255\n".encode()
                    + img.tobytes())
    meta = {"image": pgm.name, "resolution": plan.resolution, "origin": [0.0, 0.0, 0.0],
            "negate": 0, "occupied_thresh": 0.65, "free_thresh": 0.196}
    out = stem.with_suffix(".yaml")
    out.write_text(dump_yaml(meta, sort_keys=False))
    return out


def walkers(plan: FloorPlan, n: int, *, rng: np.random.Generator | int | None = 0,
            speed: tuple[float, float] = (0.5, 1.2), radius: float = 0.3,
            keep_clear: float = 2.5) -> list[dict[str, Any]]:
    """``n`` walkers pacing the plan's lanes back and forth (looping waypoint motions), each
    starting at a random point of its lane at least ``keep_clear`` [m] from the robot's
    start and goal."""
    g = np.random.default_rng(rng)
    out = []
    sx, sy = plan.start[:2]
    gx, gy = plan.goal
    for k in range(n):
        x0, y0, x1, y1 = plan.lanes[k % len(plan.lanes)]
        v = float(g.uniform(*speed))
        length = float(np.hypot(x1 - x0, y1 - y0))
        for _ in range(100):
            u = float(g.uniform(0.0, 1.0))
            px, py = x0 + u * (x1 - x0), y0 + u * (y1 - y0)
            if min(np.hypot(px - sx, py - sy), np.hypot(px - gx, py - gy)) >= keep_clear:
                break
        # forward to the lane's end, back to its start, forward to the first point: a loop
        t1 = (1.0 - u) * length / v
        t2 = t1 + length / v
        t3 = t2 + u * length / v
        kf = [[0.0, px, py], [t1, x1, y1], [t2, x0, y0]]
        if t3 > t2 + 1e-9:
            kf.append([t3, px, py])
        else:
            kf[-1] = [t2, x0, y0]
        out.append({"name": f"W{k + 1}", "type": "waypoints", "radius": radius,
                    "keyframes": [[round(a, 6) for a in row] for row in kf]})
    return out


def map_scenario(plan: FloorPlan, directory: str | Path, name: str, *,
                 n_walkers: int = 0, rng: np.random.Generator | int | None = 0,
                 time_limit: float = 150.0) -> Path:
    """Write the map and a scenario using it into ``directory``; returns the scenario path."""
    d = Path(directory)
    write_map(plan, d / f"{name}-map")
    data: dict[str, Any] = {
        "name": name,
        "description": f"generated {plan.kind} {plan.size_m[0]:g} m x {plan.size_m[1]:g} m, "
                       f"{plan.resolution:g} m cells, {n_walkers} walkers (seed {plan.seed})",
        "time_limit": time_limit,
        "static_map": f"{name}-map.yaml",
        "robot": {"start": list(plan.start), "goal": list(plan.goal), **ROBOT},
    }
    if n_walkers:
        data["dynamic_obstacles"] = walkers(plan, n_walkers, rng=rng)
    out = d / f"{name}.yaml"
    out.write_text(dump_yaml(data, sort_keys=False))
    return out
