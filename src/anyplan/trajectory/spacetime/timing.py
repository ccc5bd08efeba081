"""Re-timing a reference motion along its own path among the predicted moving obstacles.

:func:`retime` takes a :class:`~anyplan.trajectory.Trajectory` built by
:func:`~anyplan.trajectory.plan_motion` (optionally a brake and a turn in place, then one smooth
curve with its time-optimal speed profile), keeps its geometry and gives the curve a new timing:
the earliest acceleration-bounded motion along it that avoids the s-t obstacle regions of the
predicted discs (:mod:`~anyplan.trajectory.spacetime.lattice`), within the speed limit curve of
the path (:func:`speed_caps`). The robot may slow down, wait (v = 0) and go on, so it can let an
obstacle pass and drive behind it.

:func:`verify` is the certified continuous check of a timed motion against predictions whose
radius may grow with time; the planner uses it on every motion before it is executed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numba import njit

from anyplan.prediction.base import PredictedObstacle
from anyplan.prediction.collision import PredictedCollision, first_collision
from anyplan.trajectory.kinds import ST_PREFIX, SegmentKind
from anyplan.trajectory.profile import SpeedProfile
from anyplan.trajectory.spacetime.lattice import VelocityPlan, plan_velocity
from anyplan.trajectory.spacetime.stmap import RowCache, STMap, build_stmap, radii_at
from anyplan.trajectory.spline import SmoothCurve
from anyplan.trajectory.trajectory import CurveSegment, Segment, Trajectory
from anyplan.world.robot import RobotSpec

__all__ = ["TimedCurveSegment", "speed_caps", "retime", "verify", "RetimeResult", "map_ds",
           "MAX_MAP_CELLS"]

#: Largest s-t map of a re-timing, in cells (rows x columns, counting the rows after every
#: prediction's end, which are not stored: the stored rows take nine bytes a cell with their
#: goal-time bounds). The built-in, generated and benchmark scenarios need below 10^7 (the
#: paper's robot on a 30 m path: 1.3 x 10^6); a 1 km path asked for 10^9 (13 GB when every row
#: was stored) (:func:`map_ds`).
MAX_MAP_CELLS = 2 ** 25


class TimedCurveSegment(Segment):
    """Driving along ``curve`` with a :class:`VelocityPlan` (absolute times), waits included."""

    kind = SegmentKind.ST_CURVE

    def __init__(self, curve: SmoothCurve, plan: VelocityPlan) -> None:
        self.curve, self.plan = curve, plan
        self.t0, self.t1 = float(plan.t[0]), float(plan.t[-1])
        self.length = float(plan.s[-1] - plan.s[0])
        # The curve is unit speed to ~1e-4 in its arc-length parameter: 1 % covers it.
        self.max_speed = float(np.max(plan.v)) * 1.01

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, ...]:  # type: ignore[override]
        t = np.asarray(t, dtype=float)
        flat = t.ravel()
        s, v, _ = self.plan.at_time(flat)
        u = self.curve.u_of_s(np.clip(s, 0.0, self.curve.length))
        p = self.curve.position(u)
        th = self.curve.heading(u)
        k, _ = self.curve.curvature(u)
        out = (p[:, 0], p[:, 1], th, v, k * v)
        return tuple(np.asarray(o, dtype=float).reshape(t.shape) for o in out)

    def xy(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        s, _, _ = self.plan.at_time(np.asarray(t, dtype=float).ravel())
        p = self.curve.position(self.curve.u_of_s(np.clip(s, 0.0, self.curve.length)))
        return np.asarray(p[:, 0], dtype=float), np.asarray(p[:, 1], dtype=float)

    def path_points(self, step: float) -> np.ndarray:
        return self.curve.samples(step)


def speed_caps(profile: SpeedProfile, spec: RobotSpec, ds: float, ncell: int
               ) -> tuple[np.ndarray, np.ndarray]:
    """Caps on v^2 [m^2/s^2] per path cell [c ds, (c+1) ds], cruising and at |a| = a_max.

    From the curvature bounds of the profile's intervals (|kappa| <= K, |kappa'| <= K'):
    v <= v_max, v K <= omega_max and K' v^2 + K |a| <= alpha_max (the bounds of
    :func:`~anyplan.trajectory.time_parameterize`), each with the worst interval the cell overlaps.
    A cap of -1 forbids accelerating or braking in the cell.
    """
    kk, dk = _cell_max(profile.s, profile.kappa_max, profile.dkappa_max, ds, ncell)
    with np.errstate(divide="ignore"):
        x0 = np.minimum(spec.v_max ** 2, np.where(kk > 0, (spec.omega_max / kk) ** 2, np.inf))
        x0 = np.minimum(x0, np.where(dk > 0, spec.alpha_max / dk, np.inf))
        room = spec.alpha_max - kk * spec.a_max
        x1 = np.where(room < 0.0, -1.0, np.minimum(x0, np.where(dk > 0, room / dk, np.inf)))
    return np.ascontiguousarray(x0), np.ascontiguousarray(x1)


@njit(cache=True)
def _cell_max(s: np.ndarray, kmax: np.ndarray, dkmax: np.ndarray, ds: float, ncell: int
              ) -> tuple[np.ndarray, np.ndarray]:
    """Largest interval bound on |kappa| and |kappa'| over the intervals each cell overlaps."""
    kk = np.zeros(ncell)
    dk = np.zeros(ncell)
    for i in range(len(kmax)):
        lo = min(max(int(s[i] / ds), 0), ncell - 1)
        hi = min(max(int(s[i + 1] / ds), 0), ncell - 1)
        for c in range(lo, hi + 1):
            kk[c] = max(kk[c], kmax[i])
            dk[c] = max(dk[c], dkmax[i])
    return kk, dk


def map_ds(ds: float, length: float, horizon_s: float, h: float) -> float:
    """The s-t map's cell width [m]: ``ds``, or wider when a map of ``horizon_s`` / ``h`` rows
    [s] by ``length`` / ``ds`` columns [m] would exceed :data:`MAX_MAP_CELLS` (a path of
    hundreds of metres, or a robot so slow that its motion lasts hours). A wider cell is
    conservative (a disc is marked on every cell it comes within half a cell of)."""
    nrow = int(math.ceil(horizon_s / h)) + 1
    if nrow * math.ceil(length / ds) <= MAX_MAP_CELLS:
        return ds
    return max(ds, length / max(1, MAX_MAP_CELLS // nrow))


class RetimeResult:
    """A re-timed motion and what was learnt on the way.

    Attributes:
        trajectory: The new :class:`Trajectory` (None if no timing avoids the obstacles).
        plan: Its :class:`VelocityPlan` along the curve (None likewise).
        stmap: The s-t map used.
        nominal_arrival_s: End time [s] of the input trajectory.
    """

    def __init__(self, trajectory: Trajectory | None, plan: VelocityPlan | None, stmap: STMap | None,
                 nominal_arrival_s: float) -> None:
        self.trajectory, self.plan, self.stmap = trajectory, plan, stmap
        self.nominal_arrival_s = nominal_arrival_s

    @property
    def delay_s(self) -> float:
        """Arrival delay [s] against the input timing (inf when none was found)."""
        if self.trajectory is None:
            return math.inf
        return self.trajectory.t_end - self.nominal_arrival_s


def retime(traj: Trajectory, obstacles: Sequence[Any], spec: RobotSpec, *, margin: float = 0.05,
           max_wait_s: float = 30.0, ds: float = 0.05, h: float = 0.05, target_dt: float = 0.25,
           free_tail_m: float = 0.0, rows: RowCache | None = None) -> RetimeResult:
    """The earliest timing of ``traj``'s curve that avoids the predicted ``obstacles``.

    Args:
        traj: A motion of :func:`plan_motion` (prefix segments, then one :class:`CurveSegment`).
        obstacles: Predicted moving discs (constant or growing radius, see ``stmap``).
        spec: Robot limits and radius.
        margin: Extra clearance [m] kept from the obstacles.
        max_wait_s: Latest arrival considered, beyond the input's own arrival [s].
        ds: Cell width [m] of the s-t map.
        h: Row duration [s] of the s-t map.
        target_dt: Approximate step [s] of the velocity lattice.
        free_tail_m: Path metres before the end never blocked (inside the goal tolerance).
        rows: Obstacle rows shared by the re-timings of one replanning (a :class:`RowCache`,
            whose ``h`` replaces ``h``): the map starts on its time grid.

    Returns:
        A :class:`RetimeResult`; its trajectory keeps the prefix segments unchanged.
    """
    segs = traj.segments
    nominal = traj.t_end
    curves = [i for i, s in enumerate(segs) if isinstance(s, CurveSegment)]
    if len(curves) != 1 or curves[0] != len(segs) - 1:
        return RetimeResult(None, None, None, nominal)
    seg: CurveSegment = segs[-1]  # type: ignore[assignment]
    curve = seg.curve
    length = curve.length
    horizon = seg.t1 - seg.t0 + max_wait_s

    def points_at(s: np.ndarray) -> np.ndarray:
        return curve.position(curve.u_of_s(s))

    ds = map_ds(ds, length, horizon, rows.h if rows is not None else h)
    stmap = build_stmap(points_at, length, obstacles, spec.radius, seg.t0, horizon, margin=margin,
                        ds=ds, h=h, free_tail_m=free_tail_m, rows=rows)
    x0, x1 = speed_caps(seg.profile, spec, ds, stmap.forbidden.shape[1])
    v0 = float(seg.profile.v[0])
    plan = plan_velocity(stmap.forbidden, stmap.t_map, stmap.h, ds, x0, x1, length, seg.t0, v0,
                         spec.a_max, spec.v_max, target_dt=target_dt, horizon_s=horizon,
                         rows=stmap.rows)
    if plan is None:
        return RetimeResult(None, None, stmap, nominal)
    new = Trajectory(list(segs[:-1]) + [TimedCurveSegment(curve, plan)], kind=ST_PREFIX + traj.kind,
                     feasible=traj.feasible, lower_bound_s=traj.lower_bound_s,
                     polyline=traj.polyline, certified_free=traj.certified_free,
                     info=dict(traj.info, wait_s=plan.wait_s, nominal_end_s=nominal))
    return RetimeResult(new, plan, stmap, nominal)


def _first_contact_growing(motion: Any, o: Any, reach0: float, t0: float, t1: float,
                           step: float = 0.02, tol: float = 1e-4) -> float | None:
    """First time in [t0, t1] with |p(t) - o(t)| <= reach0 + r_o(t), or None (certified).

    On an interval [a, b] the distance is at least (d_a + d_b - L (b - a)) / 2 with L the bound
    on the relative speed, and the radius at most max(r_a, r_b) (a monotone radius on the
    interval). Intervals not certified clear are bisected, earliest first, down to ``tol``; one
    still uncertain is reported as a contact at its start (conservative).
    """
    vr = float(motion.max_speed) + float(o.max_speed)

    def gap(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = np.hypot(*(motion.positions(t) - o.positions(t)).T)
        return d, radii_at(o, t)

    n = max(2, int(math.ceil((t1 - t0) / step)) + 1)
    t = np.linspace(t0, t1, n)
    d, r = gap(t)
    if d[0] <= reach0 + r[0]:
        return float(t0)
    lb = 0.5 * (d[:-1] + d[1:] - vr * np.diff(t))
    bad = np.flatnonzero(lb <= reach0 + np.maximum(r[:-1], r[1:]))
    for i in bad:
        stack = [(float(t[i]), float(t[i + 1]), float(d[i]), float(d[i + 1]), float(r[i]),
                  float(r[i + 1]))]
        while stack:
            a, b, da, db, ra, rb = stack.pop()
            # contact at b at the latest: search [a, b] finer unless already fine
            if db <= reach0 + rb and b - a <= tol:
                return a
            if 0.5 * (da + db - vr * (b - a)) > reach0 + max(ra, rb):
                continue
            if b - a <= tol:
                return a
            m = 0.5 * (a + b)
            dm, rm = gap(np.array([m]))
            if dm[0] <= reach0 + rm[0]:
                # a contact at m: the first one is in [a, m]
                stack = [(a, m, da, float(dm[0]), ra, float(rm[0]))]
                continue
            stack.append((m, b, float(dm[0]), db, float(rm[0]), rb))
            stack.append((a, m, da, float(dm[0]), ra, float(rm[0])))
    return None


def verify(motion: Any, obstacles: Sequence[Any], robot_radius: float, *, margin: float = 0.0,
           t_from: float | None = None, t_until: float | None = None,
           sample_dt: float | None = 0.02) -> PredictedCollision | None:
    """The first predicted contact of ``motion`` with ``obstacles``, or None (certified).

    Obstacles of constant radius, and every :class:`~anyplan.prediction.PredictedObstacle`
    (whose ``growth`` it honours exactly), go to :func:`anyplan.prediction.collision.first_collision`;
    those with a ``radius_at(t)`` (radius growing or shrinking monotonically between samples
    ``0.02`` s apart) to a certified bisection search on the distance minus the radius.
    """
    t0 = motion.t_start if t_from is None else float(t_from)
    t1 = motion.t_end if t_until is None else float(t_until)
    # PredictedObstacle (growing or not) is certified exactly by first_collision itself.
    const = [o for o in obstacles
             if isinstance(o, PredictedObstacle) or not callable(getattr(o, "radius_at", None))]
    grow = [o for o in obstacles
            if not isinstance(o, PredictedObstacle) and callable(getattr(o, "radius_at", None))]
    hits: list[PredictedCollision] = []
    if const:
        hit = first_collision(motion, const, robot_radius, t_from=t0, t_until=t1, margin=margin,
                              sample_dt=sample_dt)
        if hit is not None:
            hits.append(hit)
    for o in grow:
        tc = _first_contact_growing(motion, o, robot_radius + margin, t0, t1)
        if tc is not None:
            ta = np.array([tc])
            hits.append(PredictedCollision(str(o.name), float(tc), motion.positions(ta)[0],
                                           o.positions(ta)[0], float(radii_at(o, ta)[0])))
    return min(hits, key=lambda c: c.t) if hits else None
