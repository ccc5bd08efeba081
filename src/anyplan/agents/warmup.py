"""Loading the compiled kernels before anything is timed.

anyplan's hot loops are numba functions compiled on first use and cached on disk
(``cache=True``). The very first process on a machine compiles them (tens of seconds); later
processes load the cached machine code (a fraction of a second). Agents call
:func:`warm_up_kernels` in ``reset`` so that neither cost lands inside a timed planning call: a
robot's planner is a long-lived process, and loading its code is a start-up cost, not part of
any replanning.
"""

from __future__ import annotations

import logging
import time

import numpy as np

__all__ = ["warm_up_kernels"]

logger = logging.getLogger(__name__)
_DONE = False


def warm_up_kernels() -> float:
    """Compile or load every kernel the planning agents use, once per process; returns seconds."""
    global _DONE
    if _DONE:
        return 0.0
    _DONE = True
    t0 = time.perf_counter()
    from anyplan.geometry.collision import ObstacleSet
    from anyplan.geometry.shapes import Circle, square
    from anyplan.planning.bitstar import warm_up as warm_up_bitstar
    from anyplan.prediction.base import PredictedObstacle
    from anyplan.prediction.collision import first_collision
    from anyplan.trajectory.motion import plan_motion
    from anyplan.world.motion import UnicycleMotion
    from anyplan.world.robot import RobotSpec, RobotState

    warm_up_bitstar()
    obs = ObstacleSet([Circle((2.0, 2.0), 0.4), square((2.0, 0.9), 0.3)], bounds=(0.0, 0.0, 4.0, 4.0))
    spec = RobotSpec(start=(0.5, 0.5, 0.0), goal=(3.5, 3.5), radius=0.2)
    path = np.array([[0.5, 0.5], [3.0, 1.2], [3.5, 3.5]])
    for state in (RobotState(0.5, 0.5, 0.0), RobotState(0.5, 0.5, 0.3, 0.2, 0.1)):
        traj = plan_motion(path, spec, state, obs, 0.0)
        traj.sample(np.array([0.5]))
        traj.sample(np.linspace(0.0, traj.t_end, 7))
    mover = PredictedObstacle("D", 0.2, UnicycleMotion(3.0, 0.5, 2.0, 0.2, 0.1))
    first_collision(traj, [mover], spec.radius, sample_dt=0.02)
    # One Sequential BIT* replanning around a crossing obstacle: virtual squares, repairs of
    # curves that cut them, delayed departures.
    from anyplan.planning.sequential import SequentialBITStar, SequentialConfig

    crossing = PredictedObstacle("X", 0.2, UnicycleMotion(2.0, 0.2, 1.5708, 0.25, 0.0))
    rest = RobotState(0.5, 3.0, -0.7854)

    def motion_fn(p: np.ndarray, shapes: list, delay: float):  # noqa: ANN202
        return plan_motion(p, spec, rest, obs.with_shapes(shapes), delay, margin=0.015, grid_step=0.05)

    loop = SequentialBITStar(obs, spec.radius, spec.radius + 0.03, motion_fn,
                             SequentialConfig(max_iterations=3, wait_delays_s=(1.0,)),
                             np.random.default_rng(0))
    loop.replan(np.array([0.5, 3.0]), np.array([3.5, 0.5]), [crossing], 0.0)
    dt = time.perf_counter() - t0
    logger.info("compiled kernels ready in %.2f s", dt)
    return dt
