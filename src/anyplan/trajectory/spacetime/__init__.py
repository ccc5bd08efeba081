"""Space-time timing of a path: s-t obstacle maps and time-optimal velocity planning.

* :mod:`~anyplan.trajectory.spacetime.stmap`: the conservative s-t obstacle map of a path among
  predicted moving discs (radius may grow with time);
* :mod:`~anyplan.trajectory.spacetime.lattice`: the earliest acceleration-bounded motion along
  the path through that map (waiting allowed);
* :mod:`~anyplan.trajectory.spacetime.timing`: both applied to a reference motion of
  :func:`~anyplan.trajectory.plan_motion`, and the certified check of the result.
"""

from anyplan.trajectory.spacetime.lattice import VelocityPlan, edge_ok, lattice_dt, plan_velocity
from anyplan.trajectory.spacetime.stmap import RowCache, STMap, build_stmap, radii_at
from anyplan.trajectory.spacetime.timing import (
    RetimeResult,
    TimedCurveSegment,
    retime,
    speed_caps,
    verify,
)

__all__ = ["RetimeResult", "RowCache", "STMap", "TimedCurveSegment", "VelocityPlan", "build_stmap", "edge_ok",
           "lattice_dt", "plan_velocity", "radii_at", "retime", "speed_caps", "verify"]
