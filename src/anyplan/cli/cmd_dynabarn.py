"""``anyplan import-dynabarn``: DynaBARN worlds to scenario YAML files."""

from __future__ import annotations

import argparse
from pathlib import Path

from anyplan.errors import UsageError


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``import-dynabarn`` sub-command."""
    p = sub.add_parser(
        "import-dynabarn", help="convert DynaBARN worlds into scenario files",
        description="Convert DynaBARN worlds (worlds.json) into scenario YAML files with moving "
        "obstacles on looping piecewise-linear tracks and a Clearpath Jackal robot. Coordinates "
        "are shifted by (+10.5, +10.5) m; the open +x side is closed 1.5 m behind the start. "
        "Then e.g.: anyplan bench --suite DIR --planners seq-bitstar,dovs")
    p.add_argument("--worlds", default="0-19",
                   help="world indices, e.g. 0-19 (easy, default), 20-39 (medium), 40-59 (hard), "
                        "'3,5,41' or 'all'")
    p.add_argument("--worlds-file", default=None, metavar="PATH",
                   help="DynaBARN worlds.json (default ../shared/benchmarks/dynabarn/worlds.json "
                        "relative to the current folder)")
    p.add_argument("--out", required=True, help="output folder for dynabarn-NN.yaml")
    p.set_defaults(func=cmd_import_dynabarn)


def cmd_import_dynabarn(args: argparse.Namespace) -> int:
    """Convert and write the selected worlds."""
    from anyplan.experiments.dynabarn import convert, default_worlds_path

    src = Path(args.worlds_file) if args.worlds_file else default_worlds_path()
    try:
        paths = convert(src, args.out, args.worlds)
    except OSError as exc:
        raise UsageError(f"import-dynabarn: --out {args.out}: cannot write ({exc.strerror})") from None
    print(f"wrote {len(paths)} scenarios to {args.out} ({paths[0].name} .. {paths[-1].name})"
          if paths else "no worlds selected")
    return 0
