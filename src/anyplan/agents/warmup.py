"""Loading the compiled kernels before anything is timed.

anyplan's hot loops are numba functions compiled on first use and cached on disk
(``cache=True``): the first process on a machine compiles them, later ones load the cached
code. Agents call :func:`warm_up_kernels` in ``reset`` with the parts they use (``"bitstar"``:
BIT*'s search; ``"motion"``: smoothing, speed profile and sampling; ``"sequential"``: collision
prediction and one replanning around a crossing obstacle), so that neither cost lands inside a
timed planning call: loading a planner's code is a start-up cost, not part of a replanning.
``on_compile`` is called once, when numba really compiles (a cache miss), so a command can say
"compiling" only when it is. ``docs/motion.md``, "Compiled kernels".
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

__all__ = ["warm_up_kernels", "PARTS", "compiling_notifier"]

logger = logging.getLogger(__name__)
#: Every part, in the order they are loaded.
PARTS = ("bitstar", "motion", "sequential")
_DONE: set[str] = set()


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


def _bitstar() -> None:
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


def _motion() -> None:
    from anyplan.trajectory.motion import plan_motion
    from anyplan.world.robot import RobotState

    obs, spec = _scene()
    path = np.array([[0.5, 0.5], [3.0, 1.2], [3.5, 3.5]])
    for state in (RobotState(0.5, 0.5, 0.0), RobotState(0.5, 0.5, 0.3, 0.2, 0.1)):
        traj = plan_motion(path, spec, state, obs, 0.0, margin=0.015, grid_step=0.05)
        traj.sample(np.array([0.5]))
        traj.sample(np.linspace(0.0, traj.t_end, 7))


def _sequential() -> None:
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


_RUN = {"bitstar": _bitstar, "motion": _motion, "sequential": _sequential}


def warm_up_kernels(parts: Iterable[str] = PARTS,
                    on_compile: Callable[[], None] | None = None) -> float:
    """Compile or load the kernels of ``parts`` (see the module docstring), each once per
    process; returns seconds. ``on_compile`` is called once if numba compiles anything.

    Raises:
        ValueError: an unknown part.
    """
    todo = [p for p in PARTS if p in set(parts) and p not in _DONE]
    unknown = set(parts) - set(PARTS)
    if unknown:
        raise ValueError(f"parts: unknown {sorted(unknown)} (known: {', '.join(PARTS)})")
    if not todo:
        return 0.0
    t0 = time.perf_counter()
    with compiling_notifier(on_compile) as note:
        for p in todo:
            _DONE.add(p)
            _RUN[p]()
    dt = time.perf_counter() - t0
    logger.info("kernels %s %s in %.2f s", "compiled" if note.compiled else "loaded",
                ", ".join(todo), dt)
    return dt
