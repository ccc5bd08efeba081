"""``anyplan dovs-plot``: the DOVS velocity space at a chosen time of a DOVS run."""

from __future__ import annotations

import argparse
import math
from typing import Any

from anyplan.cli import checks
from anyplan.errors import UsageError


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``dovs-plot`` sub-command."""
    p = sub.add_parser(
        "dovs-plot", help="picture of the DOVS velocity space at a time of a DOVS run",
        description="Drive the robot with the 'dovs' planner up to time T, then draw the DOVS "
        "decision taken in that state: the (omega, v) plane with each obstacle's forbidden "
        "region, the dynamic window, the goal command and the chosen command (like Figure 2 of "
        "Lorente et al., IJRR 2018), next to the world at that instant.")
    p.add_argument("scenario", help="built-in scenario name (see 'anyplan scenarios') or YAML file")
    p.add_argument("--time", type=float, required=True, metavar="T",
                   help="simulated time [s] at which to draw the decision (>= 0)")
    p.add_argument("--seed", type=checks.seed, default=0, help="random seed >= 0 (default 0)")
    p.add_argument("--out", default=None, metavar="FILE",
                   help="output picture, .png, .svg or .pdf (default runs/dovs-SCENARIO-tT.png)")
    p.add_argument("--format", default=None, choices=("png", "svg", "pdf"),
                   help="picture format (default: the suffix of --out, else png)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="params",
                   help="override a DOVSConfig parameter, e.g. --set time_horizon_s=6 (repeatable)")
    p.set_defaults(func=cmd_dovs_plot)


def _parse_params(items: list[str]) -> dict[str, Any]:
    from anyplan.baselines.dovs.config import DOVSConfig

    # the robot's limits come from the scenario (a RobotLimits, not a value of the command line)
    names = [n for n in DOVSConfig.field_names() if n != "limits"]
    out: dict[str, Any] = {}
    for item in items:
        key, sep, raw = item.partition("=")
        key = key.strip()
        if not sep or key not in names:
            raise UsageError(f"dovs-plot: --set {item!r}: expected KEY=VALUE with KEY one of "
                             f"{', '.join(names)}")
        raw = raw.strip()
        val: object
        if raw.lower() in ("true", "false"):
            val = raw.lower() == "true"
        elif raw.lower() == "none":
            val = None
        else:
            try:
                val = int(raw)
            except ValueError:
                try:
                    val = float(raw)
                except ValueError:
                    val = raw
        out[key] = val
    return out


def cmd_dovs_plot(args: argparse.Namespace) -> int:
    """Simulate DOVS up to ``--time`` and draw its decision there."""
    from anyplan.agents.base import Observation
    from anyplan.agents.dovs import DOVSAgent
    from anyplan.simulation.simulator import RunStatus, SimConfig, observe, simulate
    from anyplan.world.robot import RobotState
    from anyplan.world.scenario import load_scenario

    scenario = load_scenario(args.scenario)
    t_req = float(args.time)
    if not math.isfinite(t_req) or t_req < 0.0:
        raise UsageError(f"dovs-plot: --time must be a finite time >= 0 s, got {args.time}")
    if t_req > scenario.time_limit:
        raise UsageError(f"dovs-plot: --time {t_req:g} s is beyond the scenario's time limit "
                         f"({scenario.time_limit:g} s)")
    from anyplan.cli.pictures import picture_path

    default = f"runs/dovs-{checks.safe_name(scenario.name)}-t{t_req:g}.{args.format or 'png'}"
    out = picture_path(args.out or default, args.format, "dovs-plot", "--out")
    checks.writable_file(out, "dovs-plot: --out")
    agent = DOVSAgent(**_parse_params(args.params))

    note = ""
    if t_req > 0.0:
        result = simulate(scenario, agent, seed=args.seed, config=SimConfig(time_limit=t_req))
        traj = result.trajectory_array
        if result.status != RunStatus.TIMEOUT:
            note = f"(the run ended at t = {traj[-1, 0]:.2f} s: {result.status}; drawn there)"
    else:
        import numpy as np

        agent.reset(scenario.static_only(), np.random.default_rng(args.seed))
        x, y, th = scenario.robot.start
        traj = np.array([[0.0, x, y, th, 0.0, 0.0]])
    t, x, y, th, v, w = (float(a) for a in traj[-1])
    state = RobotState(x, y, th, v, w)
    decision = agent.decide(Observation(t, state, observe(scenario, t, state)))

    from anyplan.viz.dovs import save_dovs_figure

    save_dovs_figure(scenario, decision, t, out, trajectory=traj, note=note)
    s = decision.selection
    print(f"{scenario.name} / dovs at t = {t:.2f} s: chosen v = {s.v:.3f} m/s, omega = {s.omega:+.3f} "
          f"rad/s ({s.mode}; {s.n_free} of {s.n_candidates} window samples free)")
    print(f"  wrote {out}")
    return 0
