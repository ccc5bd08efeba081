"""Fuzzing harness: generated scenario documents and option values, and the checks of the promise.

The promise (README, docs/scenarios.md): bad input ends with exit code 2 and one line on stderr
naming the file and the field, never a traceback, never a hang; valid input gives a sound result.
:func:`run_cli` runs the command line in this process (``main(argv)``) under a wall-clock alarm
and classifies what happened; :func:`broken_problem` and :func:`sound_problem` state what is
wrong with an outcome (None when the promise holds). The strategies generate:

* :func:`valid_documents`: scenario dictionaries within the stated limits (they may still be
  refused, e.g. a start inside an obstacle: a clean refusal is an acceptable outcome);
* :func:`broken_documents`: YAML texts of one class each (see :data:`BROKEN_CLASSES`), every one
  of which must be refused.

Used by ``tests/fuzz/test_fuzz_*.py`` (a fast subset by default, more examples under ``-m slow``)
and by ``benchmarks/fuzz_robustness.py`` (several hundred cases per class, with counts).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import signal
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hypothesis import strategies as st

from anyplan.cli.main import main
from anyplan.world.yaml_load import dump_yaml

MAX_LINE = 420  # "anyplan: error: " + the bounded message


class Hang(Exception):
    """The command outlived its wall-clock allowance."""


@dataclass
class Outcome:
    """What one command did: exit code, stdout, stderr, and a traceback if it raised."""

    rc: int | None
    out: str
    err: str
    exc: str | None = None
    hang: bool = False


def run_cli(argv: list[str], timeout_s: float = 60.0) -> Outcome:
    """``anyplan ARGV`` in this process, stdout/stderr captured, under a SIGALRM timeout."""
    out, err = io.StringIO(), io.StringIO()

    def alarm(signum: int, frame: Any) -> None:
        raise Hang()

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout_s)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                rc = main(argv)
            except SystemExit as e:  # argparse's errors
                rc = e.code if isinstance(e.code, int) else 2
        return Outcome(rc, out.getvalue(), err.getvalue())
    except Hang:
        return Outcome(None, out.getvalue(), err.getvalue(), hang=True)
    except BaseException:  # noqa: BLE001 - a traceback is what we are looking for
        return Outcome(None, out.getvalue(), err.getvalue(), exc=traceback.format_exc(limit=8))
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def refusal_problem(o: Outcome, must_name: str | None = None) -> str | None:
    """Why ``o`` is not a clean refusal (exit 2, one bounded ``anyplan: error:`` line), or None."""
    if o.hang:
        return "hang"
    if o.exc is not None:
        return "traceback: " + o.exc.strip().splitlines()[-1][:200]
    if o.rc != 2:
        return f"exit code {o.rc}, expected 2"
    lines = o.err.splitlines()
    if len(lines) != 1 or not o.err.endswith("\n"):
        return f"{len(lines)} lines on stderr, expected 1: {o.err[:300]!r}"
    line = lines[0]
    if not line.startswith("anyplan: error:"):
        return f"stderr does not start with 'anyplan: error:': {line[:200]!r}"
    if len(line) > MAX_LINE:
        return f"line of {len(line)} characters"
    if must_name is not None and must_name not in line:
        return f"the line does not name {must_name!r}: {line[:200]!r}"
    return None


# ------------------------------------------------------------------------------ documents
def _f(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


@st.composite
def valid_documents(draw: st.DrawFn, max_time_limit: float = 8.0) -> dict[str, Any]:
    """A scenario dictionary within the stated limits (not always loadable: see module doc)."""
    w, h = draw(_f(3.0, 40.0)), draw(_f(3.0, 40.0))
    r = draw(_f(0.05, 0.6))
    r = min(r, 0.2 * min(w, h))

    def point() -> list[float]:
        return [draw(_f(r + 0.01, w - r - 0.01)), draw(_f(r + 0.01, h - r - 0.01))]

    extreme = draw(st.booleans())
    robot = {
        "start": [*point(), draw(_f(-math.pi, math.pi))], "goal": point(), "radius": r,
        "v_max": draw(_f(0.05, 100.0 if extreme else 2.0)),
        "omega_max": draw(_f(0.05, 100.0 if extreme else 2.0)),
        "a_max": draw(_f(0.05, 1000.0 if extreme else 2.0)),
        "alpha_max": draw(_f(0.05, 1000.0 if extreme else 3.0)),
    }
    if draw(st.booleans()):
        robot["goal_tolerance"] = draw(_f(0.01, 1.0))
    if draw(st.booleans()):
        robot["sensing_range"] = draw(_f(0.5, 50.0))
    statics = []
    for i in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from(["rectangle", "circle", "polygon"]))
        c = point()
        if kind == "rectangle":
            statics.append({"name": f"S{i}", "type": kind, "center": c,
                            "size": [draw(_f(0.05, 3.0)), draw(_f(0.05, 3.0))],
                            "angle": draw(_f(-7.0, 7.0))})
        elif kind == "circle":
            statics.append({"name": f"S{i}", "type": kind, "center": c, "radius": draw(_f(0.05, 2.0))})
        else:
            k = draw(st.integers(3, 6))
            rad = draw(_f(0.1, 2.0))
            pts = [[c[0] + rad * math.cos(2 * math.pi * j / k), c[1] + rad * math.sin(2 * math.pi * j / k)]
                   for j in range(k)]
            statics.append({"name": f"S{i}", "type": kind, "points": pts})
    moving = []
    for i in range(draw(st.integers(0, 3))):
        if draw(st.booleans()):
            moving.append({"name": f"D{i}", "start": [*point(), draw(_f(-math.pi, math.pi))],
                           "v": draw(_f(-2.0, 2.0)), "omega": draw(_f(-1.5, 1.5)),
                           "radius": draw(_f(0.05, 1.0)), "start_time": draw(_f(0.0, 5.0))})
        else:
            t1 = draw(_f(0.5, 10.0))
            moving.append({"name": f"D{i}", "type": "waypoints", "radius": draw(_f(0.05, 1.0)),
                           "keyframes": [[0.0, *point()], [t1, *point()],
                                         [t1 + draw(_f(0.5, 10.0)), *point()]]})
    name = st.text(st.characters(min_codepoint=33, max_codepoint=0x2FF, blacklist_categories=("Cc", "Cs")),
                   min_size=1, max_size=20)
    doc: dict[str, Any] = {"name": draw(name),
                           "time_limit": draw(_f(0.5, max_time_limit)),
                           "arena": {"width": w, "height": h}, "robot": robot,
                           "static_obstacles": statics, "dynamic_obstacles": moving}
    if draw(st.booleans()):
        doc["description"] = draw(st.text(max_size=40))
    return doc


def _numeric_paths(doc: dict[str, Any]) -> list[tuple[Any, ...]]:
    """Paths (tuples of keys/indices) of every number in ``doc``."""
    out: list[tuple[Any, ...]] = []

    def walk(obj: Any, path: tuple[Any, ...]) -> None:
        if isinstance(obj, dict):
            for k, v in obj.items():
                walk(v, (*path, k))
        elif isinstance(obj, list):
            for i, v in enumerate(obj):
                walk(v, (*path, i))
        elif isinstance(obj, int | float) and not isinstance(obj, bool):
            out.append(path)

    walk(doc, ())
    return out


def _set(doc: Any, path: tuple[Any, ...], value: Any) -> None:
    for k in path[:-1]:
        doc = doc[k]
    doc[path[-1]] = value


def _field_name(path: tuple[Any, ...]) -> str:
    s = ""
    for k in path:
        s += f"[{k}]" if isinstance(k, int) else (f".{k}" if s else str(k))
    return s


def _dump(doc: Any) -> str:
    # anyplan's dumper: a text value such as "0E0" is quoted (plain, the loader reads a number)
    return dump_yaml(doc, sort_keys=False, allow_unicode=True, width=10_000)


BAD_VALUES = ["abc", [1.0], {"a": 1}, None, True, ".inf", "-.inf", ".nan", "1e308", "-1e308", "1e999",
              "1" + "0" * 400, "-" + "9" * 350]
ROBOT_REQUIRED = ["start", "goal", "radius", "v_max", "omega_max", "a_max", "alpha_max"]
LIMITS = [  # (path, value) beyond a stated limit
    (("arena", "width"), 1e6), (("arena", "height"), 2000.0), (("time_limit",), 1e9),
    (("robot", "v_max"), 1e308), (("robot", "omega_max"), 1e5), (("robot", "a_max"), 1e308),
    (("robot", "alpha_max"), 5e3), (("robot", "radius"), 0.0), (("robot", "radius"), -1.0),
    (("robot", "radius"), 1e-9), (("robot", "goal_tolerance"), -0.1), (("robot", "sensing_range"), 1e300),
]
#: Classes of broken documents.
BROKEN_CLASSES = ["missing", "type", "huge", "limit", "unknown_key", "duplicate", "alias_bomb",
                  "deep", "description", "polygon_huge", "syntax", "not_utf8", "empty", "top_level",
                  "long_value"]


@st.composite
def broken_documents(draw: st.DrawFn, kind: str | None = None) -> tuple[str, bytes, str | None]:
    """``(class, file bytes, field the error must name or None)``: a document to be refused."""
    kind = kind or draw(st.sampled_from(BROKEN_CLASSES))
    doc = draw(valid_documents())
    field: str | None = None
    if kind == "missing":
        where = draw(st.sampled_from(["name", "arena", "robot", "arena.width", "arena.height",
                                      *[f"robot.{k}" for k in ROBOT_REQUIRED]]))
        parts = where.split(".")
        d = doc
        for p in parts[:-1]:
            d = d[p]
        del d[parts[-1]]
        field = where
        text = _dump(doc)
    elif kind in ("type", "huge"):
        paths = _numeric_paths(doc)
        path = draw(st.sampled_from(paths))
        pool = BAD_VALUES[:5] if kind == "type" else BAD_VALUES[5:]
        value = draw(st.sampled_from(pool))
        if value is None and path[-1] == "sensing_range":
            value = "abc"  # null means "not given" there (known from the start): valid
        token = "@@BAD@@"
        _set(doc, path, token if isinstance(value, str) and kind == "huge" else value)
        text = _dump(doc).replace(f"'{token}'", value) if kind == "huge" else _dump(doc)
        field = _field_name(path)
    elif kind == "limit":
        path, value = draw(st.sampled_from(LIMITS))
        _set(doc, path, value)
        field = _field_name(path)
        text = _dump(doc)
    elif kind == "unknown_key":
        key = draw(st.one_of(st.text(min_size=1, max_size=30), st.just("x\nsecond line"),
                             st.just("k" * 200_000), st.just("tab\there")))
        where = draw(st.sampled_from([(), ("robot",), ("arena",)]))
        d = doc
        for p in where:
            d = d[p]
        known = set(d) | {"description", "time_limit", "static_obstacles", "dynamic_obstacles",
                          "sensing", "goal_tolerance", "sensing_range", "<<"}
        if key in known or key.strip() in known:
            key = key + "_zz"
        d[key] = 1
        text = _dump(doc)
    elif kind == "duplicate":
        which = draw(st.sampled_from(["name", "time_limit", "robot.radius", "arena.width"]))
        text = _dump(doc)
        if which == "name":
            text += "name: other\n"
        elif which == "time_limit":
            text += "time_limit: 5.0\n"
        elif which == "robot.radius":
            text = text.replace("robot:\n", "robot:\n  radius: 5.0\n", 1)
        else:
            text = text.replace("arena:\n", "arena:\n  width: 9.0\n", 1)
        field = None
    elif kind == "alias_bomb":
        width = draw(st.integers(8, 12))
        depth = draw(st.integers(7, 9))
        lines = ["a0: &a0 [" + ", ".join(["lol"] * width) + "]"]
        for i in range(1, depth + 1):
            lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * width) + "]")
        lines.append(f"name: *a{depth}")
        text = "\n".join(lines) + "\n" + _dump({k: v for k, v in doc.items() if k != "name"})
    elif kind == "deep":
        n = draw(st.integers(51, 20_000))
        text = _dump(doc).replace("arena:", "arena: " + "[" * n + "]" * n + "\nunused_arena:", 1)
    elif kind == "description":
        doc["description"] = draw(st.sampled_from([0, [], {}, 1.5, True, [1, 2], {"a": "b"}]))
        field = "description"
        text = _dump(doc)
    elif kind == "polygon_huge":
        big = draw(st.sampled_from([1e308, -1e308, 1e300, 1e20, -5e5]))
        doc["static_obstacles"] = [{"name": "P", "type": "polygon",
                                    "points": [[big, 0.0], [0.0, big], [-big, -big]]}]
        text = _dump(doc)
        field = "static_obstacles[0].points"
    elif kind == "syntax":
        base = _dump(doc)
        cut = draw(st.integers(1, max(1, len(base) - 1)))
        text = draw(st.sampled_from([base[:cut] + "\n  - ][: {\n", "name: [unclosed\n",
                                     "\tname: tab\n", "{a: 1, a}: }\n", base + "\n...\n--- {x: 1\n",
                                     "name: x\n--- \nname: y\n", "!!python/object:os.system 1\n"]))
    elif kind == "not_utf8":
        return kind, b"name: \xff\xfe\xfa\n" + _dump(doc).encode(), None
    elif kind == "empty":
        text = draw(st.sampled_from(["", "\n", "---\n", "# only a comment\n", "~\n", "null\n"]))
    elif kind == "top_level":
        text = draw(st.sampled_from(["- 1\n- 2\n", "42\n", "just text\n", "[name, arena]\n",
                                     "'quoted'\n"]))
    elif kind == "long_value":
        doc["name"] = "n" * draw(st.sampled_from([2001, 20_001, 200_000]))
        field = "name"
        text = _dump(doc)
    else:
        raise ValueError(kind)
    return kind, text.encode("utf-8"), field


def sound_problem(o: Outcome, result_path: Path, time_limit: float | None = None) -> str | None:
    """Why ``o`` is neither a sound run result nor a clean refusal, or None."""
    if o.hang:
        return "hang"
    if o.exc is not None:
        return "traceback: " + o.exc.strip().splitlines()[-1][:200]
    if o.rc == 2:
        return refusal_problem(o)
    if o.rc not in (0, 1):
        return f"exit code {o.rc}"
    if not result_path.is_file():
        return "no result.json"
    res = json.loads(result_path.read_text())
    if res["status"] not in ("reached", "timeout", "collision", "unreachable"):
        return f"status {res['status']}"
    traj = res["trajectory"]
    if not traj or any(v is None or not math.isfinite(v) for row in traj for v in row[:6]):
        return "trajectory is empty or not finite"
    ts = [row[0] for row in traj]
    if any(b <= a for a, b in zip(ts, ts[1:], strict=False)):
        return "trajectory times do not increase"
    if time_limit is not None and ts[-1] > time_limit + res["dt_s"] + 1e-9:
        return f"ran to t = {ts[-1]} beyond the limit {time_limit}"
    if res["status"] == "collision" and not res.get("collision_with"):
        return "collision without an obstacle named"
    if res["status"] == "unreachable" and len(traj) != 1:
        return "unreachable but the robot moved"
    if "Traceback" in o.err or "Warning" in o.err:
        return f"stderr: {o.err[:200]!r}"
    return None
