"""Experiments: scenario suites, the parallel benchmark runner, the results database, tables.

* :mod:`~anyplan.experiments.generate`: random scenarios whose moving obstacles cross the route.
* :mod:`~anyplan.experiments.suites`: ``paper``, ``random``, ``gaps``, a folder or a list of files.
* :mod:`~anyplan.experiments.runner`: :func:`run_bench` over processes or a Dask cluster.
* :mod:`~anyplan.experiments.db`: :class:`ResultsDB`, an SQLite file in OMPL's benchmark layout.
* :mod:`~anyplan.experiments.tables`: the paper's Tables 2-3 from the database.
* :mod:`~anyplan.experiments.dynabarn`: DynaBARN worlds as scenario files.
* :mod:`~anyplan.experiments.barn`, :mod:`~anyplan.experiments.barn_tables`: BARN's static worlds
  as scenario files, their feasibility, and the BARN table.
"""

from anyplan.experiments.db import ResultsDB
from anyplan.experiments.generate import random_scenario, random_suite
from anyplan.experiments.runner import PlannerSpec, derive_seed, execute_task, run_bench
from anyplan.experiments.suites import resolve_suite
from anyplan.experiments.tables import summarize

__all__ = ["PlannerSpec", "ResultsDB", "derive_seed", "execute_task", "random_scenario", "random_suite",
           "resolve_suite", "run_bench", "summarize"]
