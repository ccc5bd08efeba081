"""``anyplan run`` and ``anyplan scenarios``."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from anyplan.agents.base import AGENTS, make_agent
from anyplan.agents.stats import improvement_calls
from anyplan.cli import checks
from anyplan.cli.agent_options import add_agent_options, run_config
from anyplan.cli.perception_opts import (
    add_perception_options,
    add_tracker_option,
    apply_perception,
    tracker_settings,
)
from anyplan.errors import UsageError
from anyplan.experiments.db import agent_settings_string
from anyplan.simulation.simulator import SimConfig, simulate
from anyplan.world.scenario import builtin_scenarios, load_scenario

DEFAULT_PLANNER = "st-bitstar"
#: The picture format and the animation's playback speed when --format and --speed are not given.
DEFAULT_FORMAT = "png"
DEFAULT_SPEED = 4.0

EXIT_CODES = """\
exit codes:
  0  the robot reached the goal
  1  the run collided or timed out (result.json and run.png are still written)
  2  bad input (unknown scenario, planner or setting, malformed file or option)"""


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``run`` and ``scenarios`` sub-commands."""
    p = sub.add_parser("run", help="simulate a planner on a scenario",
                       description="Simulate a planner on a scenario; writes DIR/result.json "
                       "and DIR/run.png (or --format svg/pdf) and prints a summary.", epilog=EXIT_CODES,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenario", type=checks.nonempty("a built-in scenario name or a YAML file"),
                   help="built-in scenario name (see 'anyplan scenarios') or YAML file")
    p.add_argument("--planner", default=DEFAULT_PLANNER,
                   help=f"planner name (default {DEFAULT_PLANNER}; one of: {', '.join(AGENTS.names())})")
    p.add_argument("--seed", type=checks.seed, default=0, help="random seed >= 0 (default 0)")
    p.add_argument("--out", default=None, type=checks.nonempty("a folder"),
                   help="output folder (default runs/SCENARIO-PLANNER-SEED)")
    p.add_argument("--dt", type=checks.sim_step, default=0.05,
                   help="simulation step [s], in [0.001, 0.05] (default 0.05)")
    p.add_argument("--time-limit", type=checks.time_limit, default=None,
                   help="simulated time limit [s] (default: the scenario's)")
    p.add_argument("--actuation-noise", type=checks.actuation_noise, default=(0.0, 0.0),
                   metavar="SV,SW", help="the robot drives its commands with a correlated error of "
                   "these spreads [m/s, rad/s] at full speed (slip; none at rest; seeded by --seed; "
                   "default 0,0: exactly)")
    p.add_argument("--localization-noise", type=checks.localization_noise, default=(0.0, 0.0),
                   metavar="SXY,STH", help="the robot believes its pose off by a slowly wandering "
                   "error of these spreads [m per axis, rad], and places what it senses with it "
                   "(seeded by --seed; default 0,0: exactly)")
    p.add_argument("--no-plot", action="store_true", help="do not write run.png")
    p.add_argument("--format", default=None, choices=("png", "svg", "pdf"),
                   help=f"picture format: DIR/run.png, run.svg or run.pdf (default {DEFAULT_FORMAT}; "
                        "not with --no-plot)")
    p.add_argument("--animate", default=None, metavar="FILE", type=checks.nonempty("a file"),
                   help="also write an animation of the run (.gif, or .mp4 when ffmpeg is present)")
    p.add_argument("--speed", type=checks.playback_speed, default=None,
                   help="with --animate: the animation's playback speed, x real time "
                        f"(default {DEFAULT_SPEED:g})")
    add_perception_options(p)
    add_tracker_option(p)
    p.add_argument("--mcap", default=None, metavar="FILE", type=checks.nonempty("a file"),
                   help="also write the run as an MCAP file with ROS 2 messages (poses, plans, "
                        "obstacles; for Foxglove, RViz, ros2 bag); needs the 'mcap' extra")
    add_agent_options(p)
    p.set_defaults(func=cmd_run)

    s = sub.add_parser("scenarios", help="list the built-in scenarios")
    s.set_defaults(func=cmd_scenarios)


def cmd_scenarios(args: argparse.Namespace) -> int:
    """Print the built-in scenarios."""
    for name, desc in builtin_scenarios().items():
        print(f"{name:12s} {desc}")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    """Simulate one run and write its result and picture; say so on stderr if numba compiles
    kernels (the first run on a machine), and for how long.

    On a cold cache a second process compiles the feasibility check's visibility graph and the
    planner's motion kernels meanwhile (:func:`~anyplan.agents.warmup.prefetch_kernels`;
    ``ANYPLAN_COMPILE_JOBS=1`` turns it off)."""
    from anyplan.agents.warmup import VISGRAPH, compiling_notifier, prefetch_kernels, prefetch_report

    def compiling() -> None:
        _compiling_notice()
        prefetch_kernels((VISGRAPH, *_kernel_parts(args.planner)))

    with compiling_notifier(compiling) as note:
        code = _run(args)
    if note.compiled:
        more, waited = prefetch_report()
        n = note.count + more
        what = _count(n, "function")
        where = f", {more} of them in a second process" if more else ""
        sys.stderr.write(f"anyplan: compiled {what} in {note.seconds + waited:.1f} s{where} "
                         "(once: later runs load them from the cache)\n")
    return code


def _kernel_parts(planner: str) -> tuple[str, ...]:
    """The compiled parts the planner loads (``Agent.kernel_parts``), none if it is unknown."""
    from anyplan.agents.base import AGENTS

    try:
        cls = AGENTS.get(planner)
    except Exception:  # noqa: BLE001 - an unknown or broken planner fails later, with its message
        return ()
    return tuple(getattr(cls, "kernel_parts", ()))


def _compiling_notice() -> None:
    sys.stderr.write("anyplan: compiling kernels for this machine (once; later runs load them "
                     "from the cache)\n")
    sys.stderr.flush()


def _refuse_unused(args: argparse.Namespace) -> None:
    """Refuse an option that nothing would read: ``--speed`` without ``--animate``, ``--format``
    with ``--no-plot``."""
    if args.speed is not None and not args.animate:
        raise UsageError("run: --speed applies to --animate only")
    if args.format is not None and args.no_plot:
        raise UsageError("run: --format applies to the picture, which --no-plot turns off")


def _run(args: argparse.Namespace) -> int:
    _refuse_unused(args)  # before any work
    fmt = args.format or DEFAULT_FORMAT
    speed = DEFAULT_SPEED if args.speed is None else args.speed
    scenario = apply_perception("run", [load_scenario(args.scenario)], args)[0]
    config = run_config(args, args.planner)  # unknown names and bad settings fail before any work
    tracker = tracker_settings("run", args, [scenario])
    try:
        cfg = SimConfig(dt=args.dt, time_limit=args.time_limit, tracker=tracker,
                        actuation_sigma_v=args.actuation_noise[0],
                        actuation_sigma_omega=args.actuation_noise[1],
                        localization_sigma_xy=args.localization_noise[0],
                        localization_sigma_theta=args.localization_noise[1])
        cfg.steps(scenario.time_limit)
    except ValueError as exc:
        raise UsageError(f"run: {checks.flag_message(exc, checks.SIM_FLAGS)}") from None
    out = Path(args.out or f"runs/{checks.safe_name(scenario.name)}-"
                           f"{checks.safe_name(args.planner)}-{args.seed}")
    # Every output is proven writable before simulating, so no run is lost at the end.
    checks.writable_folder(out, "run: --out")
    checks.writable_file(out / "result.json", "run: --out")
    if not args.no_plot:
        checks.writable_file(out / f"run.{fmt}", "run: --out")
    if args.animate:
        from anyplan.viz.animation import check_target

        checks.writable_file(args.animate, "run: --animate", (".gif", ".mp4"))
        try:
            check_target(args.animate, speed)
        except ValueError as exc:
            raise UsageError(f"run: --animate: {exc}") from None
    if args.mcap:  # check the extra and the target before simulating
        from anyplan.experiments.mcap_log import check_target as check_mcap

        check_mcap(args.mcap)
        checks.writable_file(args.mcap, "run: --mcap", (".mcap",), make_parent=False)
    agent = make_agent(args.planner, **config)
    result = simulate(scenario, agent, seed=args.seed, config=cfg)
    # the settings given (--set, --deterministic, --tracker), as anyplan bench records them: with
    # the seed and the scenario, what reproduces the run
    result.extra["settings"] = agent_settings_string(config, cfg)
    (out / "result.json").write_text(json.dumps(result.to_dict(), indent=1))
    if not args.no_plot:
        from anyplan.viz.run import save_run_figure

        save_run_figure(scenario, result, out / f"run.{fmt}")
    print(summary(result, out))
    if args.mcap:
        from anyplan.experiments.mcap_log import write_mcap

        print(f"  ROS 2 log      {write_mcap(args.mcap, scenario, result).path}")
    if args.animate:
        from anyplan.viz.animation import animate_run

        print(f"  animation      {animate_run(scenario, result, args.animate, speed=speed)}")
    return 0 if result.reached_goal else 1


def _count(n: int, noun: str) -> str:
    """``"1 call"``, ``"2 calls"``."""
    return f"{n} {noun}" + ("" if n == 1 else "s")


def _tracking_line(extra: dict) -> str:
    """How far the robot strayed from its references, and how often it planned from its own
    state instead (``reanchored_s``)."""
    n = len(extra.get("reanchored_s") or ())
    worst = extra.get("tracking_max_m")
    off = (f"off it {_count(n, 'time')} (replanned from the robot's own state)" if n
           else "never off it")
    return f"  tracking       {'-' if worst is None else f'{worst:.3f} m'} from the reference at most; {off}"


def _localization_line(extra: dict) -> str:
    """How far off the robot believed its position at most, with the error's spreads, and the
    clearance its planner kept for it (``pose_margin_m``)."""
    loc, kept = extra["localization"], extra.get("pose_margin_m")
    return (f"  localization   believed position off by {loc['max_position_error_m']:.3f} m at most "
            f"(spreads {loc['sigma_xy_m']:g} m, {loc['sigma_theta_rad']:g} rad)"
            + ("" if kept is None else f"; {kept:.3f} m more clearance kept for it"))


def summary(result, out: Path) -> str:  # noqa: ANN001 - RunResult
    """A few human-readable lines about a run."""
    pt = result.planning_times_s
    # st-bitstar's improvement calls: made while the robot drives a safe motion already
    n_imp = sum(improvement_calls(result.extra, len(pt)))
    lines = [
        f"{result.scenario} / {result.planner} / seed {result.seed}: {result.status}"
        + (f" (hit {result.collision_with} at t = {result.collision_time_s:.2f} s, "
           f"{'robot-caused' if result.collision_robot_caused else 'not robot-caused'})"
           if result.collision else ""),
        (f"  time to goal   {result.time_to_goal_s:.2f} s" if result.time_to_goal_s is not None
         else "  time to goal   -")
        + (f" ({result.time_over_lower_bound:.3f} x lower bound {result.time_lower_bound_s:.2f} s)"
           if result.time_over_lower_bound is not None else ""),
        f"  path length    {result.path_length_m:.3f} m",
        f"  min clearance  {result.min_clearance_m:.3f} m",
        f"  planning       {_count(len(pt), 'call')}, {sum(pt):.3f} s total, "
        f"{_count(result.replans, 'replan')}"
        + (f" ({n_imp} of them improving the motion in use)" if n_imp else ""),
        *([f"  fallbacks      {len(result.extra['fallbacks'])}"]
          if result.extra.get("fallbacks") else []),
        *([_tracking_line(result.extra)] if any(result.extra.get(k) for k in (
            "actuation", "localization", "reanchored_s")) else []),
        *([_localization_line(result.extra)]
          if result.extra.get("localization") else []),
        f"  wrote          {out / 'result.json'}",
    ]
    return "\n".join(lines)


