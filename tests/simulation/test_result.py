"""RunResult: the status is a string enum, and from_dict reads back what to_dict writes."""

import json

from anyplan.agents.straight import StraightAgent
from anyplan.simulation import RunResult, RunStatus, simulate
from anyplan.world.scenario import load_scenario


def test_status_is_a_string_enum_and_result_json_keeps_plain_strings():
    res = simulate(load_scenario("paper-1"), StraightAgent(), seed=0)
    assert isinstance(res.status, RunStatus) and res.status == "collision"
    d = json.loads(json.dumps(res.to_dict()))
    assert d["status"] == "collision" and type(res.to_dict()["status"]) is str


def test_from_dict_round_trips_and_reads_partial_results():
    res = simulate(load_scenario("paper-1"), StraightAgent(), seed=3)
    d = json.loads(json.dumps(res.to_dict()))
    back = RunResult.from_dict({**d, "agent_name": "x"})  # unknown keys are ignored
    assert back.to_dict() == res.to_dict() and back.status is RunStatus.COLLISION
    partial = RunResult.from_dict({"status": "reached", "extra": None})
    assert partial.status is RunStatus.REACHED and partial.extra == {} and partial.trajectory == []
