"""Perception modes: noise statistics and seeding, sensor rate, range, exact line of sight,
obstacles that exist only within their recorded span, and the override of the sensing block."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.agents.base import Agent, Observation
from anyplan.errors import ScenarioError
from anyplan.simulation import SimConfig, simulate
from anyplan.simulation.perception import Sensor, effective_sensing, override_sensing
from anyplan.world import Command, RobotState, scenario_from_dict
from anyplan.world.sensing import SensingSpec
from tests.conftest import small_scenario_dict


class Recorder(Agent):
    """Stands still and records every observation (the raw detections: no tracking front end)."""

    name = "recorder"
    handles_detections = True

    def reset(self, scenario, rng):
        self.log = []

    def act(self, obs: Observation) -> Command:
        self.log.append(obs)
        return Command(0.0, 0.0)


def _tracked(noise=0.05, rate=10.0, **kw):
    d = small_scenario_dict(**kw)
    d["sensing"] = {"mode": "tracked", "noise_m": noise, "rate_hz": rate}
    return scenario_from_dict(d)


def test_noise_is_gaussian_with_the_stated_sigma_and_seeded():
    sc = _tracked(noise=0.1, static_obstacles=[])
    robot = RobotState(1.0, 3.0, 0.0)
    truth, meas = [], []
    s = Sensor(sc, sc.sensing, seed=7)
    for i in range(4000):
        t = i * 0.1
        _, det = s.observe(t, robot)
        assert len(det) == 1 and det[0].name == "D1" and det[0].radius == 0.3
        truth.append(sc.moving_obstacles[0].position(t))
        meas.append((det[0].x, det[0].y))
    e = np.array(meas) - np.array(truth)
    n = len(e)
    # mean within 4 standard errors, variance within 4 standard errors of its estimate
    assert np.all(np.abs(e.mean(axis=0)) < 4 * 0.1 / math.sqrt(n))
    var = e.var(axis=0)
    assert np.all(np.abs(var - 0.01) < 4 * 0.01 * math.sqrt(2.0 / n))
    assert abs(np.corrcoef(e.T)[0, 1]) < 4 / math.sqrt(n)
    # the same seed gives the same noise, another seed another
    again = Sensor(sc, sc.sensing, seed=7)
    other = Sensor(sc, sc.sensing, seed=8)
    a = [again.observe(i * 0.1, robot)[1][0] for i in range(5)]
    b = [other.observe(i * 0.1, robot)[1][0] for i in range(5)]
    assert [(d.x, d.y) for d in a] == [tuple(m) for m in meas[:5]]
    assert [(d.x, d.y) for d in b] != [tuple(m) for m in meas[:5]]


def test_runs_without_a_sensor_model_record_only_their_mode():
    # oracle and twist read no noise, rate or seed: a record of them would say they applied
    for mode in ("oracle", "twist"):
        sc = override_sensing(scenario_from_dict(small_scenario_dict()), mode)
        res = simulate(sc, Recorder(), seed=3, config=SimConfig(time_limit=1.0))
        assert res.extra["perception"] == {"mode": mode}


def test_simulated_runs_record_the_noise_seed_and_repeat():
    sc = _tracked(static_obstacles=[])
    runs = []
    for _ in range(2):
        ag = Recorder()
        res = simulate(sc, ag, seed=3, config=SimConfig(time_limit=2.0))
        runs.append([(d.x, d.y) for o in ag.log for d in o.detections])
        assert res.extra["perception"]["noise_seed"][0] == 3
        assert res.extra["perception"]["mode"] == "tracked"
    assert runs[0] == runs[1] and len(runs[0]) == 20  # 10 Hz over 2 s


@pytest.mark.parametrize("rate", [10.0, 3.0, 2.5])
def test_frames_come_at_the_sensor_rate(rate):
    sc = _tracked(rate=rate, static_obstacles=[])
    ag = Recorder()
    simulate(sc, ag, seed=0, config=SimConfig(time_limit=6.0))
    times = np.array([o.t for o in ag.log if o.detections])
    assert all(not o.obstacles for o in ag.log)  # positions only: no pose/twist records
    k = np.arange(len(times))
    # each frame is the first step at or after k / rate
    assert np.all(times >= k / rate - 1e-9) and np.all(times - 0.05 < k / rate + 1e-9)
    assert len(times) == math.floor(6.0 * rate - 1e-9) + 1


def test_range_limits_detection():
    d = small_scenario_dict(static_obstacles=[])
    d["robot"]["sensing_range"] = 2.0
    d["sensing"] = {"mode": "tracked", "noise_m": 0.0}
    sc = scenario_from_dict(d)
    s = Sensor(sc, sc.sensing, 0)
    for i in range(60):
        t = 0.1 * i
        x, y = sc.moving_obstacles[0].position(t)
        _, det = s.observe(t, RobotState(4.0, 3.0, 0.0))
        assert (len(det) == 1) == (math.hypot(x - 4.0, y - 3.0) <= 2.0)
        if det:
            assert (det[0].x, det[0].y) == (x, y)  # zero noise: exact


def _segment_hits_box(a, b, lo, hi):
    """Liang-Barsky: does segment ab meet the closed axis-aligned box [lo, hi]?"""
    t0, t1 = 0.0, 1.0
    d = b - a
    for k in range(2):
        for p, q in ((-d[k], a[k] - lo[k]), (d[k], hi[k] - a[k])):
            if p == 0.0:
                if q < 0.0:
                    return False
            else:
                r = q / p
                if p < 0.0:
                    t0 = max(t0, r)
                else:
                    t1 = min(t1, r)
    return t0 <= t1


def _segment_hits_circle(a, b, c, rad):
    d = b - a
    u = np.clip(np.dot(c - a, d) / np.dot(d, d), 0.0, 1.0)
    return np.linalg.norm(a + u * d - c) <= rad


def test_line_of_sight_matches_exact_segment_tests():
    rng = np.random.default_rng(5)
    d = small_scenario_dict(static_obstacles=[
        {"name": "B", "type": "rectangle", "center": [4.0, 3.0], "size": [1.0, 2.0]},
        {"name": "C", "type": "circle", "center": [2.5, 1.5], "radius": 0.6}])
    d["sensing"] = {"mode": "tracked"}
    sc = scenario_from_dict(d)
    s = Sensor(sc, sc.sensing, 0)
    robot = RobotState(1.0, 3.0, 0.0)
    a = np.array([robot.x, robot.y])
    pts = rng.uniform([0, 0], [8, 6], size=(3000, 2))
    vis = s.visible(robot, pts)
    expect = np.array([not (_segment_hits_box(a, p, np.array([3.5, 2.0]), np.array([4.5, 4.0]))
                            or _segment_hits_circle(a, p, np.array([2.5, 1.5]), 0.6)) for p in pts])
    assert vis.sum() > 500 and (~vis).sum() > 500
    assert np.array_equal(vis, expect)


def test_occluded_obstacle_is_not_detected_until_it_comes_out():
    # D1 walks up x = 6 behind a wall at x = 4 (y in [1, 5]); the robot at (1, 3) sees it only
    # when the sight line clears the wall's corners.
    d = small_scenario_dict(static_obstacles=[
        {"name": "W", "type": "rectangle", "center": [4.0, 3.0], "size": [0.2, 4.0]}],
        dynamic_obstacles=[{"name": "D1", "start": [6.0, 0.2, 1.5708], "v": 0.5, "radius": 0.3}])
    d["sensing"] = {"mode": "tracked", "noise_m": 0.0}
    sc = scenario_from_dict(d)
    s = Sensor(sc, sc.sensing, 0)
    for i in range(110):
        t = 0.1 * i
        y = 0.2 + 0.5 * t
        _, det = s.observe(t, RobotState(1.0, 3.0, 0.0))
        # sight line from (1, 3) to (6, y) crosses x = 3.9 at 3 + (y - 3) * 2.9 / 5
        y_at_wall = 3.0 + (y - 3.0) * 2.9 / 5.0
        blocked = 1.0 <= y_at_wall <= 5.0
        if abs(abs(y_at_wall - 3.0) - 2.0) > 1e-3:  # away from the grazing instants
            assert (len(det) == 0) == blocked, t


def _track_dict(samples, name="P1"):
    return {"name": name, "type": "track", "radius": 0.25, "samples": samples}


@pytest.mark.parametrize("mode", ["oracle", "twist", "tracked"])
def test_track_obstacle_is_observed_only_within_its_span(mode):
    d = small_scenario_dict(static_obstacles=[],
                            dynamic_obstacles=[_track_dict([[1.0, 5, 1], [2.0, 5, 2], [3.0, 6, 2]])])
    d["sensing"] = {"mode": mode}
    sc = scenario_from_dict(d)
    ag = Recorder()
    simulate(sc, ag, seed=0, config=SimConfig(time_limit=4.0))
    for o in ag.log:
        seen = o.detections if mode == "tracked" else o.obstacles
        present = 1.0 - 1e-9 <= o.t <= 3.0 + 1e-9
        if mode == "tracked" and abs(round(o.t * 10) - o.t * 10) > 1e-6:
            continue  # not a sensor frame
        assert bool(seen) == present, o.t


def test_simulator_collides_with_a_track_only_while_it_exists():
    # The robot stands at (1, 3). A person's first sample is on the robot at t = 5: a clamped
    # position before it would be a collision at t = 0; it must be at 5 s. Another person ends
    # on the robot's spot at t = 1.0 minus a hair... ends 1 m away: never a collision afterwards.
    still = {"start": [1.0, 3.0, 0.0], "goal": [7.0, 3.0]}
    d = small_scenario_dict(static_obstacles=[], dynamic_obstacles=[
        _track_dict([[5.0, 1.0, 3.0], [6.0, 3.0, 3.0]], "P1"),
        _track_dict([[0.0, 6.0, 5.0], [1.0, 1.0, 4.4]], "P2")])
    d["robot"].update(still)
    sc = scenario_from_dict(d)
    res = simulate(sc, Recorder(), seed=0, config=SimConfig(time_limit=8.0))
    assert res.collision and res.collision_with == "P1"
    assert 5.0 - 1e-9 <= res.collision_time_s <= 5.05 + 1e-9
    # P2 stops 0.1 m from touching (1.4 m apart, radii 0.55); after t = 1 it no longer exists
    d["dynamic_obstacles"] = [_track_dict([[0.0, 6.0, 5.0], [1.0, 1.0, 3.6]], "P2")]
    res = simulate(scenario_from_dict(d), Recorder(), seed=0, config=SimConfig(time_limit=3.0))
    assert not res.collision


def test_override_and_defaults():
    sc = scenario_from_dict(small_scenario_dict())
    assert sc.sensing is None and effective_sensing(sc).mode == "oracle"
    assert effective_sensing(sc, announce_motions=False).mode == "twist"
    t = override_sensing(sc, "tracked", None, 5.0)
    assert t.sensing == SensingSpec("tracked", 0.05, 5.0)
    assert t.content_hash() != sc.content_hash()
    assert override_sensing(sc) is sc
    # round trip through the schema
    assert scenario_from_dict(t.to_dict()).sensing == t.sensing
    with pytest.raises(ValueError, match="noise"):
        override_sensing(sc, noise_m=-0.1)


@pytest.mark.parametrize(("block", "field"), [
    ({"mode": "radar"}, "sensing.mode"),
    ({"mode": "tracked", "noise_m": -0.1}, "sensing.noise_m"),
    ({"mode": "tracked", "rate_hz": 0}, "sensing.rate_hz"),
    ({"mode": "tracked", "noise": 0.1}, "sensing.noise"),
])
def test_bad_sensing_block_names_the_field(block, field):
    d = small_scenario_dict()
    d["sensing"] = block
    with pytest.raises(ScenarioError) as ei:
        scenario_from_dict(d, "f.yaml")
    assert ei.value.field == field and "f.yaml" in str(ei.value)



class Estimates(Recorder):
    """Records the tracker's estimates (behind the tracking front end)."""

    name = "estimates"
    handles_detections = False


def test_tracking_settings_reach_the_tracker_and_its_discs():
    from anyplan.agents.perceiving import TrackingAgent
    from anyplan.simulation.perception import tracking_configs, with_tracking

    spec = SensingSpec("tracked", 0.07, 10.0)
    ag = with_tracking(Estimates(), spec, {"q_cv": 0.01, "cap_m": 0.5})
    assert isinstance(ag, TrackingAgent)
    assert ag.tracker_config.q_cv == 0.01 and ag.tracker_config.sigma_m == 0.07
    assert ag.uncertainty.cap_m == 0.5 and ag.uncertainty.k_sigma == 2.0
    # a robot that does not know its sensor's noise may say so
    assert tracking_configs({"sigma_m": 0.1}, 0.07)[0].sigma_m == 0.1
    # other modes are not tracked, whatever the settings
    assert not isinstance(with_tracking(Estimates(), SensingSpec("twist"), {"q_cv": 0.01}),
                          TrackingAgent)


def test_tracker_settings_change_the_estimates_and_repeat():
    sc = _tracked(static_obstacles=[])

    def run(settings):
        ag = Estimates()
        res = simulate(sc, ag, seed=3,
                       config=SimConfig(time_limit=2.0, tracker=tuple(sorted(settings.items()))))
        return [(o.x, o.y, o.v) for ob in ag.log for o in ob.obstacles], res

    quiet, res = run({"q_cv": 0.001, "q_ct": 0.001})
    assert len(quiet) >= 15  # an estimate at every step after the first frame
    assert quiet == run({"q_cv": 0.001, "q_ct": 0.001})[0]  # seeded: the same estimates
    assert quiet != run({})[0]  # the process noise is the tracker's
    assert res.extra["perception"]["tracker"]["q_cv"] == 0.001
    assert res.extra["perception"]["tracker"]["sigma_m"] == sc.sensing.noise_m


def test_a_bad_tracker_setting_names_the_field():
    from anyplan.config import SettingError

    with pytest.raises(SettingError, match=r"SimConfig\.tracker: unknown tracker setting 'ksigma'"):
        SimConfig(tracker=(("ksigma", 1.0),))
    with pytest.raises(SettingError, match=r"UncertaintyModel\.cap_m: must be in \[0, 100\] m"):
        SimConfig(tracker=(("cap_m", -1.0),))


def _anonymous(prob=1.0, clutter=0.0, sensing_range=None, **kw):
    d = small_scenario_dict(**kw)
    d["dynamic_obstacles"] = [
        {"name": f"D{k}", "start": [1.5 + 1.5 * k, 0.5, 1.5708], "v": 0.2, "omega": 0.0,
         "radius": 0.2 + 0.05 * k} for k in range(4)]
    if sensing_range is not None:
        d["robot"]["sensing_range"] = sensing_range
    d["sensing"] = {"mode": "tracked", "association": "anonymous", "detection_prob": prob,
                    "clutter_rate": clutter}
    return scenario_from_dict(d)


def test_anonymous_detections_carry_no_identity_and_come_in_the_order_of_x():
    sc = _anonymous(static_obstacles=[])
    s = Sensor(sc, sc.sensing, seed=1)
    for i in range(20):
        _, det = s.observe(0.1 * i, RobotState(1.0, 3.0, 0.0))
        assert len(det) == 4 and all(d.name is None for d in det)
        assert [d.x for d in det] == sorted(d.x for d in det)
        assert sorted(d.radius for d in det) == pytest.approx([0.2, 0.25, 0.3, 0.35])


def test_detection_probability_and_clutter_rate_hold_and_repeat():
    p, rate, frames = 0.7, 1.5, 2000
    sc = _anonymous(prob=p, clutter=rate, sensing_range=3.0)
    robot = RobotState(4.0, 3.0, 0.0)
    s = Sensor(sc, sc.sensing, seed=5)
    real = false = visible = 0
    for i in range(frames):
        t = 0.1 * i
        truth = [o.position(t) for o in sc.moving_obstacles if o.motion.exists(t)]
        near = [q for q in truth if math.hypot(q[0] - 4.0, q[1] - 3.0) <= 3.0
                and s.visible(robot, np.array([q]))[0]]
        _, det = s.observe(t, robot)
        visible += len(near)
        for d in det:
            # every detection is in range and in line of sight of the robot
            assert math.hypot(d.x - 4.0, d.y - 3.0) <= 3.0 + 0.3
            # a false detection has the median radius of the obstacles (0.275 m: none's)
            is_real = abs(d.radius - s.clutter_radius) > 1e-9
            if is_real:
                assert any(math.hypot(d.x - q[0], d.y - q[1]) < 0.3 for q in near)
            real += is_real
            false += not is_real
            if not is_real:
                assert math.hypot(d.x - 4.0, d.y - 3.0) <= 3.0
                assert s.visible(robot, np.array([[d.x, d.y]]))[0]
                assert not (3.5 <= d.x <= 4.5 and 4.5 <= d.y <= 5.5)  # not inside S1
    # binomial and Poisson counts within 5 standard deviations
    assert abs(real - p * visible) < 5 * math.sqrt(visible * p * (1 - p)) + 2
    assert abs(false - rate * frames) < 5 * math.sqrt(rate * frames) + 2
    assert s.missed == visible - real and s.false_detections == false
    rec = s.record()
    assert rec["association"] == "anonymous" and rec["clutter_seed"] == [5, 0xC1A7]
    # the same seed, the same frames
    a, b = Sensor(sc, sc.sensing, seed=5), Sensor(sc, sc.sensing, seed=5)
    for i in range(30):
        assert a.observe(0.1 * i, robot) == b.observe(0.1 * i, robot)


def test_named_detections_are_unchanged_by_the_new_settings():
    sc = _tracked(static_obstacles=[])
    assert (sc.sensing.association, sc.sensing.detection_prob, sc.sensing.clutter_rate) == \
        ("named", 1.0, 0.0)
    assert "association" not in sc.sensing.to_dict()
    s = Sensor(sc, sc.sensing, seed=7)
    assert "association" not in s.record()


@pytest.mark.parametrize(("block", "field", "words"), [
    ({"association": "guess"}, "sensing.association", "unknown association 'guess'"),
    ({"detection_prob": 0.0}, "sensing.detection_prob", "> 0"),
    ({"detection_prob": 1.5}, "sensing.detection_prob", "<= 1"),
    ({"association": "anonymous", "clutter_rate": -1.0}, "sensing.clutter_rate", ">= 0"),
    ({"clutter_rate": 2.0}, "sensing.clutter_rate", "association: anonymous"),
    ({"occlusion": "people"}, "sensing.occlusion", "unknown occlusion 'people'"),
    ({"occlusion": 1}, "sensing.occlusion", "string"),
])
def test_bad_association_settings_name_the_field(block, field, words):
    d = small_scenario_dict()
    d["sensing"] = {"mode": "tracked", **block}
    with pytest.raises(ScenarioError) as ei:
        scenario_from_dict(d, "f.yaml")
    assert ei.value.field == field and "f.yaml" in str(ei.value) and words in str(ei.value)


def test_association_settings_round_trip_and_override():
    sc = _anonymous(prob=0.9, clutter=0.5)
    assert scenario_from_dict(sc.to_dict()).sensing == sc.sensing
    t = override_sensing(scenario_from_dict(small_scenario_dict()), "tracked",
                         association="anonymous", clutter_rate=2.0)
    assert (t.sensing.association, t.sensing.clutter_rate, t.sensing.detection_prob) == \
        ("anonymous", 2.0, 1.0)
    with pytest.raises(ValueError, match="anonymous"):
        override_sensing(t, association="named")  # clutter needs anonymous detections


def test_a_run_with_anonymous_detections_and_clutter_tracks_and_repeats():
    sc = _anonymous(prob=0.9, clutter=1.0, static_obstacles=[])
    runs = []
    for _ in range(2):
        ag = Estimates()
        res = simulate(sc, ag, seed=2, config=SimConfig(time_limit=4.0))
        runs.append([(o.name, o.x, o.y) for ob in ag.log for o in ob.obstacles])
        trk = res.extra["tracking"]
        assert trk["tracks"] == 4 and trk["started"] >= 4 and trk["discarded"] >= 1
        assert res.extra["perception"]["false_detections"] > 0
    assert runs[0] == runs[1]
    # the last frame's estimates: one per obstacle, each within 0.3 m of it
    last = list(ag.log[-1].obstacles)
    truth = [o.position(ag.log[-1].t) for o in sc.moving_obstacles]
    assert len(last) == 4
    assert all(min(math.hypot(o.x - q[0], o.y - q[1]) for o in last) < 0.3 for q in truth)


def test_with_occlusion_all_a_disc_hides_what_is_behind_it():
    # D0..D3 walk up x = 1.5, 3, 4.5, 6 from y = 0.5; a robot at (0, 0.5) looks along their row
    d = small_scenario_dict(static_obstacles=[])
    d["dynamic_obstacles"] = [
        {"name": f"D{k}", "start": [1.5 + 1.5 * k, 0.5, 1.5708], "v": 0.2, "omega": 0.0,
         "radius": 0.3} for k in range(4)]
    d["sensing"] = {"mode": "tracked", "occlusion": "all", "noise_m": 0.0}
    sc = scenario_from_dict(d)
    assert scenario_from_dict(sc.to_dict()).sensing == sc.sensing
    s = Sensor(sc, sc.sensing, seed=0)
    _, det = s.observe(0.0, RobotState(0.0, 0.5, 0.0))
    assert [x.name for x in det] == ["D0"]  # the first one hides the three behind it
    assert s.record()["occlusion"] == "all"
    # from beside the row every one is seen, as with static occlusion only
    _, det = s.observe(0.1, RobotState(3.75, 3.0, 0.0))
    assert sorted(x.name for x in det) == ["D0", "D1", "D2", "D3"]
    plain = override_sensing(sc, occlusion="static")
    static = Sensor(plain, plain.sensing, 0)
    _, det = static.observe(0.0, RobotState(0.0, 0.5, 0.0))
    assert len(det) == 4 and "occlusion" not in static.record()

