"""Exact shortest paths for a disc robot among polygons and circles, by a visibility graph.

The tangent (reduced) visibility graph of the obstacles inflated by the robot radius ``r``
(Lozano-Pérez & Wesley, CACM 1979; de Berg et al., *Computational Geometry*, ch. 15), searched
by Dijkstra; the inflated obstacles' round corners become chains of chords with a step of at
most ``arc_step`` [rad]. ``variant="lower"`` inscribes the chains (a **lower bound** on the
optimum, to ~1e-9 m per contact); ``variant="feasible"`` circumscribes them and checks every
edge exactly with :class:`~anyplan.geometry.collision.ObstacleSet` (a valid path, within a
relative ~``arc_step**2 / 8`` of the optimum). The robot centre stays in the bounds shrunk by
``r``; obstacles are not clipped at the walls. Convex components for the interior tests travel
as one record, :class:`Components`. Details: ``docs/planning.md`` ("Exact optimum").
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Circle, Polygon
from anyplan.planning._visgraph_boxes import convex_box_corners, corner_arcs, inscribed_radius
from anyplan.planning._visgraph_kernels import Components, edges, edges_relaxed, points_in_any
from anyplan.planning.base import Planner, PlanResult
from anyplan.planning.problem import Problem
from anyplan.planning.status import PlannerStatus
from anyplan.planning.termination import TerminationCondition

__all__ = ["VisGraphResult", "shortest_path", "lower_bound", "reachable_margin", "usable_margin",
           "VisGraphPlanner", "warm_up"]

DEFAULT_ARC_STEP = 2.0 * math.pi / 64.0
#: Room [m] :func:`usable_margin` leaves on each side of a passage narrower than wanted.
USABLE_SLACK_M = 0.01
_EPS = 1e-9  # geometric tolerance [m] of the interior tests


@dataclass(frozen=True)
class VisGraphResult:
    """A visibility-graph shortest path.

    Attributes:
        status: EXACT_SOLUTION, INVALID_START/GOAL, or INFEASIBLE (no path in the graph).
        path: Waypoints (N, 2) [m]; (0, 2) if none.
        cost: Length [m]; inf if none.
        variant: "lower" or "feasible".
        n_nodes: Graph vertices (including start and goal).
        n_edges: Visible bitangent edges.
        time_s: Wall-clock time of the computation [s].
    """

    status: PlannerStatus
    path: np.ndarray
    cost: float
    variant: str
    n_nodes: int
    n_edges: int
    time_s: float


# ------------------------------------------------------------------------------------------
# Geometry construction (plain numpy; small)
# ------------------------------------------------------------------------------------------
def _ccw(v: np.ndarray) -> np.ndarray:
    a2 = float(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
    return v if a2 >= 0.0 else v[::-1].copy()


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _ear_clip(v: np.ndarray) -> list[np.ndarray]:
    """Triangulate a simple CCW polygon (O(n^3), fine for obstacle outlines)."""
    idx = list(range(len(v)))
    tris: list[np.ndarray] = []
    guard = 0
    while len(idx) > 3 and guard < 10 * len(v) ** 2:
        guard += 1
        n = len(idx)
        for k in range(n):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % n]
            a, b, c = v[i0], v[i1], v[i2]
            if _cross(a, b, c) <= 1e-15:
                continue  # reflex or degenerate corner: not an ear
            inside = False
            for j in idx:
                if j in (i0, i1, i2):
                    continue
                p = v[j]
                if _cross(a, b, p) >= 0 and _cross(b, c, p) >= 0 and _cross(c, a, p) >= 0:
                    inside = True
                    break
            if not inside:
                tris.append(np.array([a, b, c]))
                idx.pop(k)
                break
        else:  # numerically stuck: fan the rest (still a subset of the hull; rare)
            break
    if len(idx) >= 3:
        for k in range(1, len(idx) - 1):
            tris.append(np.array([v[idx[0]], v[idx[k]], v[idx[k + 1]]]))
    return tris


def _arc(center: np.ndarray, rad: float, a0: float, a1: float, step: float,
         circumscribed: bool) -> np.ndarray:
    """Chain replacing the arc of radius ``rad`` from angle a0 to a1 (a1 >= a0)."""
    k = max(1, math.ceil((a1 - a0) / step - 1e-12))
    d = (a1 - a0) / k
    if not circumscribed:
        ang = a0 + d * np.arange(k + 1)
        rr = np.full(k + 1, rad)
    else:
        # Tangent points at both ends, polygon corners in between at rad / cos(d / 2).
        ang = np.concatenate([[a0], a0 + d * (np.arange(k) + 0.5), [a1]])
        rr = np.concatenate([[rad], np.full(k, rad / math.cos(d / 2.0)), [rad]])
    return center + rr[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])


class _Builder:
    """Collects convex interior-test components and graph nodes with tangent neighbours."""

    def __init__(self) -> None:
        self.comps: list[np.ndarray] = []
        self.nodes: list[np.ndarray] = []
        self.prev: list[np.ndarray] = []
        self.next: list[np.ndarray] = []

    def chain(self, pts: np.ndarray, before: np.ndarray, after: np.ndarray) -> None:
        """Nodes ``pts`` (a convex chain, CCW); ``before``/``after`` continue it at both ends."""
        n = len(pts)
        for j in range(n):
            self.nodes.append(pts[j])
            self.prev.append(pts[j - 1] if j > 0 else before)
            self.next.append(pts[j + 1] if j < n - 1 else after)

    def ring(self, pts: np.ndarray) -> None:
        """Nodes of a closed convex CCW polygon."""
        n = len(pts)
        for j in range(n):
            self.nodes.append(pts[j])
            self.prev.append(pts[j - 1])
            self.next.append(pts[(j + 1) % n])


def _build(problem: Problem, variant: str, arc_step: float) -> _Builder:
    r = _radius(problem, variant)
    circ = variant == "feasible"
    b = _Builder()
    grow = (1.0 + 1e-9) if circ else 1.0  # feasible nodes sit a hair outside the true boundary
    for shape in problem.obstacles.shapes:
        if isinstance(shape, Circle):
            rad = shape.radius + r
            n = max(8, math.ceil(2.0 * math.pi / arc_step))
            ang = 2.0 * math.pi * np.arange(n) / n
            rr = rad / math.cos(math.pi / n) * grow if circ else rad
            pts = shape.center + rr * np.column_stack([np.cos(ang), np.sin(ang)])
            b.comps.append(pts)
            b.ring(pts)
            continue
        assert isinstance(shape, Polygon)
        v = _ccw(np.asarray(shape.vertices, dtype=float))
        n = len(v)
        d = np.roll(v, -1, axis=0) - v                      # edge i: v[i] -> v[i+1]
        d = d / np.hypot(d[:, 0], d[:, 1])[:, None]
        nrm = np.column_stack([d[:, 1], -d[:, 0]])           # outward normals (CCW polygon)
        convex = np.array([_cross(v[i - 1], v[i], v[(i + 1) % n]) > 1e-14 for i in range(n)])
        b.comps.extend([v] if shape.is_convex else _ear_clip(v))
        if r <= 0.0:
            for i in range(n):
                if convex[i]:
                    b.chain(v[i:i + 1], v[i - 1], v[(i + 1) % n])
            continue
        for i in range(n):
            q = np.array([v[i], v[(i + 1) % n], v[(i + 1) % n] + r * nrm[i], v[i] + r * nrm[i]])
            b.comps.append(_ccw(q))
        for i in range(n):
            if not convex[i]:
                continue
            a0 = math.atan2(nrm[i - 1, 1], nrm[i - 1, 0])
            a1 = math.atan2(nrm[i, 1], nrm[i, 0])
            while a1 < a0:
                a1 += 2.0 * math.pi
            pts = _arc(v[i], r * grow, a0, a1, arc_step, circ)
            b.comps.append(np.vstack([v[i:i + 1], _arc(v[i], r, a0, a1, arc_step, False)]))
            b.chain(pts, pts[0] - d[i - 1], pts[-1] + d[i])
    if len(problem.obstacles.boxes):
        # A map's merged cells: nodes only around the convex corners of their union; their
        # interior test is the exact clearance of the boxes (see _box_set).
        corners, dirs = convex_box_corners(problem.obstacles.boxes, obstacles=_box_set(problem))
        if r <= 0.0:  # a point robot: the boxes are interior-test components themselves
            b.comps.extend(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
                           for x0, y0, x1, y1 in problem.obstacles.boxes)
        for pts, before, after in corner_arcs(corners, dirs, r, arc_step, circ, grow, _arc):
            b.chain(pts, before, after)
    return b


def _box_set(problem: Problem) -> ObstacleSet:
    """The boxes alone, without walls and shapes (cached on the obstacle set)."""
    obs = problem.obstacles
    cached = getattr(obs, "_visgraph_boxes", None)
    if cached is None:
        cached = ObstacleSet([], boxes=obs.boxes)
        obs._visgraph_boxes = cached  # type: ignore[attr-defined]
    return cached


def _radius(problem: Problem, variant: str) -> float:
    # The feasible variant must pass the exact check, which uses check_radius (> 0).
    return problem.check_radius if variant == "feasible" else problem.radius


def _pack(comps: list[np.ndarray]) -> Components:
    """The record of the convex components ``comps`` (CCW vertex arrays)."""
    if not comps:
        z = np.zeros(0)
        return Components(z, z, np.zeros(1, np.int64), np.zeros((0, 4)), z, z, z)
    verts = np.vstack(comps)
    starts = np.concatenate([[0], np.cumsum([len(c) for c in comps])]).astype(np.int64)
    box = np.array([[c[:, 0].min(), c[:, 1].min(), c[:, 0].max(), c[:, 1].max()] for c in comps])
    nx, ny, off = [], [], []
    for c in comps:
        e = np.roll(c, -1, axis=0) - c
        ln = np.hypot(e[:, 0], e[:, 1])
        ln[ln == 0.0] = 1.0
        ux, uy = e[:, 1] / ln, -e[:, 0] / ln
        nx.append(ux)
        ny.append(uy)
        off.append(ux * c[:, 0] + uy * c[:, 1])
    return Components(np.ascontiguousarray(verts[:, 0]), np.ascontiguousarray(verts[:, 1]),
                      starts, box, np.concatenate(nx), np.concatenate(ny), np.concatenate(off))


# ------------------------------------------------------------------------------------------
# Public API
# ------------------------------------------------------------------------------------------
def shortest_path(problem: Problem, *, variant: str = "feasible",
                  arc_step: float = DEFAULT_ARC_STEP, prune_tangent: bool = True) -> VisGraphResult:
    """Shortest start-goal path among the inflated obstacles.

    Args:
        problem: The planning problem (obstacles with walls, start, goal, robot radius).
        variant: "lower" (inscribed arcs: a lower bound on the optimum) or "feasible"
            (circumscribed arcs, exact edge checks: a valid path, an upper bound).
        arc_step: Largest angle [rad] spanned by one chord of a rounded corner, in (0, pi/2].
        prune_tangent: Keep only bitangent edges (exact). False gives the complete visibility
            graph, a brute-force check meant for convex polygons and a point robot (with
            inflation, edges running exactly along the seams between the pieces of an
            inflated polygon would not be rejected).

    Returns:
        The path and its cost; status INVALID_START/INVALID_GOAL if an endpoint is in
        collision (exact check), INFEASIBLE if the graph has no path.
    """
    if variant not in ("lower", "feasible"):
        raise ValueError(f"variant: expected 'lower' or 'feasible', got {variant!r}")
    if not (0.0 < arc_step <= math.pi / 2):
        raise ValueError(f"arc_step: must be in (0, pi/2], got {arc_step}")
    t0 = time.perf_counter()

    def done(status: PlannerStatus, path: np.ndarray, cost: float, nn: int, ne: int) -> VisGraphResult:
        return VisGraphResult(status, path, cost, variant, nn, ne, time.perf_counter() - t0)

    empty = np.zeros((0, 2))
    if not problem.start_valid():
        return done(PlannerStatus.INVALID_START, empty, math.inf, 0, 0)
    if not problem.goal_valid():
        return done(PlannerStatus.INVALID_GOAL, empty, math.inf, 0, 0)

    b = _build(problem, variant, arc_step)
    comps = _pack(b.comps)
    r = _radius(problem, variant)
    # Lower variant on a map: the inscribed chains of the boxes' inflated corners contain the
    # boxes inflated by the chords' distance, so clearance >= that distance is a relaxation.
    box_limit = (inscribed_radius(r, arc_step) - 1e-9
                 if variant == "lower" and len(problem.obstacles.boxes) and r > 0.0 else 0.0)
    xmin, ymin, xmax, ymax = problem.bounds
    if b.nodes:
        nodes = np.array(b.nodes)
        prv = np.array(b.prev)
        nxt = np.array(b.next)
        # Strictly inside the shrunk box: a vertex on a wall (an obstacle touching the border,
        # point robot) is never a bend point, and keeping it would open a zero-width passage
        # along the wall.
        keep = ((nodes[:, 0] > xmin + r + _EPS) & (nodes[:, 0] < xmax - r - _EPS)
                & (nodes[:, 1] > ymin + r + _EPS) & (nodes[:, 1] < ymax - r - _EPS))
        if variant == "feasible":
            keep &= problem.obstacles.points_free(nodes, problem.check_radius)
        else:
            if box_limit > 0.0:
                keep &= _box_set(problem).clearances(nodes) >= box_limit
            idx = np.flatnonzero(keep)
            keep[idx[points_in_any(np.ascontiguousarray(nodes[idx, 0]),
                                    np.ascontiguousarray(nodes[idx, 1]), comps, _EPS)]] = False
        nodes, prv, nxt = nodes[keep], prv[keep], nxt[keep]
    else:
        nodes = prv = nxt = np.zeros((0, 2))
    pts = np.vstack([problem.start[None, :], problem.goal[None, :], nodes])
    prv = np.ascontiguousarray(np.vstack([np.zeros((2, 2)), prv]))
    nxt = np.ascontiguousarray(np.vstack([np.zeros((2, 2)), nxt]))
    if not prune_tangent:
        prv = nxt = np.ascontiguousarray(np.repeat(pts[:, None, :], 1, axis=1)[:, 0, :])
    exact = variant == "feasible"
    oarr = problem.obstacles.arrays if exact or box_limit <= 0.0 else _box_set(problem).arrays
    px, py = np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1])
    if exact or box_limit > 0.0:
        ei, ej, w = edges(px, py, prv, nxt, 2, exact, problem.check_radius, comps, oarr, box_limit)
    else:
        ei, ej, w = edges_relaxed(px, py, prv, nxt, 2, comps)
    from scipy.sparse import coo_matrix  # lazy: keeps `import anyplan.planning` light
    from scipy.sparse.csgraph import dijkstra

    n = len(pts)
    # The "lower" variant needs no wall test in edges: both ends lie in the shrunk box, which
    # is convex, so the whole segment does too.
    g = coo_matrix((np.concatenate([w, w]), (np.concatenate([ei, ej]), np.concatenate([ej, ei]))),
                   shape=(n, n)).tocsr()
    dist, pred = dijkstra(g, directed=False, indices=0, return_predecessors=True)
    if not np.isfinite(dist[1]):
        return done(PlannerStatus.INFEASIBLE, empty, math.inf, n, len(w))
    chain = [1]
    while chain[-1] != 0:
        chain.append(int(pred[chain[-1]]))
    path = pts[chain[::-1]]
    return done(PlannerStatus.EXACT_SOLUTION, path, float(dist[1]), n, len(w))


def lower_bound(problem: Problem, arc_step: float = DEFAULT_ARC_STEP) -> float:
    """A proven lower bound [m] on the optimal path length (inf if provably infeasible)."""
    res = shortest_path(problem, variant="lower", arc_step=arc_step)
    if res.status in (PlannerStatus.INVALID_START, PlannerStatus.INVALID_GOAL):
        return math.inf
    return res.cost


def reachable_margin(obstacles: ObstacleSet, start: np.ndarray | tuple[float, float],
                     goal: np.ndarray | tuple[float, float], radius: float, most: float,
                     tol: float = 0.005) -> float:
    """The largest extra clearance ``m`` in [0, ``most``] [m] (to within ``tol``) with which a
    disc of ``radius + m`` [m] still has a path from ``start`` to ``goal``: a valid path of the
    ``feasible`` variant of :func:`shortest_path` (so ``m`` never exceeds the narrowest passage
    the way needs, nor the start's and the goal's own clearance). ``most`` when the goal is
    reachable with it, 0 when not even with ``tol``; bisection, at most about
    ``log2(most / tol) + 2`` searches.

    Examples:
        Between two walls 1 m apart, a 0.3 m disc has 0.2 m to spare on each side:

        >>> from anyplan.geometry.shapes import rectangle
        >>> walls = ObstacleSet([rectangle((2.0, -0.5), (4.0, 1.0)), rectangle((2.0, 1.5), (4.0, 1.0))],
        ...                     bounds=(-2.0, -1.0, 6.0, 2.0))
        >>> round(reachable_margin(walls, (-1.0, 0.5), (5.0, 0.5), 0.3, 0.5), 2)
        0.2
    """
    def ok(m: float) -> bool:
        return bool(shortest_path(Problem.create(obstacles, start, goal, radius + m)).status)

    if not most > 0.0 or ok(most):
        return max(float(most), 0.0)
    hi = float(most)
    if not ok(min(tol, hi)):
        return 0.0
    lo = min(tol, hi)
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


def usable_margin(obstacles: ObstacleSet, start: np.ndarray | tuple[float, float],
                  goal: np.ndarray | tuple[float, float], radius: float, wanted: float) -> float:
    """The extra clearance [m] a planner may keep beyond ``radius`` [m] on the way from
    ``start`` to ``goal``: ``wanted`` when the way leaves room for it
    (:func:`reachable_margin`), else that room less :data:`USABLE_SLACK_M`, or half of it when
    it is narrower than twice that. A passage left exactly as wide as the disc planned for is one
    a sampling planner hardly ever finds (its edges must pass it on a line); a centimetre to
    spare on each side lets BIT* through (measured on BARN: ``benchmarks/results/barn.md``)."""
    room = reachable_margin(obstacles, start, goal, radius, wanted)
    return room if room >= wanted else max(room - USABLE_SLACK_M, 0.5 * room)


def warm_up() -> None:
    """Compile (or load) the kernels of the lower variant without a map (the feasibility check
    before every run, the time lower bound) on a made-up square, without a clearance query: a
    second process can compile them on a cold cache while the first compiles the clearance
    kernels (:mod:`anyplan.agents.warmup`)."""
    comps = _pack([np.array([[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]])])
    px, py = np.array([0.0, 3.0, 0.9, 2.1]), np.array([0.0, 3.0, 2.1, 0.9])
    points_in_any(px, py, comps, _EPS)
    tangents = np.ascontiguousarray(np.column_stack([px, py]))
    edges_relaxed(px, py, tangents, tangents, 2, comps)


class VisGraphPlanner(Planner):
    """The visibility-graph planner: exact (to ``arc_step``) and non-iterative.

    ``solve`` computes the feasible shortest path (and the lower bound) once; later calls
    return at once. Options: ``arc_step`` [rad], ``variant`` ("feasible", the default, returns
    a path that passes the exact check; "lower" returns the lower-bound path itself).
    """

    name = "visgraph"

    def __init__(self, problem: Problem, *, arc_step: float = DEFAULT_ARC_STEP,
                 variant: str = "feasible", rng: object = None) -> None:
        super().__init__(problem)
        if variant not in ("lower", "feasible"):
            raise ValueError(f"variant: expected 'lower' or 'feasible', got {variant!r}")
        self.arc_step = float(arc_step)
        self.variant = variant
        self._res: VisGraphResult | None = None
        self._lb: VisGraphResult | None = None
        self._time = 0.0

    @property
    def best_cost(self) -> float:
        """Cost [m] of the path (inf before solve or without a path)."""
        return math.inf if self._res is None else self._res.cost

    def solve(self, ptc: TerminationCondition | float = 0.0) -> PlannerStatus:
        """Compute the path (once); the termination condition is not consulted."""
        if self._res is None:
            t0 = time.perf_counter()
            self._lb = shortest_path(self.problem, variant="lower", arc_step=self.arc_step)
            if self.variant == "lower":
                self._res = self._lb
            elif self._lb.status is PlannerStatus.INFEASIBLE or not self._lb.status:
                self._res = VisGraphResult(self._lb.status, np.zeros((0, 2)), math.inf,
                                           "feasible", 0, 0, 0.0)
            else:
                self._res = shortest_path(self.problem, variant="feasible", arc_step=self.arc_step)
                if self._res.status is PlannerStatus.INFEASIBLE:
                    # A relaxed path exists but no circumscribed one: not a proof of
                    # infeasibility (a passage narrower than the chord error).
                    self._res = VisGraphResult(PlannerStatus.TIMEOUT, self._res.path, math.inf,
                                               "feasible", self._res.n_nodes, self._res.n_edges,
                                               self._res.time_s)
            self._time = time.perf_counter() - t0
        return self._res.status

    def result(self) -> PlanResult:
        """The path, its cost and the lower bound."""
        if self._res is None:
            return PlanResult(PlannerStatus.TIMEOUT, np.zeros((0, 2)), math.inf, 0.0, None, [],
                              None, self.name)
        res = self._res
        lb = None
        if self._lb is not None and self._lb.status:
            lb = self._lb.cost
        ok = bool(res.status)
        return PlanResult(res.status, res.path.copy(), res.cost, self._time,
                          self._time if ok else None, [(self._time, res.cost)] if ok else [],
                          lb, self.name,
                          {"n_nodes": res.n_nodes, "n_edges": res.n_edges, "variant": res.variant,
                           "arc_step": self.arc_step})
