"""``anyplan run --mcap``: the run read back from the MCAP file with the ROS 2 decoder equals the
run (one pose per step at its simulation time, each plan, the obstacles, the virtual squares)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

pytest.importorskip("mcap_ros2")

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from anyplan.cli.main import main
from anyplan.experiments.mcap_log import TOPICS
from anyplan.world import load_scenario


def _read(path):
    by_topic: dict[str, list] = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            assert schema.name == TOPICS[channel.topic] and schema.encoding == "ros2msg"
            by_topic.setdefault(channel.topic, []).append((message.log_time, decoded))
    return by_topic


def _t(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def test_run_as_mcap_reads_back_equal_to_the_run(tmp_path, capsys):
    out = tmp_path / "o"
    path = tmp_path / "run.mcap"
    assert main(["run", "paper-3", "--deterministic", "--seed", "1", "--out", str(out), "--no-plot",
                 "--mcap", str(path)]) == 0
    assert str(path) in capsys.readouterr().out
    res = json.loads((out / "result.json").read_text())
    traj = np.asarray(res["trajectory"])
    msgs = _read(path)

    poses = msgs["/robot/pose"]
    assert len(poses) == len(traj) == len(msgs["/tf"]) == len(msgs["/obstacles"])
    for (log_time, m), row in zip(poses, traj, strict=True):
        assert log_time == round(row[0] * 1e9) and _t(m.header.stamp) == pytest.approx(row[0], abs=1e-9)
        assert m.header.frame_id == "map"
        assert (m.pose.position.x, m.pose.position.y) == (row[1], row[2])
        q = m.pose.orientation
        yaw = 2.0 * math.atan2(q.z, q.w)
        assert math.remainder(yaw - row[3], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    tf = msgs["/tf"][-1][1].transforms[0]
    assert tf.child_frame_id == "base_link" and tf.transform.translation.x == traj[-1, 1]

    # Each plan is a Path at its creation time, with the planned points.
    plans = msgs["/plan"]
    assert len(plans) == len(res["plans"]) >= 1
    for (_, m), p in zip(plans, res["plans"], strict=True):
        assert _t(m.header.stamp) == pytest.approx(p["t"], abs=1e-9)
        assert [[q.pose.position.x, q.pose.position.y] for q in m.poses] == p["path"]

    # Moving obstacles at every step, where the scenario puts them.
    sc = load_scenario("paper-3")
    k = len(traj) // 2
    _, mid = msgs["/obstacles"][k]
    discs = [m for m in mid.markers if m.ns == "moving" and m.action == 0]
    assert len(discs) == len(sc.moving_obstacles) == 3
    for m, o in zip(discs, sc.moving_obstacles, strict=True):
        x, y = o.motion.position(traj[k, 0])
        assert (m.pose.position.x, m.pose.position.y) == pytest.approx((x, y), abs=1e-12)
        assert m.scale.x == pytest.approx(2 * o.radius)

    # One prediction per plan (a line per visible obstacle); the virtual squares of each replanning.
    assert len(msgs["/predictions"]) == len(res["plans"])
    lines = [m for m in msgs["/predictions"][0][1].markers if m.action == 0]
    assert len(lines) == 3 and all(len(m.points) == 41 for m in lines)
    squares = [m for _, a in msgs["/virtual_obstacles"] for m in a.markers if m.action == 0]
    assert len(squares) == len(res["virtual_obstacles"]) >= 1
    for m, v in zip(squares, res["virtual_obstacles"], strict=True):
        xs = [p.x for p in m.points]
        assert max(xs) - min(xs) == pytest.approx(v["side"])
        assert np.mean(xs[:4]) == pytest.approx(v["center"][0])
    static = msgs["/map/static"]
    assert len(static) == 1 and static[0][0] == 0
    assert {m.ns for m in static[0][1].markers} >= {"walls", "static", "goal"}
    # Log times never go back.
    times = sorted(lt for v in msgs.values() for lt, _ in v)
    assert times[-1] == round(traj[-1, 0] * 1e9)


def test_bad_mcap_target_exits_2_before_the_run(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["run", "paper-1", "--planner", "straight", "--out", str(out),
                 "--mcap", str(tmp_path / "nowhere" / "x.mcap")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--mcap" in err and "does not exist" in err
    assert not (out / "result.json").exists()
