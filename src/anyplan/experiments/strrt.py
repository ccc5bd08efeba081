"""OMPL's STRRT* (Grothe et al., ICRA 2022) as an offline peer of ``st-bitstar``.

STRRT* plans in (x, y, t) for a holonomic point robot with |v| <= v_max, minimising the arrival
time, given the static obstacles and the true motions of the moving ones, with exact validity
checks (states and motions, the latter by :func:`anyplan.geometry.first_contact`, between the
jumps of an open track). Only the ``ompl`` 1.7 wheels expose it
(``pip install 'anyplan[strrt]'``); each problem is solved in a fresh subprocess
(``python -m anyplan.experiments.strrt``, JSON in and out) because of the wheel's import-order
and exit traps.

Validity checks and the subprocess protocol: ``docs/spacetime.md``, "STRRT*: how it is run".
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from typing import Any

from anyplan.world.scenario import Scenario

__all__ = ["strrt_available", "solve_strrt"]


def _env(site: str | None) -> dict[str, str]:
    env = dict(os.environ)
    if site:
        env["PYTHONPATH"] = site + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


def strrt_available(site: str | None = None) -> bool:
    """True if a subprocess can import ``ompl`` with ``og.STRRTstar`` (1.7 wheels)."""
    code = ("import numpy, os\n"
            "try:\n from ompl import base as ob, geometric as og\n"
            " ok = hasattr(og, 'STRRTstar') and hasattr(ob, 'SpaceTimeStateSpace')\n"
            "except Exception:\n ok = False\n"
            "print('yes' if ok else 'no', flush=True)\nos._exit(0)\n")
    try:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=60, env=_env(site))
    except (OSError, subprocess.TimeoutExpired):
        return False
    return out.stdout.strip().endswith("yes")


def solve_strrt(scenario: Scenario, budget_s: float, seed: int = 0, site: str | None = None,
                timeout_s: float | None = None) -> dict[str, Any]:
    """Solve ``scenario`` offline with STRRT* for ``budget_s`` seconds in a subprocess.

    Returns:
        ``{solved, arrival_s (at the goal centre), goal_edge_s (first time within the goal
        tolerance), path_length_m, path: [[x, y, t], ...], solve_time_s}``, or
        ``{solved: False, error}`` if the subprocess failed.
    """
    problem = {"scenario": scenario.to_dict(), "budget_s": float(budget_s), "seed": int(seed)}
    try:
        out = subprocess.run([sys.executable, "-m", "anyplan.experiments.strrt"],
                             input=json.dumps(problem), capture_output=True, text=True,
                             timeout=timeout_s or (budget_s * 3 + 60), env=_env(site))
    except subprocess.TimeoutExpired:
        return {"solved": False, "error": "timeout"}
    for line in reversed(out.stdout.strip().splitlines()):
        if line.startswith("{"):
            return json.loads(line)
    return {"solved": False, "error": (out.stderr.strip().splitlines() or ["no output"])[-1]}


def _clear_of_movers(movers: list[tuple[Any, float]], radius: float, sa: tuple[float, float, float],
                     sb: tuple[float, float, float], v: float) -> bool:
    """True if a robot disc of ``radius`` [m] moving straight from ``sa`` to ``sb`` (x [m],
    y [m], t [s]) at speed ``v`` [m/s] touches no mover, (motion, radius [m]), on the way:
    :func:`~anyplan.geometry.moving.first_contact` on each continuous piece of a mover's
    motion, where its speed bound holds (an open track jumps: ``Motion.continuous_pieces``)."""
    import numpy as np

    from anyplan.geometry.moving import first_contact

    (xa, ya, ta), (xb, yb, tb) = sa, sb
    pa, pb = np.array([xa, ya]), np.array([xb, yb])

    def robot(t: np.ndarray) -> np.ndarray:
        u = ((np.asarray(t, dtype=float) - ta) / (tb - ta))[:, None]
        return pa + u * (pb - pa)

    for m, rad in movers:
        for a, b in m.continuous_pieces(ta, tb):  # [(ta, tb)] for a motion that never jumps
            if first_contact(robot, m.positions, v + m.max_speed, radius + rad, a, b,
                             tol=1e-4) is not None:
                return False
    return True


def _worker(problem: dict[str, Any]) -> dict[str, Any]:  # pragma: no cover - runs in a subprocess
    import time

    import numpy as np
    from ompl import base as ob  # after numpy (docs/spacetime.md, "STRRT*: how it is run")
    from ompl import geometric as og
    from ompl import util as ou

    from anyplan.world.scenario import scenario_from_dict

    sc = scenario_from_dict(problem["scenario"], "<strrt problem>")
    r = sc.robot
    statics = sc.obstacle_set()
    movers = [(o.motion, o.radius) for o in sc.moving_obstacles]
    ou.RNG.setSeed(int(problem["seed"]) + 1)
    ou.setLogLevel(ou.LOG_NONE)
    vs = ob.RealVectorStateSpace(2)
    b = ob.RealVectorBounds(2)
    x0, y0, x1, y1 = sc.bounds
    b.setLow(0, x0)
    b.setHigh(0, x1)
    b.setLow(1, y0)
    b.setHigh(1, y1)
    vs.setBounds(b)
    space = ob.SpaceTimeStateSpace(vs, r.v_max)
    space.setTimeBounds(0.0, float(sc.time_limit))
    space.updateEpsilon()
    si = ob.SpaceInformation(space)

    def xyt(s: Any) -> tuple[float, float, float]:
        return float(s[0][0]), float(s[0][1]), float(space.getStateTime(s))

    def valid(s: Any) -> bool:
        x, y, t = xyt(s)
        if t < 0.0 or not statics.point_free((x, y), r.radius):
            return False
        ta = np.array([t])
        return all(math.hypot(*(m.positions(ta)[0] - (x, y))) > r.radius + rad for m, rad in movers)

    class Exact(ob.MotionValidator):
        def checkMotion(self, s1: Any, s2: Any) -> bool:  # noqa: N802 - OMPL's name
            if not valid(s2):
                return False
            xa, ya, ta = xyt(s1)
            xb, yb, tb = xyt(s2)
            if tb <= ta:
                return False
            d = math.hypot(xb - xa, yb - ya)
            v = d / (tb - ta)
            if v > r.v_max * (1.0 + 1e-9):
                return False
            if d > 0.0 and not statics.segment_free((xa, ya), (xb, yb), r.radius):
                return False
            return _clear_of_movers(movers, r.radius, (xa, ya, ta), (xb, yb, tb), v)

    si.setStateValidityChecker(ob.StateValidityCheckerFn(valid))
    mv = Exact(si)
    si.setMotionValidator(mv)
    si.setup()
    start, goal = ob.State(space), ob.State(space)
    start()[0][0], start()[0][1] = r.start[0], r.start[1]
    goal()[0][0], goal()[0][1] = r.goal[0], r.goal[1]
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(start, goal)
    pdef.setOptimizationObjective(ob.MinimizeArrivalTime(si))
    planner = og.STRRTstar(si)
    planner.setRange(r.v_max)
    planner.setProblemDefinition(pdef)
    planner.setup()
    t0 = time.perf_counter()
    planner.solve(float(problem["budget_s"]))
    spent = time.perf_counter() - t0
    if not pdef.hasExactSolution():
        return {"solved": False, "solve_time_s": spent}
    path = pdef.getSolutionPath()
    pts = [list(xyt(path.getState(i))) for i in range(path.getStateCount())]
    p = np.array(pts)
    length = float(np.sum(np.hypot(*np.diff(p[:, :2], axis=0).T)))
    edge = p[-1, 2]
    for (xa, ya, ta), (xb, yb, tb) in zip(pts[:-1], pts[1:], strict=True):
        # first time along the path within the goal tolerance (solve on the segment)
        da, db = math.hypot(xa - r.goal[0], ya - r.goal[1]), math.hypot(xb - r.goal[0], yb - r.goal[1])
        if db <= r.goal_tolerance:
            if da <= r.goal_tolerance:
                edge = ta
                break
            lo, hi = 0.0, 1.0
            for _ in range(50):
                mid = 0.5 * (lo + hi)
                q = (xa + mid * (xb - xa), ya + mid * (yb - ya))
                if math.hypot(q[0] - r.goal[0], q[1] - r.goal[1]) <= r.goal_tolerance:
                    hi = mid
                else:
                    lo = mid
            edge = ta + hi * (tb - ta)
            break
    return {"solved": True, "arrival_s": float(p[-1, 2]), "goal_edge_s": float(edge),
            "path_length_m": length, "path": pts, "solve_time_s": spent}


if __name__ == "__main__":  # pragma: no cover - the subprocess
    import numpy  # noqa: F401 - before ompl

    try:
        answer = _worker(json.loads(sys.stdin.read()))
    except Exception as exc:  # report, never hang the caller
        answer = {"solved": False, "error": f"{type(exc).__name__}: {exc}"}
    sys.stdout.write(json.dumps(answer) + "\n")
    sys.stdout.flush()
    os._exit(0)
