"""BIT* (Batch Informed Trees) for a disc robot among static obstacles in the plane.

Gammell, Srinivasa & Barfoot, "Batch Informed Trees (BIT*)", ICRA 2015,
doi:10.1109/ICRA.2015.7139620, and IJRR 39(5), 2020, doi:10.1177/0278364919890396; informed
sampling from "Informed RRT*", IROS 2014, doi:10.1109/IROS.2014.6942976.

Notation: ``g_hat``/``h_hat`` the admissible cost-to-come/-go heuristics, ``c_hat`` the edge
cost heuristic, ``g_T`` the cost-to-come in the tree, ``c_best`` the best solution cost, ``r``
(or ``k``) the connection radius of the random geometric graph. Rooms as OMPL splits BIT*:
:mod:`._queue` (search queue), :mod:`._graph` (implicit graph: samples, batches, neighbours),
:mod:`._tree` (vertices), :mod:`._search` (the compiled search), :mod:`.planner` (the planner
object), :mod:`.config`. Derivations and choices: ``docs/planning.md`` ("BIT* as implemented").
"""

from anyplan.planning.bitstar.config import BITStarConfig
from anyplan.planning.bitstar.planner import BITStar, PlannerData, warm_up

__all__ = ["BITStar", "BITStarConfig", "PlannerData", "warm_up"]
