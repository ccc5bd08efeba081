"""The same bench on a Dask cluster (skipped when the 'dask' extra is not installed)."""

from __future__ import annotations

import pytest

from anyplan.experiments.db import ResultsDB
from anyplan.experiments.runner import PlannerSpec, derive_seed, run_bench
from anyplan.world.scenario import load_scenario

distributed = pytest.importorskip("distributed")


@pytest.mark.filterwarnings("ignore::DeprecationWarning", "ignore::ResourceWarning",
                            "ignore::UserWarning")
def test_bench_on_a_local_dask_cluster_matches_the_local_run(tmp_path, tiny_file):
    sc = load_scenario(tiny_file)
    planners = [PlannerSpec("straight"), PlannerSpec("half-speed")]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        s = run_bench([sc], planners, 2, tmp_path / "dask.db", master_seed=9,
                      scheduler=cluster.scheduler_address, progress=False)
    assert (s.finished, s.errors) == (4, 0)
    run_bench([sc], planners, 2, tmp_path / "local.db", master_seed=9, progress=False)

    def rows(path):
        with ResultsDB(path) as db:
            return sorted((r["planner"], r["run_index"], r["seed"], r["outcome"], r["path_length"])
                          for r in db.runs())

    dask_rows = rows(tmp_path / "dask.db")
    assert dask_rows == rows(tmp_path / "local.db")
    assert {r[2] for r in dask_rows} == {derive_seed(9, 0), derive_seed(9, 1)}
