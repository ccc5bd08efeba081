"""``anyplan import-barn``: BARN's static worlds to scenario YAML files."""

from __future__ import annotations

import argparse
from pathlib import Path

from anyplan.errors import UsageError


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``import-barn`` sub-command."""
    p = sub.add_parser(
        "import-barn", help="convert BARN's 300 static worlds into scenario files",
        description="Convert BARN worlds (worlds.json: static cylinders, the challenge's reference "
        "path lengths) into scenario YAML files with one static circle per cylinder, the "
        "challenge's start, goal (1 m success radius) and 100 s limit, and a Clearpath Jackal. "
        "BARN's x is shifted by +4.5 m. Also writes barn-index.json (reference lengths and, by the "
        "visibility graph, which worlds are feasible for the robot's disc), which 'anyplan bench "
        "--suite DIR' uses for its BARN table. Then e.g.: anyplan bench --suite DIR --planners "
        "seq-bitstar,bitstar --runs 1")
    p.add_argument("--worlds", default=None,
                   help="world indices, e.g. 0-299, '3,5,41' or 'all' (default: every world in "
                        "the file, 0-299 in BARN's)")
    p.add_argument("--source", default=None, metavar="FILE",
                   help="BARN worlds.json (default ../shared/benchmarks/barn/worlds.json relative "
                        "to the current folder)")
    p.add_argument("--out", required=True, help="output folder for barn-NNN.yaml")
    p.add_argument("--no-feasibility", action="store_true",
                   help="skip the visibility-graph feasibility check (faster)")
    p.set_defaults(func=cmd_import_barn)


def cmd_import_barn(args: argparse.Namespace) -> int:
    """Convert and write the selected worlds."""
    from anyplan.experiments.barn import INDEX_FILE, convert, default_source, load_index

    src = Path(args.source) if args.source else default_source()
    try:
        paths = convert(src, args.out, args.worlds, check_feasibility=not args.no_feasibility)
    except OSError as exc:
        raise UsageError(f"import-barn: --out {args.out}: cannot write ({exc.strerror})") from None
    if not paths:
        print("no worlds selected")
        return 0
    print(f"wrote {len(paths)} scenarios to {args.out} ({paths[0].name} .. {paths[-1].name}) "
          f"and {INDEX_FILE}")
    if not args.no_feasibility:
        index = load_index(args.out)
        names = {p.stem for p in paths}
        bad = sorted(n for n, e in index.items() if n in names and e.get("feasibility") != "feasible")
        print(f"feasible for the {index[paths[0].stem]['robot_radius_m']:g} m disc: "
              f"{len(names) - len(bad)}/{len(names)}" + (f"; not: {', '.join(bad)}" if bad else ""))
    return 0
