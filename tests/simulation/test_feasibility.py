"""The feasibility check before a run, and the bounded cost of a planner that keeps failing."""

from __future__ import annotations

from anyplan.agents import make_agent
from anyplan.cli.main import main
from anyplan.simulation import SimConfig, simulate
from anyplan.simulation.feasibility import goal_unreachable
from anyplan.world import load_scenario
from anyplan.world.scenario import scenario_from_dict


def _walled(tol: float = 0.2, wall: float = 0.4) -> dict:
    """The goal (7, 7) inside a closed square room of walls of thickness ``wall`` [m]."""
    return {"name": "room", "time_limit": 60.0, "arena": {"width": 10.0, "height": 10.0},
            "robot": {"start": [1.0, 1.0, 0.0], "goal": [7.0, 7.0], "goal_tolerance": tol, "radius": 0.3,
                      "v_max": 0.4, "omega_max": 0.4, "a_max": 0.4, "alpha_max": 1.0},
            "static_obstacles": [{"type": "rectangle", "center": [7.0, 5.5], "size": [3.4, wall]},
                                 {"type": "rectangle", "center": [7.0, 8.5], "size": [3.4, wall]},
                                 {"type": "rectangle", "center": [8.5, 7.0], "size": [wall, 3.4]},
                                 {"type": "rectangle", "center": [5.5, 7.0], "size": [wall, 3.4]}]}


def test_a_closed_room_is_proven_unreachable_and_the_run_ends_at_once():
    sc = scenario_from_dict(_walled())
    assert goal_unreachable(sc)
    res = simulate(sc, make_agent("straight"), seed=0)
    assert res.status == "unreachable" and not res.reached_goal and not res.collision
    assert len(res.trajectory) == 1 and res.planning_times_s == []


def test_the_built_in_scenarios_are_not_flagged():
    for name in ("paper-1", "paper-2", "paper-3"):
        assert not goal_unreachable(load_scenario(name))


def test_a_goal_region_through_a_wall_is_not_claimed_unreachable():
    # The goal point is enclosed, but its tolerance disc (1.4 m) crosses the 5 cm walls: a robot
    # outside might end within it, so the check claims nothing (it is conservative).
    assert goal_unreachable(scenario_from_dict(_walled(tol=0.9, wall=0.05)))  # disc inside: proven
    assert not goal_unreachable(scenario_from_dict(_walled(tol=1.4, wall=0.05)))


def test_unreachable_maps_to_exit_code_1(tmp_path, capsys):
    import yaml

    p = tmp_path / "room.yaml"
    p.write_text(yaml.safe_dump(_walled()))
    assert main(["run", str(p), "--planner", "straight", "--no-plot", "--out", str(tmp_path / "o")]) == 1
    assert "unreachable" in capsys.readouterr().out


def test_a_planner_that_keeps_failing_backs_off():
    """Without the feasibility check, Sequential BIT* fails every planning call on a closed
    room; the back-off bounds the number of calls (one per step before: 1200 in 60 s)."""
    sc = scenario_from_dict(_walled())
    res = simulate(sc, make_agent("seq-bitstar"), seed=0, config=SimConfig(check_feasibility=False))
    assert res.status == "timeout"
    n = len(res.planning_times_s)
    # Back-off dt, 2dt, 4dt, ... up to 2 s: at most log2(2 / 0.05) + 1 + 60 / 2 calls.
    assert 5 <= n <= 40, n
