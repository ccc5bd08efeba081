"""Benchmark of issue 15: planning when the obstacles' future is unknown.

Suites, each in the perception modes given (``oracle``, ``twist``, ``tracked``: see
docs/perception.md), for every planner and peer on the same seeds:

* ``dynabarn``: DynaBARN medium + hard worlds (20-59; ``--worlds`` selects);
* ``crowds``: the recorded ETH Hotel and UCY Zara 01 crowds cut into 40 s windows, a robot crossing
  each (``anyplan import-crowd``), and a dense variant (Zara 01 overlaid 10 times, ~30 people in
  view on average, up to ~55), ``tracked`` unless ``--crowd-modes`` says otherwise (``twist``:
  each person's current position and velocity, exact; ``oracle``: their recorded future too,
  the bound a prediction could approach);
* ``gaps``: spacetime's gap worlds with detection noise (``tracked``);
* ``prediction``: ADE/FDE on ETH/UCY (8 frames observed, 12 predicted, 2.5 Hz) of our tracker
  against the constant-velocity baseline, and the coverage of the uncertainty radius; and the
  tracker's predictions of the DynaBARN worlds' obstacles (``--worlds``) 0.5-3 s ahead.

Per (suite, mode, planner): successes, collisions, robot-caused collisions (and those of them
with an obstacle there for longer than the robot's stopping time: "seen in time"; a replayed
person whose recorded track begins on the robot is not), smallest distance to
a moving obstacle, discomfort time, time / lower bound, planning time per call (median and 95th
percentile over all calls; a call's whole wall-clock time, safety guard and fallbacks included,
since 2026-12-03 for ``st-bitstar``); the success rate with its 95 % Wilson interval
(``benchmarks/compare_rows.py`` compares two ``--rows`` files run by run). Targets (issue 15)
are printed beside the figures. With ``--jobs 2`` on a 2-core machine the runs share it: read
timings from ``--jobs 1``.

Usage::

    python benchmarks/unknown.py [--only dynabarn,crowds,gaps,prediction,tracking] [--modes twist,tracked]
        [--planners st-bitstar,seq-bitstar,dovs,orca] [--worlds 20-59] [--windows 9] [--seeds 1]
        [--crowd-modes tracked,twist,oracle] [--sensor-noise M] [--sensor-rate HZ]
        [--sensor-association named|anonymous] [--detection-prob P] [--clutter-rate N]
        [--sensor-occlusion static|all]
        [--actuation-noise SV,SW] [--localization-noise SXY,STH]
        [--jobs 2] [--set [PLANNER:]KEY=VALUE ...] [--deterministic]
        [--tracker KEY=VALUE ...]

``--set`` and ``--deterministic`` are ``anyplan bench``'s (agent settings; a fixed planning delay
and budgets, so that a run depends only on its scenario, settings and seed, not on the load).
``--tracker`` is ``anyplan run``'s and ``anyplan bench``'s: settings of the tracker and its
uncertain discs for every ``tracked`` run and for the prediction scores. ``--actuation-noise``
is ``anyplan run``'s: the robot drives its commands with a seeded, correlated error;
``--localization-noise`` too: the robot believes its pose (and what it senses) off by one.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

SHARED = Path(__file__).resolve().parents[1] / ".." / ".." / "shared" / "benchmarks"
if not SHARED.is_dir():
    SHARED = Path("/work/shared/benchmarks")


def _run(task: tuple[str, dict[str, Any], str, str, int, dict[str, Any],
                     tuple[tuple[str, float], ...], tuple[Any, ...],
                     tuple[float, float, float, float]]
         ) -> dict[str, Any]:
    from anyplan.agents import make_agent
    from anyplan.simulation import SimConfig, simulate
    from anyplan.simulation.perception import override_sensing
    from anyplan.world.scenario import scenario_from_dict

    suite, data, planner, mode, seed, config, tracker, sensing, (sv, sw, sxy, sth) = task
    noise_m, rate_hz, assoc, prob, clutter, occlusion = sensing
    sc = scenario_from_dict(data, f"<{data['name']}>")
    tracked = mode == "tracked"
    sc = override_sensing(sc, mode, noise_m if tracked else None, rate_hz if tracked else None,
                          association=assoc if tracked else None,
                          detection_prob=prob if tracked else None,
                          clutter_rate=clutter if tracked else None,
                          occlusion=occlusion if tracked else None)
    try:
        res = simulate(sc, make_agent(planner, **config), seed=seed,
                       config=SimConfig(tracker=tracker, actuation_sigma_v=sv, actuation_sigma_omega=sw,
                                        localization_sigma_xy=sxy, localization_sigma_theta=sth))
    except Exception as exc:  # noqa: BLE001 - a planner failure is a result, reported
        return {"suite": suite, "mode": mode, "planner": planner, "scenario": sc.name, "seed": seed,
                "status": f"error: {type(exc).__name__}", "times": []}
    appeared = None
    appeared_late = None
    if res.status == "collision" and res.collision_with is not None:
        # Did the obstacle appear (start of its recorded track) in contact with the robot, or
        # within the robot's stopping time from full speed (v_max / a_max) plus the planning
        # delay (0.1 s) before the contact (no planner could have stopped for it)?
        o = next((m for m in sc.moving_obstacles if m.name == res.collision_with), None)
        span = getattr(getattr(o, "motion", None), "span", None)
        if span is not None and res.collision_time_s is not None:
            since = res.collision_time_s - span[0]
            appeared = bool(since <= 0.1)
            appeared_late = bool(since <= sc.robot.v_max / sc.robot.a_max + 0.1)
    return {"suite": suite, "mode": mode, "planner": planner, "scenario": sc.name, "seed": seed,
            "status": res.status, "robot_caused": bool(res.collision_robot_caused),
            "collision_with": res.collision_with, "collision_time_s": res.collision_time_s,
            "appeared_in_contact": appeared, "appeared_within_stop": appeared_late,
            "min_dist": res.min_distance_to_moving_m, "discomfort": res.discomfort_time_s,
            "t_over_lb": res.time_over_lower_bound, "tracking_max_m": res.extra.get("tracking_max_m"),
            "reanchored": len(res.extra.get("reanchored_s") or ()),
            "times": list(res.planning_times_s)}


def _dynabarn(worlds: list[int]) -> list[dict[str, Any]]:
    from anyplan.experiments.dynabarn import load_worlds, world_to_scenario

    data = {w["world"]: w for w in load_worlds(SHARED / "dynabarn" / "worlds.json")}
    return [world_to_scenario(data[i]) for i in worlds]


def _crowds(windows: int) -> list[tuple[str, dict[str, Any]]]:
    from anyplan.experiments.crowds import CrowdOptions, crowd_scenarios, read_obsmat

    out = []
    for f, tag in (("eth_hotel_obsmat.txt", "crowds"), ("ucy_zara01_obsmat.txt", "crowds")):
        tr = read_obsmat(SHARED / "crowds" / f)
        scs = crowd_scenarios(tr, f.split("_obsmat")[0].replace("_", "-"))
        out += [(tag, d) for d in scs[:windows]]
    tr = read_obsmat(SHARED / "crowds" / "ucy_zara01_obsmat.txt")
    dense = crowd_scenarios(tr, "zara01", CrowdOptions(window_s=30.0, step_s=30.0, copies=10,
                                                       copy_shift_s=31.0))  # <= 200 people a window
    out += [("crowds-dense", d) for d in dense[:windows]]
    return out


def _gaps(n: int) -> list[dict[str, Any]]:
    from anyplan.experiments.gaps import gap_suite

    return [sc.to_dict() for sc in gap_suite(0, n)]


def _prediction(tracker: tuple[tuple[str, float], ...] = ()) -> str:
    from anyplan.experiments.crowds import read_obsmat
    from anyplan.experiments.prediction_eval import evaluate_prediction, trajectory_samples
    from anyplan.simulation.perception import tracking_configs

    lines = ["| scene | noise [m] | samples | ADE CV | FDE CV | ADE ours | FDE ours | coverage (all) "
             "| coverage <= 2 s | mean extra radius at 1.2 / 2.0 / 4.8 s [m] |", "|" + "---|" * 10]
    for f in ("eth_hotel", "ucy_zara01"):
        s = trajectory_samples(read_obsmat(SHARED / "crowds" / f"{f}_obsmat.txt"), stride=2)
        for noise in (0.0, 0.05):
            tc, um = tracking_configs({"sigma_m": max(noise, 0.02), **dict(tracker)}, noise)
            r = evaluate_prediction(s, noise_m=noise, seed=0, tracker=tc, uncertainty=um)
            c, e = np.array(r.coverage_by_horizon), np.array(r.mean_extra_by_horizon)
            lines.append(f"| {f} | {noise:g} | {r.samples} | {r.ade_cv:.3f} | {r.fde_cv:.3f} | "
                         f"{r.ade_imm:.3f} | {r.fde_imm:.3f} | {r.coverage:.3f} | {c[:5].mean():.3f} | "
                         f"{e[2]:.2f} / {e[4]:.2f} / {e[11]:.2f} |")
    return "\n".join(lines)


def _tracking(tracker: tuple[tuple[str, float], ...] = ()) -> str:
    """CLEAR MOT scores of the tracker on the two recorded scenes (the first 300 s of each,
    every person detected at 10 Hz with 5 cm noise, seed 0, from the scene's centre), named and
    anonymous detections, with misses and false detections, and with people hiding people
    (``occlusion: all``) (``anyplan.experiments.tracking_eval``)."""
    from anyplan.experiments.crowds import read_obsmat
    from anyplan.experiments.tracking_eval import evaluate_tracking

    rows = [("named", 1.0, 0.0, "static"), ("anonymous", 1.0, 0.0, "static"),
            ("anonymous", 0.9, 0.0, "static"), ("anonymous", 0.9, 0.5, "static"),
            ("anonymous", 0.9, 2.0, "static"), ("named", 1.0, 0.0, "all"),
            ("anonymous", 0.9, 0.5, "all")]
    lines = ["| scene | detections | detection prob. | false per frame | occlusion | people-frames | "
             "missed | false tracks | identity switches | MOTA | MOTP [m] | tracks started |",
             "|" + "---|" * 12]
    for f in ("eth_hotel", "ucy_zara01"):
        tracks = read_obsmat(SHARED / "crowds" / f"{f}_obsmat.txt")
        for assoc, prob, clutter, occ in rows:
            r = evaluate_tracking(tracks, association=assoc, detection_prob=prob,
                                  clutter_rate=clutter, occlusion=occ, tracker=dict(tracker),
                                  t_end=300.0)
            lines.append(f"| {f} | {assoc} | {prob:g} | {clutter:g} | {occ} | {r.gt} | {r.fn} | {r.fp} | "
                         f"{r.id_switches} | {r.mota:.3f} | {r.motp_m:.3f} | {r.started} |")
    return "\n".join(lines)


def _prediction_dynabarn(worlds: list[int], tracker: tuple[tuple[str, float], ...] = ()) -> str:
    """The tracker's predictions of DynaBARN's obstacles (every obstacle of ``worlds`` detected
    at 10 Hz with 5 cm noise for 30 s, seed 0; predicted every 0.2 s from 1 s on): the error of
    the predicted centre and the disc's extra radius at 0.5, 1, 2 and 3 s ahead, the share of
    true centres inside the disc, and the speed error of the estimate. The obstacles run
    straight between corners where they turn or reverse: the mean error is the corners'."""
    from anyplan.prediction.base import ConstantTwistPredictor
    from anyplan.prediction.detection import Detection
    from anyplan.prediction.tracking import Tracker
    from anyplan.simulation.perception import tracking_configs
    from anyplan.world.scenario import scenario_from_dict

    tc, um = tracking_configs(dict(tracker), 0.05)
    pred = ConstantTwistPredictor(use_announced=False)
    rng = np.random.default_rng(0)
    ahead = np.array([0.5, 1.0, 2.0, 3.0])
    err, extra, speed = [], [], []
    for d in _dynabarn(worlds):
        sc = scenario_from_dict(d, f"<{d['name']}>")
        movers = {o.name: o for o in sc.moving_obstacles}
        tr = Tracker(tc)
        for k in range(301):
            t = 0.1 * k
            z = [(o, np.asarray(o.position(t)) + rng.normal(0.0, 0.05, 2)) for o in movers.values()]
            tr.update(t, [Detection(o.name, t, float(p[0]), float(p[1]), o.radius) for o, p in z])
            if k < 10 or k % 2:
                continue
            obs = um.observations(tr.estimates(t))
            for ob, pr in zip(obs, pred.predict(obs), strict=True):
                o = movers[ob.name]
                truth = np.array([o.position(t + h) for h in ahead])
                err.append(np.hypot(*(pr.positions(t + ahead) - truth).T))
                extra.append(pr.growth.at(t + ahead) if pr.growth is not None else 0.0 * ahead)
                vel = (np.asarray(o.position(t + 0.01)) - np.asarray(o.position(t - 0.01))) / 0.02
                speed.append(math.hypot(ob.v * math.cos(ob.theta) - vel[0],
                                        ob.v * math.sin(ob.theta) - vel[1]))
    e, x, v = np.array(err), np.array(extra), np.array(speed)
    lines = ["| ahead [s] | " + " | ".join(f"{h:g}" for h in ahead) + " |", "|---|" + "---|" * 4]
    lines.append("| centre error, mean [m] | " + " | ".join(f"{a:.2f}" for a in e.mean(0)) + " |")
    lines.append("| centre error, median [m] | " + " | ".join(f"{a:.2f}" for a in np.median(e, 0))
                 + " |")
    lines.append("| extra radius, mean [m] | " + " | ".join(f"{a:.2f}" for a in x.mean(0)) + " |")
    lines.append("| inside the disc | " + " | ".join(f"{a:.3f}" for a in (e <= x).mean(0)) + " |")
    lines += ["", f"{len(v)} predictions; speed error of the estimate: median {np.median(v):.3f} "
              f"m/s, mean {v.mean():.3f} m/s, 90th percentile {np.percentile(v, 90):.3f} m/s."]
    return "\n".join(lines)


def robot_caused(r: dict[str, Any]) -> bool:
    """A run (a ``--rows`` row) that ended in a collision the robot drove into."""
    return r["status"] == "collision" and bool(r.get("robot_caused"))


def seen_in_time(r: dict[str, Any]) -> bool:
    """A robot-caused collision with an obstacle that had been there for longer than the robot
    needs to stop (``appeared_within_stop`` false or unknown): one a planner could have avoided."""
    return robot_caused(r) and r.get("appeared_within_stop") is not True


def _table(rows: list[dict[str, Any]]) -> str:
    from anyplan.experiments.significance import wilson_interval

    head = ("| suite | mode | planner | success (95 % CI) | collisions | robot-caused | robot-caused, "
            "seen in time | min distance to moving [m] | discomfort [s] | time / LB (median) | "
            "planning median / p95 [ms] | errors |")
    out = [head, "|" + "---|" * 12]
    keys = sorted({(r["suite"], r["mode"], r["planner"]) for r in rows})
    for k in keys:
        rs = [r for r in rows if (r["suite"], r["mode"], r["planner"]) == k]
        n = len(rs)
        ok = sum(r["status"] == "reached" for r in rs)
        col = sum(r["status"] == "collision" for r in rs)
        rc = sum(robot_caused(r) for r in rs)
        rc_seen = sum(seen_in_time(r) for r in rs)
        md = [r["min_dist"] for r in rs if r.get("min_dist") is not None]
        disc = [r["discomfort"] for r in rs if r.get("discomfort") is not None]
        lb = [r["t_over_lb"] for r in rs if r.get("t_over_lb") is not None and r["status"] == "reached"]
        pt = np.concatenate([np.asarray(r["times"], float) for r in rs]) * 1e3 if rs else np.zeros(0)
        err = sum(r["status"].startswith("error") for r in rs)
        succ = "{}/{} ({:.2f}-{:.2f})".format(ok, n, *wilson_interval(ok, n))
        out.append(f"| {k[0]} | {k[1]} | {k[2]} | {succ} | {col} | {rc} | {rc_seen} | "
                   f"{min(md):.3f} | {np.mean(disc):.2f} | " if md else
                   f"| {k[0]} | {k[1]} | {k[2]} | {succ} | {col} | {rc} | {rc_seen} | - | - | ")
        out[-1] += (f"{np.median(lb):.2f} | " if lb else "- | ")
        out[-1] += (f"{np.median(pt):.1f} / {np.percentile(pt, 95):.1f} | " if pt.size else "- | ")
        out[-1] += f"{err} |"
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="prediction,dynabarn,crowds,gaps")
    ap.add_argument("--modes", default="oracle,twist,tracked")
    ap.add_argument("--planners", default="st-bitstar,seq-bitstar,dovs,orca")
    ap.add_argument("--worlds", default="20-59", help="DynaBARN world indices, e.g. 20-59 or 20,25,40")
    ap.add_argument("--windows", type=int, default=100, help="crowd windows per scene (and dense)")
    ap.add_argument("--crowd-modes", default="tracked",
                    help="perception modes of the crowd windows (as imported: tracked)")
    ap.add_argument("--gaps", type=int, default=10, help="gap worlds")
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--first-seed", type=int, default=0, help="seeds first-seed .. first-seed + seeds - 1")
    ap.add_argument("--sensor-noise", type=float, default=None, metavar="M",
                    help="detection noise [m] (sigma) of every tracked run (default: the scenario's)")
    ap.add_argument("--sensor-rate", type=float, default=None, metavar="HZ",
                    help="detection rate [Hz] of every tracked run (default: the scenario's)")
    ap.add_argument("--sensor-association", default=None, metavar="KIND",
                    help="named | anonymous detections in every tracked run (as anyplan run)")
    ap.add_argument("--detection-prob", type=float, default=None, metavar="P",
                    help="probability of detecting a visible obstacle per frame (as anyplan run)")
    ap.add_argument("--clutter-rate", type=float, default=None, metavar="N",
                    help="false detections per frame, anonymous only (as anyplan run)")
    ap.add_argument("--sensor-occlusion", default=None, metavar="KIND",
                    help="static | all: what hides a moving obstacle (as anyplan run)")
    from anyplan.cli.checks import actuation_noise, localization_noise

    ap.add_argument("--actuation-noise", type=actuation_noise, default=(0.0, 0.0), metavar="SV,SW",
                    help="the robot's execution error, spreads [m/s, rad/s] (as anyplan run)")
    ap.add_argument("--localization-noise", type=localization_noise, default=(0.0, 0.0),
                    metavar="SXY,STH", help="the robot's localization error, spreads [m, rad] "
                    "(as anyplan run)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=None, help="also write the Markdown report here")
    ap.add_argument("--rows", default=None, help="also write every run's row as JSON here")
    from anyplan.agents.settings import SettingsError
    from anyplan.cli.agent_options import add_agent_options, bench_configs
    from anyplan.cli.perception_opts import add_tracker_option, tracker_settings
    from anyplan.errors import UsageError

    add_agent_options(ap, bench=True)  # --set [PLANNER:]KEY=VALUE, --deterministic (as anyplan bench)
    add_tracker_option(ap)  # --tracker KEY=VALUE (as anyplan run)
    a = ap.parse_args(argv)
    try:
        tracker = tracker_settings("unknown.py", a)
    except UsageError as exc:  # one line, exit 2
        ap.error(str(exc))
    from anyplan.agents.base import AGENTS
    from anyplan.experiments.dynabarn import parse_worlds
    from anyplan.world.sensing import DEFAULT_NOISE_M, DEFAULT_RATE_HZ, SensingError, SensingSpec

    sensing = (a.sensor_noise, a.sensor_rate, a.sensor_association, a.detection_prob,
               a.clutter_rate, a.sensor_occlusion)
    only = set(a.only.split(","))
    modes = a.modes.split(",")
    crowd_modes = a.crowd_modes.split(",")
    try:  # the scenario schema's own checks of every perception setting, before any run
        for m in modes + crowd_modes:
            SensingSpec(m, DEFAULT_NOISE_M if a.sensor_noise is None else a.sensor_noise,
                        DEFAULT_RATE_HZ if a.sensor_rate is None else a.sensor_rate,
                        a.sensor_association or "named",
                        1.0 if a.detection_prob is None else a.detection_prob,
                        0.0 if a.clutter_rate is None else a.clutter_rate,
                        a.sensor_occlusion or "static")
    except SensingError as exc:
        ap.error(str(exc))
    planners = []
    for p in a.planners.split(","):
        try:
            AGENTS.get(p)
            if p == "orca":
                import pyrvo  # noqa: F401
            planners.append(p)
        except ImportError:
            print(f"skipping {p}: not installed", file=sys.stderr)
    try:
        configs = bench_configs(a, planners)
    except SettingsError as exc:  # a bad --set: one line, exit 2, as anyplan bench
        ap.error(str(exc))
    report = [f"# benchmarks/unknown.py ({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())})",
              "", "Command: `python benchmarks/unknown.py " + " ".join(sys.argv[1:] if argv is None
                                                                     else argv) + "`", ""]
    if "prediction" in only:
        report += ["## Prediction on ETH/UCY", "", _prediction(tracker), "",
                   "## Prediction of DynaBARN's obstacles (5 cm, 10 Hz)", "",
                   _prediction_dynabarn(parse_worlds(a.worlds), tracker), ""]
        print("\n".join(report), flush=True)
    if "tracking" in only:
        report += ["## Tracking quality on ETH/UCY (CLEAR MOT)", "", _tracking(tracker), ""]
        print("\n".join(report[-4:]), flush=True)
    tasks = []
    seeds = range(a.first_seed, a.first_seed + a.seeds)
    errors = (*a.actuation_noise, *a.localization_noise)
    if "dynabarn" in only:
        for d in _dynabarn(parse_worlds(a.worlds)):
            tasks += [("dynabarn", d, p, m, s, configs[p], tracker, sensing, errors) for m in modes
                      for p in planners for s in seeds]
    if "crowds" in only:
        for tag, d in _crowds(a.windows):
            tasks += [(tag, d, p, m, s, configs[p], tracker, sensing, errors) for m in crowd_modes
                      for p in planners for s in seeds]
    if "gaps" in only:
        for d in _gaps(a.gaps):
            tasks += [("gaps", d, p, "tracked", s, configs[p], tracker, sensing, errors)
                      for p in planners for s in seeds]
    rows = []
    t0 = time.perf_counter()
    if tasks:
        with ProcessPoolExecutor(a.jobs) as ex:
            for k, r in enumerate(ex.map(_run, tasks), 1):
                rows.append(r)
                if a.out:  # partial results survive an interruption
                    Path(a.out).write_text("\n".join(report) + f"\n## Runs ({k}/{len(tasks)} done)\n\n"
                                           + _table(rows) + "\n")
                print(f"[{k}/{len(tasks)} {time.perf_counter() - t0:.0f} s] {r['suite']} {r['mode']} "
                      f"{r['planner']} {r['scenario']}: {r['status']}", file=sys.stderr, flush=True)
        tab = _table(rows)
        hits = [f"{r['suite']} {r['mode']} {r['planner']} {r['scenario']}: {r['collision_with']} at "
                f"{r['collision_time_s']:.2f} s" + (", robot-caused" if r["robot_caused"] else "")
                + (", appeared in contact" if r.get("appeared_in_contact") else
                   ", appeared within the robot's stopping time" if r.get("appeared_within_stop")
                   else "")
                for r in rows if r["status"] == "collision" and r.get("collision_time_s") is not None]
        runs = ["## Runs", "", tab, "", "Collisions: " + ("; ".join(hits) if hits else "none"), "",
                "Targets (issue 15): DynaBARN medium + hard >= 36/40 twist, >= 34/40 tracked; "
                "crowds tracked >= 95 % success and 0 robot-caused collisions; planning <= 20 ms "
                "median, <= 50 ms p95 per call with up to 60 people; ahead of dovs and orca.", ""]
        report += runs
        print("\n".join(runs))  # the table too, not only the collisions and the targets
        if a.rows:
            Path(a.rows).write_text(json.dumps([{k: (str(v) if k == "status" else v) for k, v in r.items()}
                                                for r in rows]))
    if a.out:
        Path(a.out).write_text("\n".join(report) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
