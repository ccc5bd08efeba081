"""Print ``name==floor`` for every dependency of pyproject.toml that has a ``>=`` floor.

The lowest-versions check (``.ci/lowest``) installs with these as pip constraints, so that the
floors pyproject.toml states are the versions tested, not guesses. Usage:
``python .ci/floors.py > floors.txt``. Reads the runtime dependencies and every extra; a
requirement without a floor, or with different floors in two extras (OMPL: one extra each for
its 1.7 and 2.x wheels), is left out (pip resolves it as usual).
"""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

_REQ = re.compile(r"^\s*([A-Za-z0-9_.\-]+)(\[[^\]]*\])?\s*(.*)$")


def floors(pyproject: Path) -> dict[str, str]:
    """Lower-cased distribution name -> its ``>=`` floor, over dependencies and extras."""
    project = tomllib.loads(pyproject.read_text())["project"]
    reqs = list(project.get("dependencies", []))
    for extra in project.get("optional-dependencies", {}).values():
        reqs.extend(extra)
    out: dict[str, str] = {}
    mixed: set[str] = set()
    for req in reqs:
        m = _REQ.match(req.split(";")[0])
        if m is None:
            raise SystemExit(f"floors: cannot read the requirement {req!r}")
        name, spec = m.group(1).lower(), m.group(3)
        lo = re.search(r">=\s*([0-9][^,\s]*)", spec)
        if lo is None:
            continue
        if out.get(name, lo.group(1)) != lo.group(1):
            mixed.add(name)
        out[name] = lo.group(1)
    return {k: v for k, v in out.items() if k not in mixed}


if __name__ == "__main__":
    root = Path(__file__).resolve().parents[1]
    for name, floor in sorted(floors(root / "pyproject.toml").items()):
        sys.stdout.write(f"{name}=={floor}\n")
