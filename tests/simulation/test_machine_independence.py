"""A --deterministic run gives the same bits whatever BLAS kernel the machine selects.

numpy's ``@``, ``np.dot`` and ``np.linalg`` call OpenBLAS, which picks its kernels for the CPU
(``DYNAMIC_ARCH``); ``OPENBLAS_CORETYPE`` forces another machine's choice. Until 2026-12-05 the
IMM tracker's 2 x 2 inverses, BIT*'s ellipse rotation and a few dot products went through it,
and the same seeded DynaBARN runs differed between two machines (249 against 247 of 400
`tracked` runs reached); they are written out now (``anyplan.geometry.se2``).
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys

import numpy as np
import pytest

from anyplan.geometry.se2 import dot2, dot2_rows, transform_points
from tests.conftest import DYNABARN_WORLDS as _DYNABARN
from tests.conftest import needs_dynabarn

_RUN = """
import hashlib, sys
from anyplan.agents import AGENTS, make_agent
from anyplan.experiments.dynabarn import load_worlds, world_to_scenario
from anyplan.simulation import SimConfig, simulate
from anyplan.simulation.perception import override_sensing
from anyplan.world.scenario import scenario_from_dict
world = next(w for w in load_worlds(sys.argv[1]) if w["world"] == int(sys.argv[2]))
sc = override_sensing(scenario_from_dict(world_to_scenario(world)), sys.argv[3])
agent = make_agent("st-bitstar", **AGENTS.get("st-bitstar").deterministic_settings)
res = simulate(sc, agent, seed=0, config=SimConfig(time_limit=float(sys.argv[4])))
print(hashlib.sha256(res.trajectory_array.tobytes()).hexdigest())
"""


def _digest(world: int, mode: str, seconds: float, coretype: str | None) -> str:
    env = dict(os.environ)
    env.pop("OPENBLAS_CORETYPE", None)
    if coretype is not None:
        env["OPENBLAS_CORETYPE"] = coretype
    out = subprocess.run([sys.executable, "-c", _RUN, str(_DYNABARN), str(world), mode, str(seconds)],
                         env=env, capture_output=True, text=True, timeout=600, check=True)
    return out.stdout.strip().splitlines()[-1]


@needs_dynabarn
def test_a_tracked_run_is_the_same_with_another_machines_blas_kernels():
    # World 53, tracked, seed 0: its 30 s run gave three different trajectories under the
    # three kernels (this machine's, Prescott, Sandybridge) before the products were written out.
    digests = {ct: _digest(53, "tracked", 30.0, ct) for ct in (None, "Prescott", "Sandybridge")}
    assert len(set(digests.values())) == 1, digests


def test_written_out_products_are_the_products():
    rng = np.random.default_rng(3)
    p, m = rng.normal(size=(50, 2)), rng.normal(size=(2, 2))
    a, b = rng.normal(size=2), rng.normal(size=2)
    assert transform_points(p, m) == pytest.approx(p @ m.T, rel=1e-12, abs=1e-12)
    assert dot2(a, b) == pytest.approx(float(a @ b), rel=1e-12, abs=1e-15)
    assert dot2_rows(p, b) == pytest.approx(p @ b, rel=1e-12, abs=1e-12)
    # the order of the operations is the one written: x m00 + y m01, bit for bit
    x, y = p[:, 0], p[:, 1]
    assert np.array_equal(transform_points(p, m)[:, 0], x * m[0, 0] + y * m[0, 1])
    assert hashlib.sha256(transform_points(p, m).tobytes()).hexdigest() == hashlib.sha256(
        np.column_stack([x * m[0, 0] + y * m[0, 1], x * m[1, 0] + y * m[1, 1]]).tobytes()).hexdigest()
