"""Stated limits of what anyplan accepts (SI units: m, s, rad).

Values outside these ranges are refused by the scenario loader and the command line with a
message that names the limit, instead of being run for hours, overflowing to ``inf`` in numpy,
or leaving the robot parked. They are generous: the paper's arenas are 15 m wide and its robot
drives at 0.4 m/s. Documented in ``docs/scenarios.md`` (section "Limits").
"""

from __future__ import annotations

__all__ = [
    "MAX_ARENA_M", "MAX_COORD_M", "MAX_SIZE_M", "ROBOT_RADIUS_M", "ROBOT_LIMITS", "MAX_OBSTACLE_SPEED",
    "MAX_OBSTACLE_TURN_RATE", "MAX_ANGLE_RAD", "MAX_TIME_LIMIT_S", "MAX_EVENT_TIME_S",
    "MAX_STATIC_OBSTACLES", "MAX_MOVING_OBSTACLES", "MAX_POLYGON_POINTS", "MAX_KEYFRAMES",
    "MIN_DT_S", "MAX_SIM_STEPS", "MAX_SEED", "MAX_TEXT_CHARS", "MAX_SENSOR_RATE_HZ",
    "MAX_IMPORT_SCENARIOS", "MAX_CROWD_COPIES", "MAX_GOAL_TOLERANCE_M",
]

#: Largest arena side [m].
MAX_ARENA_M = 1000.0
#: Largest absolute coordinate of any point (start, goal, obstacle, keyframe) [m].
MAX_COORD_M = 10_000.0
#: Largest obstacle size or radius [m].
MAX_SIZE_M = 10_000.0
#: Robot radius range [m].
ROBOT_RADIUS_M = (1e-3, 50.0)
#: Ranges of the robot's limits: v_max [m/s], omega_max [rad/s], a_max [m/s^2], alpha_max [rad/s^2].
ROBOT_LIMITS: dict[str, tuple[float, float]] = {
    "v_max": (1e-3, 100.0), "omega_max": (1e-3, 100.0),
    "a_max": (1e-3, 1000.0), "alpha_max": (1e-3, 1000.0),
}
#: Largest goal tolerance of the robot [m] (it must also be > 0).
MAX_GOAL_TOLERANCE_M = MAX_ARENA_M
#: Largest speed of a moving obstacle [m/s].
MAX_OBSTACLE_SPEED = 1000.0
#: Largest turn rate of a moving obstacle [rad/s].
MAX_OBSTACLE_TURN_RATE = 1000.0
#: Largest absolute angle (headings, rectangle angles) [rad].
MAX_ANGLE_RAD = 1000.0
#: Largest simulated time limit [s] (one hour).
MAX_TIME_LIMIT_S = 3600.0
#: Largest time of an event (an obstacle's start_time, a keyframe) [s].
MAX_EVENT_TIME_S = 1e6
#: Most static obstacles in a scenario.
MAX_STATIC_OBSTACLES = 2000
#: Most moving obstacles in a scenario.
MAX_MOVING_OBSTACLES = 200
#: Most vertices of one polygon.
MAX_POLYGON_POINTS = 1000
#: Most keyframes of one waypoint track.
MAX_KEYFRAMES = 100_000
#: Smallest simulation step [s].
MIN_DT_S = 1e-3
#: Most simulation steps of one run (time limit / dt).
MAX_SIM_STEPS = 200_000
#: Largest random seed (seeds are in [0, MAX_SEED]).
MAX_SEED = 2**63 - 1
#: Highest sensor rate [Hz].
MAX_SENSOR_RATE_HZ = 1000.0
#: Longest name or description [characters].
MAX_TEXT_CHARS = 2000
#: Most scenario files one import (``import-crowd`` windows, ``import-barn``/``import-dynabarn``
#: worlds) writes; world indices are in [0, MAX_IMPORT_SCENARIOS - 1].
MAX_IMPORT_SCENARIOS = 1000
#: Most overlaid copies of a recorded crowd (``import-crowd --copies``).
MAX_CROWD_COPIES = 100
