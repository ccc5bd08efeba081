"""Fuzzing the scenario loader through the command line: every broken document is refused with
exit code 2 and one bounded line naming the file (and the field, where there is one); every
valid one gives a sound result or a clean refusal. Never a traceback, never a hang.

The default run tries a fast subset; ``-m slow`` tries many more examples and other planners.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzz.harness import (
    BROKEN_CLASSES,
    broken_documents,
    refusal_problem,
    run_cli,
    sound_problem,
    valid_documents,
)

FAST = settings(max_examples=30, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
SLOW = settings(max_examples=300, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def _refused(kind: str, blob: bytes, field: str | None, command: list[str]) -> None:
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "doc.yaml"
        path.write_bytes(blob)
        o = run_cli([command[0], str(path), *command[1:], *(["--out", str(Path(d) / "o")]
                                                           if command[0] == "run" else [])])
        problem = refusal_problem(o, must_name=str(path))
        assert problem is None, f"{kind}: {problem}"
        if field is not None:
            assert field in o.err, f"{kind}: the line does not name field {field}: {o.err[:300]!r}"


RUN = ["run", "--planner", "straight", "--no-plot"]
PLAN = ["plan", "--planner", "visgraph"]


@pytest.mark.filterwarnings("error::RuntimeWarning")
@FAST
@given(case=broken_documents())
def test_broken_documents_are_refused_by_run(case):
    _refused(*case, RUN)


@pytest.mark.filterwarnings("error::RuntimeWarning")
@settings(FAST, max_examples=25)
@given(case=broken_documents())
def test_broken_documents_are_refused_by_plan(case):
    _refused(*case, PLAN)


@pytest.mark.parametrize("kind", BROKEN_CLASSES)
def test_each_broken_class_is_refused_once(kind):
    """One example of every class in the default run, whatever hypothesis draws above."""
    @settings(FAST, max_examples=2)
    @given(case=broken_documents(kind))
    def check(case):
        _refused(*case, RUN)

    check()


@pytest.mark.filterwarnings("error::RuntimeWarning")
@FAST
@given(doc=valid_documents())
def test_valid_documents_give_a_sound_result(doc):
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "doc.yaml"
        path.write_text(yaml.safe_dump(doc, allow_unicode=True))
        out = Path(d) / "o"
        o = run_cli(["run", str(path), "--planner", "straight", "--no-plot", "--out", str(out)])
        problem = sound_problem(o, out / "result.json", doc["time_limit"])
        assert problem is None, problem


@pytest.mark.slow
@pytest.mark.filterwarnings("error::RuntimeWarning")
@SLOW
@given(case=broken_documents(), cmd=st.sampled_from([RUN, PLAN]))
def test_many_broken_documents_are_refused(case, cmd):
    _refused(*case, cmd)


@pytest.mark.slow
@pytest.mark.filterwarnings("error::RuntimeWarning")
@settings(SLOW, max_examples=40)
@given(doc=valid_documents(max_time_limit=4.0), planner=st.sampled_from(["dovs", "seq-bitstar", "bitstar"]))
def test_valid_documents_give_a_sound_result_with_every_planner(doc, planner):
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "doc.yaml"
        path.write_text(yaml.safe_dump(doc, allow_unicode=True))
        out = Path(d) / "o"
        o = run_cli(["run", str(path), "--planner", planner, "--no-plot", "--out", str(out)], timeout_s=300)
        o.err = "".join(ln + "\n" for ln in o.err.splitlines() if "kernels" not in ln)  # warm-up notices
        problem = sound_problem(o, out / "result.json", doc["time_limit"])
        assert problem is None, problem
