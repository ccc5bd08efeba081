"""Loading the compiled kernels before anything is timed.

anyplan's hot loops are numba functions compiled on first use and cached on disk
(``cache=True``): the first process on a machine compiles them, later ones load the cached
code. Agents call :func:`warm_up_kernels` in ``reset`` with the parts they use (:data:`PARTS`,
each described by its function below), so that neither cost lands inside a timed planning call:
loading a planner's code is a start-up cost, not part of a replanning. ``on_compile`` is called
once, when numba really compiles (a cache miss), so a command can say "compiling" only when it is.

numba compiles under the interpreter's lock, one function at a time, so a thread cannot share the
work; a second *process* can. :func:`prefetch_kernels` starts one that compiles a part into the
on-disk cache while this process compiles the others; :func:`warm_up_kernels` waits for it
before that part and then loads the part from the cache. ``docs/motion.md``, "Compiled kernels".
"""

from __future__ import annotations

import atexit
import json
import logging
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from anyplan.world.robot import RobotSpec

__all__ = ["warm_up_kernels", "PARTS", "VISGRAPH", "compiling_notifier", "prefetch_kernels",
           "prefetch_parts", "prefetch_report"]

logger = logging.getLogger(__name__)
#: Every agent's part, in the order they are loaded.
PARTS = ("bitstar", "stmap", "motion", "contacts", "sequential", "spacetime")
#: A part of the simulation's own, not an agent's: the visibility graph of the feasibility check
#: before every run and of the time lower bound (a scenario without a map). Only a second
#: process compiles it ahead (``anyplan run``); otherwise it compiles or loads on first use.
VISGRAPH = "visgraph"
_DONE: set[str] = set()
#: A part that a second process may compile while this one compiles the others: it shares no
#: kernel with loading a scenario or BIT*'s part but the clearance kernels (``sequential`` runs
#: BIT* and the motion planner, so it would compile both again). The second process compiles
#: them in this order, the clearance kernels last (:func:`_curves`), so that it loads those from
#: the cache this process fills first, and this process loads the visibility graph's kernels
#: from the cache when it checks the run's feasibility, after loading the scenario.
PREFETCHABLE = (VISGRAPH, "contacts", "motion")
#: Set to ``1`` (or ``0``) to compile in this process only.
ENV_JOBS = "ANYPLAN_COMPILE_JOBS"


class compiling_notifier:  # noqa: N801 - a context manager used like a function
    """Within the ``with`` block, call ``callback()`` once at numba's first real compilation
    (a cache miss; loading cached machine code is not one).

    Attributes:
        compiled: True once something was compiled inside the block.
        seconds: Wall time [s] spent compiling inside the block (nested compilations, of the
            functions a kernel calls, counted once).
        count: Number of functions compiled (each specialisation, nested ones included).
    """

    def __init__(self, callback: Callable[[], None] | None) -> None:
        self.callback = callback
        self.compiled = False
        self.seconds = 0.0
        self.count = 0
        self._listener: Any = None

    def __enter__(self) -> compiling_notifier:
        from numba.core import event

        notifier = self
        depth = [0, 0.0]

        class _Listener(event.Listener):
            def on_start(self, ev: event.Event) -> None:
                notifier.count += 1
                if depth[0] == 0:
                    depth[1] = time.perf_counter()
                depth[0] += 1
                if not notifier.compiled:
                    notifier.compiled = True
                    if notifier.callback is not None:
                        notifier.callback()

            def on_end(self, ev: event.Event) -> None:
                depth[0] -= 1
                if depth[0] == 0:
                    notifier.seconds += time.perf_counter() - depth[1]

        self._listener = _Listener()
        event.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc: object) -> None:
        from numba.core import event

        event.unregister("numba:compile", self._listener)


class _Prefetch:
    """A second process compiling ``parts`` into numba's on-disk cache."""

    def __init__(self, parts: tuple[str, ...]) -> None:
        import anyplan

        self.parts = parts
        self.log = tempfile.TemporaryFile(mode="w+")  # noqa: SIM115 - closed in finish()
        root = os.path.dirname(os.path.dirname(os.path.abspath(anyplan.__file__)))
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
        env[ENV_JOBS] = "1"
        self.proc = subprocess.Popen(
            [sys.executable, "-c", "from anyplan.agents.warmup import _child; _child()",
             *parts], stdin=subprocess.DEVNULL, stdout=self.log, stderr=subprocess.STDOUT, env=env)
        self.waited_s = 0.0
        self.count = 0
        self.seconds = 0.0
        self.ok: bool | None = None

    def finish(self, timeout_s: float = 600.0) -> None:
        """Wait for the process (at most ``timeout_s``, then stop it); read what it compiled."""
        if self.ok is not None:
            return
        t0 = time.perf_counter()
        try:
            code = self.proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait()
        self.waited_s = time.perf_counter() - t0
        self.log.seek(0)
        out = self.log.read()
        self.log.close()
        self.ok = code == 0
        last = out.strip().splitlines()[-1:] if out.strip() else []
        try:
            rec = json.loads(last[0]) if self.ok and last else {}
        except ValueError:
            rec = {}
        self.count, self.seconds = int(rec.get("count", 0)), float(rec.get("seconds", 0.0))
        if not self.ok:
            logger.info("compiling %s in a second process failed (exit %s); compiling here:\n%s",
                        ", ".join(self.parts), code, out[-2000:])

    def stop(self) -> None:
        if self.ok is None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
            self.ok = False
            self.log.close()


_PREFETCH: dict[str, _Prefetch] = {}


def prefetch_parts(parts: Iterable[str]) -> tuple[str, ...]:
    """The parts of ``parts`` that :func:`prefetch_kernels` would hand to a second process: the
    prefetchable ones, when another part stays for this process and this process has not
    loaded them yet, in :data:`PREFETCHABLE`'s order."""
    parts = tuple(parts)
    mine = [p for p in parts if p not in PREFETCHABLE]
    return tuple(p for p in PREFETCHABLE if p in parts and p not in _DONE and p not in _PREFETCH
                 and mine)


def prefetch_kernels(parts: Iterable[str]) -> tuple[str, ...]:
    """Start compiling the prefetchable ``parts`` (:func:`prefetch_parts`) in a second process;
    returns the parts handed over (none on a single core, or with ``ANYPLAN_COMPILE_JOBS=1``).

    Call it when numba starts compiling (a cold cache: :class:`compiling_notifier`'s callback):
    this process goes on with scenario loading and the other parts, and :func:`warm_up_kernels`
    waits for the second process before a part it took, then loads that part from the cache.
    On a warm cache there is nothing to gain (loading takes milliseconds), so do not call it.
    If the second process fails, this one compiles the part itself."""
    jobs = os.environ.get(ENV_JOBS, "").strip()
    if jobs in ("0", "1") or (not jobs and (os.cpu_count() or 1) < 2):
        return ()
    todo = prefetch_parts(parts)
    if not todo:
        return ()
    try:
        job = _Prefetch(todo)
    except OSError as exc:  # no process could be started: compile here
        logger.info("no second process for compiling: %s", exc)
        return ()
    for p in todo:
        _PREFETCH[p] = job
    return todo


def prefetch_report() -> tuple[int, float]:
    """Functions compiled by the second processes that have finished, and the seconds [s] this
    process waited for them (compile time on its clock, beside its own compilations)."""
    jobs = {id(j): j for j in _PREFETCH.values() if j.ok is not None}.values()
    return sum(j.count for j in jobs), sum(j.waited_s for j in jobs)


@atexit.register
def _stop_prefetch() -> None:
    for job in _PREFETCH.values():
        job.stop()


def _child() -> None:
    """The second process: compile ``sys.argv[1:]``, print what it compiled as one JSON line."""
    with compiling_notifier(None) as note:
        for part in sys.argv[1:]:  # in the order given (PREFETCHABLE's), not PARTS'
            warm_up_kernels([part])
    print(json.dumps({"count": note.count, "seconds": note.seconds}))


def _bitstar() -> None:
    """BIT*'s search."""
    from anyplan.planning.bitstar import warm_up as warm_up_bitstar

    warm_up_bitstar()


def _scene():  # noqa: ANN202 - small fixture shared by the motion and sequential parts
    from anyplan.geometry.collision import ObstacleSet
    from anyplan.geometry.shapes import Circle, square
    from anyplan.world.robot import RobotSpec

    obs = ObstacleSet([Circle(np.array([2.0, 2.0]), 0.4), square((2.0, 0.9), 0.3)],
                      bounds=(0.0, 0.0, 4.0, 4.0))
    spec = RobotSpec(start=(0.5, 0.5, 0.0), goal=(3.5, 3.5), radius=0.2)
    return obs, spec


def _curves(spec: RobotSpec, path: np.ndarray) -> None:
    """The motion part's kernels that query no obstacle (the spline, its regularity, speed
    profile and sampling; turning in place): compiled first, so that a second process compiling
    the motion part reaches the clearance kernels it shares with this one's scenario loading and
    BIT* after them, and loads them from the cache instead of compiling them again."""
    from anyplan.trajectory.motion import turn_segment
    from anyplan.trajectory.path import clean_path
    from anyplan.trajectory.profile import time_parameterize
    from anyplan.trajectory.spline import SmoothCurve
    from anyplan.trajectory.trajectory import CurveSegment, Trajectory

    pts = clean_path(path)
    for heading, kappa, v0 in ((0.0, None, 0.0), (0.3, 0.5, 0.2)):  # _motion's two states
        curve = SmoothCurve(pts, start_heading=heading, grid_step=0.05, start_curvature=kappa)
        curve.is_regular()
        curve.curvature(np.array([0.0]))
        traj = Trajectory([CurveSegment(curve, time_parameterize(curve, spec, v0), 0.0)])
        traj.sample(np.array([0.5]))
        traj.sample(np.linspace(0.0, traj.t_end, 7))
    turn_segment(0.5, 0.5, 0.0, 1.0, spec, 0.0).sample(np.array([0.1]))


def _motion() -> None:
    """Smoothing, certification, speed profile and sampling of a motion."""
    from anyplan.trajectory.motion import plan_motion
    from anyplan.world.robot import RobotState

    obs, spec = _scene()
    path = np.array([[0.5, 0.5], [3.0, 1.2], [3.5, 3.5]])
    _curves(spec, path)
    for state in (RobotState(0.5, 0.5, 0.0), RobotState(0.5, 0.5, 0.3, 0.2, 0.1)):
        traj = plan_motion(path, spec, state, obs, 0.0, margin=0.015, grid_step=0.05)
        traj.sample(np.array([0.5]))
        traj.sample(np.linspace(0.0, traj.t_end, 7))


def _contacts() -> None:
    """The closed-form first contacts of straight discs, growing or not, with a sampled motion
    (the collision prediction's common case: twist and tracked predictions, straight movers),
    and the broad phase of looping tracks (pacing movers, DynaBARN's announced tracks)."""
    from anyplan.prediction.base import PredictedObstacle, RadiusGrowth
    from anyplan.prediction.collision import first_collision, predict_collisions
    from anyplan.world.motion import UnicycleMotion, WaypointMotion

    class _Line:  # a robot reference on a straight line: x = t [m]
        t_start, t_end, max_speed = 0.0, 4.0, 1.0

        def positions(self, t: np.ndarray) -> np.ndarray:
            t = np.asarray(t, dtype=float)
            return np.column_stack([t, np.zeros_like(t)])

    grow = RadiusGrowth(0.0, np.array([0.0, 2.0]), np.array([0.0, 0.5]))
    movers = [PredictedObstacle("a", 0.2, UnicycleMotion(3.0, 1.0, -1.5708, 0.5), grow),
              PredictedObstacle("b", 0.2, UnicycleMotion(1.0, -2.0, 1.5708, 0.5))]
    predict_collisions(_Line(), movers, 0.2, sample_dt=0.02)
    predict_collisions(_Line(), movers[1:], 0.2, sample_dt=0.02)
    pacing = PredictedObstacle("c", 0.2, WaypointMotion(np.array([[0.0, 2.0, 1.0], [2.0, 2.0, -1.0],
                                                                  [4.0, 2.0, 1.0]])))
    first_collision(_Line(), [pacing], 0.2, sample_dt=0.02)


def _sequential() -> None:
    """Collision prediction, and one Sequential BIT* replanning around a crossing obstacle."""
    from anyplan.planning.sequential import SequentialBITStar, SequentialConfig
    from anyplan.prediction.base import PredictedObstacle
    from anyplan.prediction.collision import first_collision
    from anyplan.trajectory.motion import plan_motion
    from anyplan.world.motion import UnicycleMotion
    from anyplan.world.robot import RobotState

    if TYPE_CHECKING:
        from anyplan.geometry.shapes import Shape
        from anyplan.trajectory.trajectory import Trajectory

    obs, spec = _scene()
    path = np.array([[0.5, 0.5], [3.0, 1.2], [3.5, 3.5]])
    traj = plan_motion(path, spec, RobotState(0.5, 0.5, 0.3, 0.2, 0.1), obs, 0.0)
    mover = PredictedObstacle("D", 0.2, UnicycleMotion(3.0, 0.5, 2.0, 0.2, 0.1))
    first_collision(traj, [mover], spec.radius, sample_dt=0.02)
    # One Sequential BIT* replanning around a crossing obstacle: virtual squares, repairs of
    # curves that cut them, delayed departures.
    crossing = PredictedObstacle("X", 0.2, UnicycleMotion(2.0, 0.2, 1.5708, 0.25, 0.0))
    rest = RobotState(0.5, 3.0, -0.7854)

    def motion_fn(p: np.ndarray, shapes: Sequence[Shape], delay: float) -> Trajectory:
        return plan_motion(p, spec, rest, obs.with_shapes(shapes), delay, margin=0.015, grid_step=0.05)

    loop = SequentialBITStar(obs, robot_radius=spec.radius, plan_radius=spec.radius + 0.03,
                             motion=motion_fn,
                             config=SequentialConfig(max_iterations=3, wait_delays_s=(1.0,)),
                             rng=np.random.default_rng(0))
    loop.replan(np.array([0.5, 3.0]), np.array([3.5, 0.5]), [crossing], 0.0)


def _stmap() -> None:
    """The s-t map, the velocity lattice and the detours' disconnection proof: kernels that call
    none of the motion part's, so this process compiles them while a second one compiles that
    part (the straight path below is numpy, not a smoothed curve)."""
    from anyplan.geometry.collision import ObstacleSet
    from anyplan.planning.connectivity import provably_disconnected
    from anyplan.prediction.base import PredictedObstacle
    from anyplan.trajectory.spacetime import build_stmap, plan_velocity
    from anyplan.world.motion import UnicycleMotion

    a, b = np.array([0.5, 0.5]), np.array([3.5, 0.5])
    length = float(np.hypot(*(b - a)))

    def points_at(s: np.ndarray) -> np.ndarray:
        return a + np.outer(s / length, b - a)

    mover = PredictedObstacle("X", 0.2, UnicycleMotion(2.0, 1.9, -1.5708, 0.3))
    st = build_stmap(points_at, length, [mover], 0.2, 0.0, 8.0)
    caps = np.full(st.forbidden.shape[1], 1.0)
    for v0 in (0.0, 0.3):  # on the lattice's speed levels, and between two (its first step)
        plan_velocity(st.forbidden, st.t_map, st.h, st.ds, caps, caps, length, 0.0, v0, 0.5, 1.0,
                      horizon_s=8.0, rows=st.rows)
    provably_disconnected(ObstacleSet([], bounds=(0.0, 0.0, 4.0, 2.0)), (0.5, 0.5), (3.5, 0.5),
                          0.2)


def _spacetime() -> None:
    """st-bitstar's timing of a smoothed motion among moving discs and its certified check (the
    detours' disconnection proof is the ``stmap`` part's)."""
    from anyplan.geometry.collision import ObstacleSet
    from anyplan.prediction.base import PredictedObstacle
    from anyplan.trajectory.motion import plan_motion
    from anyplan.trajectory.spacetime import retime, verify
    from anyplan.world.motion import UnicycleMotion
    from anyplan.world.robot import RobotSpec, RobotState

    spec = RobotSpec(start=(0.5, 0.5, 0.0), goal=(3.5, 0.5), radius=0.2)
    obs = ObstacleSet([], bounds=(0.0, 0.0, 4.0, 2.0))
    tr = plan_motion(np.array([[0.5, 0.5], [3.5, 0.5]]), spec, RobotState(0.5, 0.5, 0.0), obs, 0.0)
    mover = PredictedObstacle("X", 0.2, UnicycleMotion(2.0, 1.9, -1.5708, 0.3))
    res = retime(tr, [mover], spec, max_wait_s=5.0)
    if res.trajectory is not None:
        verify(res.trajectory, [mover], spec.radius)


def _visgraph() -> None:
    """The relaxed visibility graph without a map (:data:`VISGRAPH`)."""
    from anyplan.planning.visgraph import warm_up

    warm_up()


#: Every part (the simulation's first), in the order they are loaded.
_RUN = {VISGRAPH: _visgraph, "bitstar": _bitstar, "stmap": _stmap, "motion": _motion,
        "contacts": _contacts, "sequential": _sequential, "spacetime": _spacetime}


def warm_up_kernels(parts: Iterable[str] = PARTS,
                    on_compile: Callable[[], None] | None = None) -> float:
    """Compile or load the kernels of ``parts`` (see the module docstring), each once per
    process; returns seconds. ``on_compile`` is called once if numba compiles anything.

    Raises:
        ValueError: an unknown part.
    """
    todo = [p for p in _RUN if p in set(parts) and p not in _DONE]
    unknown = set(parts) - set(_RUN)
    if unknown:
        raise ValueError(f"parts: unknown {sorted(unknown)} (known: {', '.join(_RUN)})")
    if not todo:
        return 0.0
    t0 = time.perf_counter()
    with compiling_notifier(on_compile) as note:
        for p in todo:
            _DONE.add(p)
            job = _PREFETCH.get(p)
            if job is not None:
                job.finish()  # then the part loads from the cache it filled
            _RUN[p]()
    dt = time.perf_counter() - t0
    logger.info("kernels %s %s in %.2f s", "compiled" if note.compiled else "loaded",
                ", ".join(todo), dt)
    return dt
