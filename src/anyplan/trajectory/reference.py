"""Reference motions of one robot among static obstacles: brake, hold, continue, drive a path.

:class:`ReferenceBuilder` holds what every motion of a run shares (the robot's limits v, omega,
a, alpha, the static obstacles, the smoothing margin and grid step); :meth:`ReferenceBuilder.
departing` binds it to the state the robot will have when a new motion starts, giving a
:class:`Departure`: the motion model that Sequential BIT* (:mod:`anyplan.planning.sequential`,
its ``MotionModel`` protocol) calls for each path, with the virtual squares of that iteration and
a departure delay. A delayed departure brakes to rest, stops any rotation, holds
(:class:`HoldSegment`) and then drives the path from where the robot stopped.

Notation: v, omega the robot's twist [m/s, rad/s], a_max, alpha_max its accelerations; times are
absolute simulation times [s]. See ``docs/sequential.md`` ("Reference motions").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from anyplan.geometry.collision import ObstacleSet
from anyplan.geometry.shapes import Shape
from anyplan.trajectory.kinds import SegmentKind
from anyplan.trajectory.motion import brake_to_rest, come_to_rest, continue_from, plan_motion
from anyplan.trajectory.trajectory import CurveSegment, Segment, Trajectory, TurnSegment
from anyplan.world.robot import RobotSpec, RobotState

__all__ = ["HoldSegment", "ReferenceBuilder", "Departure", "WAIT_PREFIX"]

#: Prefix of the kind of a motion departing late (``"wait+smooth"``, ...).
WAIT_PREFIX = "wait+"


class HoldSegment(Segment):
    """Standing still at (x, y, theta) from ``t0`` to ``t1`` [s]."""

    kind = SegmentKind.HOLD

    def __init__(self, x: float, y: float, theta: float, t0: float, t1: float) -> None:
        self.x, self.y, self.theta = float(x), float(y), float(theta)
        self.t0, self.t1 = float(t0), float(t1)
        self.max_speed = 0.0
        self.length = 0.0

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, ...]:  # type: ignore[override]
        t = np.asarray(t, dtype=float)
        z = np.zeros(t.shape)
        return np.full(t.shape, self.x), np.full(t.shape, self.y), np.full(t.shape, self.theta), z, z

    def xy(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        shape = np.shape(t)
        return np.full(shape, self.x), np.full(shape, self.y)

    def path_points(self, step: float) -> np.ndarray:
        return np.array([[self.x, self.y]])


class ReferenceBuilder:
    """Timed reference motions within the robot's v, omega, a and alpha, for one run.

    Args:
        spec: The robot (limits and radius).
        obstacles: Static obstacles with the arena walls.
        smooth_margin: Clearance [m] beyond the robot radius the smoothed curve must keep
            (reduced to the robot's own clearance where it is closer).
        grid_step: Grid spacing [m] of the speed profile and of the curve certification.
    """

    def __init__(self, *, spec: RobotSpec, obstacles: ObstacleSet, smooth_margin: float = 0.015,
                 grid_step: float = 0.05) -> None:
        self.spec = spec
        self.obstacles = obstacles
        self.smooth_margin = float(smooth_margin)
        self.grid_step = float(grid_step)

    def departing(self, state: RobotState, t_start: float) -> Departure:
        """The motion model for motions starting from ``state`` at ``t_start`` [s]."""
        clear = self.obstacles.clearance((state.x, state.y)) - self.spec.radius
        return Departure(self, state, float(t_start), min(self.smooth_margin, max(clear, 0.0)))

    def hold(self, state: RobotState, t0: float, duration_s: float, *, kind: str,
             stop_rotation: bool = True) -> tuple[Trajectory, float]:
        """Brake to rest from ``state`` at ``t0`` [s] (and stop rotating, with
        ``stop_rotation``), then hold for ``duration_s`` [s]; also returns the time at rest."""
        spec = self.spec
        if stop_rotation:
            segs, t_rest, rest, _ = come_to_rest(state, spec, self.obstacles, spec.radius, t0)
        else:
            segs, t_rest, rest, _ = brake_to_rest(state, spec, self.obstacles, spec.radius, t0)
        segs.append(HoldSegment(rest.x, rest.y, rest.theta, t_rest, t_rest + duration_s))
        return Trajectory(segs, kind=kind, lower_bound_s=0.0), t_rest


@dataclass(frozen=True)
class Departure:
    """Motions from one start: ``state`` at ``t_start`` [s], smoothed with ``margin`` [m].

    Calling it, ``departure(path, extra_shapes, delay_s)``, gives the timed reference motion along
    ``path`` (N, 2) [m] among the static obstacles plus ``extra_shapes`` (virtual squares),
    departing ``delay_s`` [s] late (brake, hold, then drive the path from where the robot
    stopped; kind ``"wait+..."``).
    """

    builder: ReferenceBuilder
    state: RobotState
    t_start: float
    margin: float
    #: The late departures built so far, by the identity of their path and squares (the entry
    #: keeps them alive): the braking, where it rests, and the drive from there (see __call__).
    _late: dict[tuple[int, ...], tuple[np.ndarray, tuple[Shape, ...], list[Segment], float,
                                       RobotState, Trajectory]] = field(
        default_factory=dict, compare=False, repr=False)

    def __call__(self, path: np.ndarray, extra_shapes: Sequence[Shape], delay_s: float) -> Trajectory:
        b, spec, state = self.builder, self.builder.spec, self.state
        if delay_s <= 0.0:
            obst = b.obstacles.with_shapes(extra_shapes) if extra_shapes else b.obstacles
            return plan_motion(path, spec, state, obst, self.t_start, margin=self.margin,
                               grid_step=b.grid_step)
        # The braking, the place of rest and the drive from rest along the path do not depend on
        # the delay: the drive is planned for the first delay asked, and for later ones its
        # segments start later, each built as plan_motion builds it (t0 = the previous t1).
        key = (id(path), *(id(x) for x in extra_shapes))
        hit = self._late.get(key)
        drive = None
        if hit is not None and hit[0] is path and len(hit[1]) == len(extra_shapes) and all(
                x is y for x, y in zip(hit[1], extra_shapes, strict=True)):
            _, _, stop, t, rest, tail = hit
            drive = _started_at(tail.segments, t + delay_s)
        if drive is None:
            obst = b.obstacles.with_shapes(extra_shapes) if extra_shapes else b.obstacles
            stop, t, rest, _ = come_to_rest(state, spec, obst, spec.radius + self.margin,
                                            self.t_start)
            p = continue_from(np.array([rest.x, rest.y]), np.asarray(path, dtype=float), obst,
                              spec.radius + self.margin)
            tail = plan_motion(p, spec, rest, obst, t + delay_s, margin=self.margin,
                               grid_step=b.grid_step)
            self._late[key] = (path, tuple(extra_shapes), stop, t, rest, tail)
            drive = tail.segments
        hold = HoldSegment(rest.x, rest.y, rest.theta, t, t + delay_s)
        return Trajectory([*stop, hold, *drive], kind=WAIT_PREFIX + tail.kind,
                          feasible=tail.feasible, lower_bound_s=tail.lower_bound_s,
                          polyline=tail.polyline, info=tail.info,
                          certified_free=tail.certified_free, departs_s=t + delay_s)


def _started_at(segments: Sequence[Segment], t0: float) -> list[Segment] | None:
    """``segments`` (turns and curves, contiguous) moved to start at ``t0`` [s], each built as
    :func:`~anyplan.trajectory.plan_motion` builds it there (its start the previous one's end,
    its end its start plus its duration); None if one is of another kind."""
    out: list[Segment] = []
    for s in segments:
        if type(s) is CurveSegment:
            c = CurveSegment(s.curve, s.profile, t0)
            c.max_speed = s.max_speed  # the curve's and the profile's, whenever it starts
            out.append(c)
        elif type(s) is TurnSegment:
            out.append(TurnSegment(s.x, s.y, s.rotation, t0))
        else:
            return None
        t0 = out[-1].t1
    return out
