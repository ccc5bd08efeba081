"""``anyplan import-crowd``: ETH/UCY obsmat recordings to scenario YAML files."""

from __future__ import annotations

import argparse

from anyplan.errors import UsageError


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``import-crowd`` sub-command."""
    from anyplan.experiments.crowds import SERVICE_ROBOT, CrowdOptions

    d = CrowdOptions()
    p = sub.add_parser(
        "import-crowd", help="convert a recorded pedestrian crowd (ETH/UCY obsmat) into scenarios",
        description="Cut an ETH/UCY obsmat recording into time windows, each a scenario in which "
        "a service robot crosses the scene among the replayed people (discs of 0.25 m on 'track' "
        "motions), with 'sensing: {mode: tracked}'. See anyplan.experiments.crowds.")
    p.add_argument("file", help="obsmat file (frame person x z y vx vz vy per row)")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--name", default=None, help="scenario name prefix, a plain file-name stem "
                   "(letters, digits, ._+-; default: from the file name)")
    p.add_argument("--window", type=float, default=d.window_s,
                   help=f"window length [s] (default {d.window_s:g})")
    p.add_argument("--step", type=float, default=d.step_s,
                   help=f"window start spacing [s] (default {d.step_s:g}; at most 1000 windows)")
    p.add_argument("--copies", type=int, default=d.copies,
                   help="overlay this many time-shifted copies of the recording (denser crowds; 1-100; "
                        "default 1)")
    p.add_argument("--copy-shift", type=float, default=d.copy_shift_s,
                   help=f"time shift [s] between copies, > 0 (default {d.copy_shift_s:g})")
    p.add_argument("--margin", type=float, default=d.margin_m,
                   help=f"arena margin around the recorded positions [m] (default {d.margin_m:g})")
    p.add_argument("--edge", type=float, default=d.edge_m,
                   help=f"start and goal distance from the arena's ends [m] (default {d.edge_m:g})")
    p.add_argument("--sensing-range", type=float, default=d.sensing_range_m,
                   help=f"robot sensing range [m] (default {d.sensing_range_m:g})")
    p.add_argument("--sensor-noise", type=float, default=d.noise_m, metavar="M",
                   help=f"tracked sensing noise [m] (default {d.noise_m:g})")
    p.add_argument("--sensor-rate", type=float, default=d.rate_hz, metavar="HZ",
                   help=f"tracked sensing rate [Hz] (default {d.rate_hz:g})")
    units = {"radius": "m", "v_max": "m/s", "omega_max": "rad/s", "a_max": "m/s^2",
             "alpha_max": "rad/s^2", "goal_tolerance": "m"}
    for key, val in SERVICE_ROBOT.items():
        p.add_argument(f"--robot-{key.replace('_', '-')}", type=float, default=val, dest=f"robot_{key}",
                       help=f"robot {key}" + (f" [{units[key]}]" if key in units else "")
                       + f" (default {val:g})")
    p.set_defaults(func=cmd_import_crowd)


def cmd_import_crowd(args: argparse.Namespace) -> int:
    """Convert and write the windows."""
    from anyplan.experiments.crowds import SERVICE_ROBOT, CrowdOptions, import_crowd

    opt = CrowdOptions(window_s=args.window, step_s=args.step, margin_m=args.margin,
                       edge_m=args.edge, copies=args.copies, copy_shift_s=args.copy_shift,
                       sensing_range_m=args.sensing_range, noise_m=args.sensor_noise,
                       rate_hz=args.sensor_rate,
                       robot={k: getattr(args, f"robot_{k}") for k in SERVICE_ROBOT})
    try:
        paths = import_crowd(args.file, args.out, opt, args.name)
    except OSError as exc:
        raise UsageError(f"import-crowd: --out {args.out}: cannot write ({exc.strerror})") from None
    print(f"wrote {len(paths)} scenarios to {args.out}" +
          (f" ({paths[0].name} .. {paths[-1].name})" if paths else ""))
    return 0
