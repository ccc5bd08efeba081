"""From a planned polyline to a timed reference motion: :func:`plan_motion`.

The chain of the paper (Roy, Harchowdhury & Vachhani, §4): smooth the path with a cubic spline,
repair it where it cuts an obstacle, generate the reference motion within the robot's limits,
and turn in place first when that is faster. Candidates (:class:`~anyplan.trajectory.kinds.
MotionKind`): ``smooth`` (a spline from the robot's heading, speed and curvature omega0 / v0),
``turn+smooth`` / ``brake+turn+smooth`` (brake to rest if moving, turn in place toward the path,
then a spline tangent to it) and ``polyline`` (when no spline can be certified: brake, then turn
and drive straight, rest to rest, along each segment). The fastest candidate that is certified
collision-free (:mod:`anyplan.trajectory.spline`) and feasible from the current state wins.
Notation: v0, omega0 the robot's twist; times are absolute [s].
See ``docs/motion.md`` ("``plan_motion`` and ``Trajectory``").
"""

from __future__ import annotations

import math

import numpy as np

from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.geometry.se2 import wrap_angle
from anyplan.trajectory.brake import SwerveSegment
from anyplan.trajectory.kinds import MotionKind
from anyplan.trajectory.path import clean_path, polyline_length, shortcut_path
from anyplan.trajectory.profile import time_lower_bound, time_parameterize
from anyplan.trajectory.spline import SmoothCurve, smooth_path
from anyplan.trajectory.trajectory import (
    BrakeSegment,
    CurveSegment,
    Segment,
    Trajectory,
    TurnSegment,
)
from anyplan.trajectory.turn import rotation_profile
from anyplan.world.robot import RobotSpec, RobotState

__all__ = ["plan_motion", "turn_segment", "polyline_trajectory", "brake_to_rest", "come_to_rest",
           "continue_from", "swerve_trajectory"]

_EPS_V = 1e-6  # [m/s] speeds below this count as rest
_EPS_TH = 1e-3  # [rad] headings closer than this count as aligned
_V_CURVATURE = 0.02  # [m/s] above this speed the start curvature omega0 / v0 is matched
_MAX_START_CURVATURE = 5.0  # [1/m] tighter start curvatures are not matched
#: [s] B (turn in place, then a curve) is not built when its lower bound exceeds A's arrival by
#: more than this: far above the rounding of a profile's time (~1e-12 s), far below a control step.
_PRUNE_SLACK_S = 1e-6


def turn_segment(x: float, y: float, theta: float, target: float, spec: RobotSpec, t0: float,
                 omega0: float = 0.0) -> TurnSegment:
    """The faster of the two in-place rotations from ``theta`` to ``target`` [rad]."""
    d = float(wrap_angle(target - theta))
    options = [d, d - 2.0 * math.pi if d > 0.0 else d + 2.0 * math.pi]
    rots = [rotation_profile(theta, o, spec.omega_max, spec.alpha_max, omega0) for o in options]
    best = min(rots, key=lambda r: r.duration)
    return TurnSegment(x, y, best, t0)


def _table_free(seg: BrakeSegment | SwerveSegment, obstacles: ObstacleSet, radius: float) -> bool:
    """Whether a tabulated segment (braking, swerving) is certified free for ``radius``: its
    reference is the table, whose consecutive samples are at most its speed x 2 ms apart (the
    true arc leaves each chord by far less than 1 um), tested segment by segment, exactly."""
    pts = seg.path_points(0.0)
    return bool(np.all(obstacles.segments_clearance(pts[:-1], pts[1:]) >= radius + 1e-6 - COLLISION_EPS))


#: Recent braking segments, newest last: (key, segment, {(obstacles' fingerprint, radius):
#: free}). A fallback ranking brakes from one state for each of its candidates (the guard's,
#: 8 evasions); the key is every input, so a hit is the same segment (segments are not changed
#: once built, and trajectories share them).
_BRAKES: list[tuple[bytes, BrakeSegment, dict[tuple[bytes, float], bool]]] = []
_BRAKES_SIZE = 8


def _brake(state: RobotState, spec: RobotSpec, obstacles: ObstacleSet, radius: float,
           t0: float) -> tuple[BrakeSegment | None, bool]:
    """The braking segment (None at rest) and whether it is certified free."""
    if abs(state.v) <= _EPS_V:
        return None, True
    # the inputs' bits (0.0 and -0.0 are equal floats, not the same input)
    key = np.array([state.x, state.y, state.theta, state.v, state.omega, spec.a_max, spec.alpha_max,
                    t0], dtype=float).tobytes()
    entry = next((e for e in _BRAKES if e[0] == key), None)
    if entry is None:
        entry = (key, BrakeSegment(state.x, state.y, state.theta, state.v, state.omega, spec.a_max,
                                   spec.alpha_max, t0), {})
        _BRAKES.append(entry)
        del _BRAKES[:-_BRAKES_SIZE]
    _, seg, free = entry
    fkey = (obstacles.fingerprint, float(radius))
    if fkey not in free:
        free[fkey] = _table_free(seg, obstacles, radius)
    return seg, free[fkey]


def brake_to_rest(state: RobotState, spec: RobotSpec, obstacles: ObstacleSet, radius: float,
                  t0: float) -> tuple[list[Segment], float, RobotState, bool]:
    """Brake to rest from ``state`` at ``t0`` [s] (nothing to do at rest).

    Returns:
        The segments (the braking segment, or none), the time [s] the robot is at rest, its
        state at rest, and whether the braking path is certified free for ``radius``.
    """
    brake, free = _brake(state, spec, obstacles, radius, t0)
    if brake is None:
        return [], t0, RobotState(state.x, state.y, state.theta, 0.0, state.omega), free
    bx, by, bth, _, _ = brake.sample(np.array([brake.t1]))
    return [brake], brake.t1, RobotState(float(bx[0]), float(by[0]), float(bth[0]), 0.0, 0.0), free


def come_to_rest(state: RobotState, spec: RobotSpec, obstacles: ObstacleSet, radius: float,
                 t0: float) -> tuple[list[Segment], float, RobotState, bool]:
    """Brake to rest at a_max from ``state`` at ``t0`` [s], then stop any rotation in place at
    alpha_max.

    Returns:
        The segments, the time [s] the robot is at rest (v = omega = 0), its state then, and
        whether the braking path is certified free for ``radius`` [m].
    """
    segs, t, rest, free = brake_to_rest(state, spec, obstacles, radius, t0)
    if abs(rest.omega) > 1e-9:  # turning in place: stop the rotation at alpha_max too
        stop = BrakeSegment(rest.x, rest.y, rest.theta, 0.0, rest.omega, spec.a_max,
                            spec.alpha_max, t)
        segs.append(stop)
        t = stop.t1
        x, y, th, _, _ = stop.sample(np.array([t]))
        return segs, t, RobotState(float(x[0]), float(y[0]), float(th[0]), 0.0, 0.0), free
    return segs, t, RobotState(rest.x, rest.y, rest.theta, 0.0, 0.0), free


def swerve_trajectory(state: RobotState, spec: RobotSpec, obstacles: ObstacleSet, radius: float,
                      t0: float, v1: float, omega1: float, duration: float) -> Trajectory:
    """Swerve from ``state`` at ``t0`` [s]: ramp to the twist (``v1`` [m/s], ``omega1``
    [rad/s]) within a_max and alpha_max and hold it until ``t0 + duration``, then brake to
    rest (:class:`~anyplan.trajectory.brake.SwerveSegment`, then braking). An escape that
    moves at once: evasions along straight lines first stop the robot's turn and face their
    direction, which a differential-drive robot needs about a second for. ``certified_free``
    tells whether the whole path is free for ``radius`` among ``obstacles`` (exact segment
    tests along the 2 ms table, whose arcs leave their chords by far less than 1 um)."""
    v1 = float(np.clip(v1, -spec.v_max, spec.v_max))
    omega1 = float(np.clip(omega1, -spec.omega_max, spec.omega_max))
    sw = SwerveSegment(state.x, state.y, state.theta, state.v, state.omega, v1, omega1,
                       spec.a_max, spec.alpha_max, t0, duration)
    free = _table_free(sw, obstacles, radius)
    end = sw.sample(np.array([sw.t1]))
    tail, _, _, brake_free = come_to_rest(RobotState(*(float(a[0]) for a in end)), spec,
                                          obstacles, radius, sw.t1)
    segs: list[Segment] = [sw, *tail]
    length = float(sum(s.length for s in segs))
    return Trajectory(segs, kind=MotionKind.SWERVE,
                      lower_bound_s=time_lower_bound(length, spec, abs(state.v)),
                      certified_free=free and brake_free)


def continue_from(p_stop: np.ndarray, pts: np.ndarray, obstacles: ObstacleSet,
                  radius: float) -> np.ndarray:
    """The path from ``p_stop`` (where the robot will be at rest): skip pts[0] if possible."""
    if len(pts) >= 2 and obstacles.segment_free(p_stop, pts[1], radius) and \
            math.hypot(*(pts[1] - p_stop)) > 1e-6:
        return np.vstack([p_stop, pts[1:]])
    if math.hypot(*(pts[0] - p_stop)) > 1e-6:
        return np.vstack([p_stop, pts])
    return pts


def polyline_trajectory(path: np.ndarray, spec: RobotSpec, state: RobotState, t_start: float,
                        obstacles: ObstacleSet | None = None, radius: float | None = None,
                        grid_step: float = 0.02) -> Trajectory:
    """Brake if moving, then turn in place and drive straight, rest to rest, along each segment.

    The path continues from where the robot stops (see ``continue_from``). The result's
    ``certified_free`` tells whether the braking path and every segment are free for ``radius``
    (default: the robot radius) among ``obstacles``.
    """
    r = spec.radius if radius is None else radius
    obst = obstacles if obstacles is not None else ObstacleSet()
    segs, t, rest, free = brake_to_rest(state, spec, obst, r, t_start)
    x, y, th, w = rest.x, rest.y, rest.theta, rest.omega
    pts = clean_path(path)
    pts = continue_from(np.array([x, y]), pts, obst, r) if len(pts) >= 2 else np.array([[x, y]])
    free = free and obst.path_free(pts, r)
    length = 0.0
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        target = math.atan2(b[1] - a[1], b[0] - a[0])
        if abs(float(wrap_angle(target - th))) > 1e-9 or abs(w) > 0.0:
            seg = turn_segment(a[0], a[1], th, target, spec, t, w)
            if seg.t1 > seg.t0:
                segs.append(seg)
                t = seg.t1
        th, w = target, 0.0
        curve = SmoothCurve(np.array([a, b]), grid_step=grid_step)
        prof = time_parameterize(curve, spec, 0.0)
        cs = CurveSegment(curve, prof, t)
        segs.append(cs)
        length += curve.length
        t = cs.t1
    if not segs:
        segs.append(TurnSegment(x, y, rotation_profile(th, 0.0, spec.omega_max, spec.alpha_max, 0.0), t))
    return Trajectory(segs, kind=MotionKind.POLYLINE,
                      lower_bound_s=time_lower_bound(length, spec, abs(state.v)),
                      polyline=pts, certified_free=free)


def plan_motion(path: np.ndarray, spec: RobotSpec, state: RobotState, obstacles: ObstacleSet,
                t_start: float, *, margin: float = 0.0, grid_step: float = 0.02,
                max_repair_rounds: int = 10, allow_turn: bool = True, shortcut: bool = True,
                shortcut_slack: float = 0.01, start_speed_tolerance: float = 0.01,
                start_omega_tolerance: float = 0.05) -> Trajectory:
    """Turn a planned polyline into a timed, collision-free reference motion.

    Args:
        path: Planned points (N, 2) [m] from (near) the robot's position to the goal. A first
            point within 5 cm of the robot is moved onto it; otherwise the robot's position is
            prepended.
        spec: Robot limits and radius.
        state: Current robot state (pose and twist).
        obstacles: Obstacles the curve must avoid (static and any virtual ones).
        t_start: Absolute time [s] at which the motion starts.
        margin: Extra clearance [m] required of the smoothed curve beyond ``spec.radius``
            (reduced to the robot's current clearance when it is already closer).
        grid_step: Grid spacing [m] of the speed profile and the collision certification.
        max_repair_rounds: Spline repair rounds before the polyline fallback.
        allow_turn: Consider turning in place (disable to force the smooth start).
        shortcut: First drop the path's vertices that a straight segment can skip
            (:func:`~anyplan.trajectory.spline.shortcut_path`); the new segments keep a clearance
            of ``spec.radius + margin + shortcut_slack``. ``obstacles`` must then contain every
            obstacle the path avoids (virtual ones included).
        shortcut_slack: Extra clearance [m] of shortcut segments, left for the spline to round
            the corners in.
        start_speed_tolerance: The smooth start is accepted when its reference starts at most
            this much [m/s] below the robot's speed (the curvature bounds are inflated by 2 %, so
            a robot turning at exactly omega_max would otherwise never qualify); keep it below
            a_max times the control period so the robot matches the reference within one step.
        start_omega_tolerance: Likewise for the turn rate [rad/s] (keep it below alpha_max
            times the control period).

    Returns:
        The fastest admissible :class:`Trajectory`; ``info`` lists the candidate durations
        (``pruned``: the lower bounds of those not built because they could not win).
        If nothing is both feasible from the current state and certified collision-free (a path
        that itself collides, or a robot too fast for the start of every curve), the best effort
        is returned with ``feasible`` or ``certified_free`` False.
    """
    # A robot already closer than the margin to an obstacle can only be held to its clearance.
    margin = min(margin, max(obstacles.clearance((state.x, state.y)) - spec.radius, 0.0))
    radius = spec.radius + margin
    pts = clean_path(path)
    n_input = len(pts)
    if shortcut:
        pts = shortcut_path(pts, obstacles, radius + shortcut_slack)
    p0 = np.array([state.x, state.y])
    d0 = math.hypot(*(pts[0] - p0))
    if d0 <= 0.05:
        pts = pts.copy()
        pts[0] = p0
        if len(pts) >= 2 and math.hypot(*(pts[1] - p0)) <= 1e-9:
            pts = pts[1:]
    else:
        pts = np.vstack([p0, pts])
    if len(pts) < 2:
        # Nothing to drive: come to rest where the robot is (a turn in place stops where the
        # spin ends, as come_to_rest stops it; it does not turn back to the heading it had).
        segs, _, _, _ = come_to_rest(state, spec, obstacles, radius, t_start)
        if not segs:  # at rest: a turn by nothing holds the pose
            segs = [TurnSegment(state.x, state.y, rotation_profile(
                state.theta, 0.0, spec.omega_max, spec.alpha_max, 0.0), t_start)]
        return Trajectory(segs, kind=MotionKind.HOLD, lower_bound_s=0.0, polyline=pts)
    v0 = max(state.v, 0.0)
    cands: list[tuple[bool, float, Trajectory]] = []
    info: dict = {"candidates": {}, "input_vertices": n_input, "vertices": len(pts)}

    # A. smooth start along the current heading, at the current speed.
    # A robot already turning (omega0 = kappa0 v0) takes up a curve with the same curvature, so
    # that the reference turn rate does not jump at the start.
    k0 = state.omega / v0 if v0 > _V_CURVATURE else math.inf
    res = smooth_path(pts, obstacles, radius, start_heading=state.theta, max_rounds=max_repair_rounds,
                      grid_step=grid_step, tight_margin=False,
                      start_curvature=k0 if abs(k0) <= _MAX_START_CURVATURE else None)
    if res.curve is not None:
        prof = time_parameterize(res.curve, spec, v0)
        # A start speed a little above what the (conservatively bounded) curve admits is
        # absorbed within one control step: accept it up to start_speed_tolerance.
        ok_a = prof.feasible or v0 - float(prof.v[0]) <= start_speed_tolerance
        # The reference turn rate must also start at the robot's (e.g. not while it spins in
        # place at v = 0): otherwise the turn-in-place candidate, which starts from omega0, is
        # the consistent one.
        k_start, _ = res.curve.curvature(np.array([0.0]))
        ok_a = ok_a and abs(float(k_start[0]) * float(prof.v[0]) - state.omega) <= start_omega_tolerance
        seg_a = CurveSegment(res.curve, prof, t_start)
        tr = Trajectory([seg_a], kind=MotionKind.SMOOTH, feasible=ok_a,
                        lower_bound_s=time_lower_bound(res.curve.length, spec, v0), polyline=pts,
                        info={"repair_rounds": res.rounds, "points_added": res.points_added,
                              "certified_margin_m": res.margin})  # a lower bound, <= 5 cm
        cands.append((ok_a, tr.duration, tr))
        info["candidates"]["smooth"] = tr.duration if ok_a else math.inf

    # B. brake (if moving), turn in place toward the path, then a spline tangent to it.
    first_dir = math.atan2(pts[1][1] - pts[0][1], pts[1][0] - pts[0][0])
    misaligned = abs(float(wrap_angle(first_dir - state.theta))) > _EPS_TH
    turning = abs(state.omega) > 1e-3
    if allow_turn and (misaligned or turning or res.curve is None or not cands[-1][0]):
        segs, t, rest, brake_free = brake_to_rest(state, spec, obstacles, radius, t_start)
        braked = bool(segs)
        x, y, th, w = rest.x, rest.y, rest.theta, rest.omega
        pts_b = continue_from(np.array([x, y]), pts, obstacles, radius)
        target = math.atan2(pts_b[1][1] - pts_b[0][1], pts_b[1][0] - pts_b[0][0])
        turn = turn_segment(x, y, th, target, spec, t, w)
        if turn.t1 > turn.t0:
            segs.append(turn)
            t = turn.t1
        # B's curve passes through the cleaned points of pts_b in order (the spline interpolates
        # them, and a repair inserts points on the polyline's segments), so it is at least as
        # long as their polyline (less 1e-6 of it, far beyond the arc length's quadrature
        # error); no motion from rest along it is faster than a straight line of that length
        # under v_max and a_max (the profile keeps both everywhere), so B cannot arrive before
        # t + time_lower_bound(that length). When that is later than a certified, feasible A (by
        # more than the profile's rounding, _PRUNE_SLACK_S), B would lose the choice below (the
        # earlier motion, A on a tie): it is not smoothed. (The ends' distance, the bound until
        # 2026-12-03, pruned none of 48 such choices in the office, the polyline 20.)
        bound = t + time_lower_bound(polyline_length(clean_path(pts_b)) * (1.0 - 1e-6), spec, 0.0)
        a_wins = bool(cands) and cands[0][0] and cands[0][2].certified_free and \
            bound > cands[0][2].t_end + _PRUNE_SLACK_S
        if a_wins:
            info["pruned"] = {"turn+smooth": bound - t_start}
        res_b = None if a_wins else smooth_path(pts_b, obstacles, radius, start_heading=target,
                                                max_rounds=max_repair_rounds, grid_step=grid_step,
                                                tight_margin=False)
        if res_b is not None and res_b.curve is not None and brake_free:
            prof = time_parameterize(res_b.curve, spec, 0.0)
            segs.append(CurveSegment(res_b.curve, prof, t))
            tr = Trajectory(segs, kind=(MotionKind.BRAKE_TURN_SMOOTH if braked
                                      else MotionKind.TURN_SMOOTH),
                            feasible=True,
                            lower_bound_s=time_lower_bound(res_b.curve.length, spec, 0.0),
                            polyline=pts_b,
                            info={"repair_rounds": res_b.rounds, "points_added": res_b.points_added,
                                  "certified_margin_m": res_b.margin})
            cands.append((True, tr.duration, tr))
            info["candidates"]["turn+smooth"] = tr.duration

    if not any(ok for ok, _, _ in cands):
        tr = polyline_trajectory(pts, spec, state, t_start, obstacles, radius, grid_step)
        cands.append((True, tr.duration, tr))
        info["candidates"]["polyline"] = tr.duration

    good = [c for c in cands if c[0] and c[2].certified_free]
    pool = good or [c for c in cands if c[2].certified_free] or cands
    best = min(pool, key=lambda c: c[1])[2]
    best.info.update(info)
    return best
