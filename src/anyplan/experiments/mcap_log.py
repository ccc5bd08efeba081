"""A run as an MCAP file with ROS 2 messages (``anyplan run --mcap FILE``).

For Foxglove, RViz (through ``ros2 bag play``) and rosbag tools; needs the extra
``anyplan[mcap]``. Every message is stamped with the simulation time (ns from the start of the
run); frames ``map`` (the scenario's x, y [m]) and ``base_link`` (the robot). Topics:
``/robot/pose``, ``/tf``, ``/plan``, ``/map/static``, ``/obstacles``, ``/predictions`` and
``/virtual_obstacles``.

Message types and when each topic is written: ``docs/integrations.md``, "MCAP topics".
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from anyplan.errors import AnyplanError
from anyplan.experiments.ros2_msgs import schema_text
from anyplan.geometry.shapes import Circle, Polygon
from anyplan.prediction.base import ConstantTwistPredictor
from anyplan.simulation.simulator import RunResult, observe
from anyplan.world.robot import RobotState
from anyplan.world.scenario import Scenario

__all__ = ["McapUnavailable", "McapSummary", "write_mcap", "TOPICS", "stamp"]

#: Topic -> ROS 2 message type.
TOPICS = {
    "/robot/pose": "geometry_msgs/msg/PoseStamped",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/plan": "nav_msgs/msg/Path",
    "/map/static": "visualization_msgs/msg/MarkerArray",
    "/obstacles": "visualization_msgs/msg/MarkerArray",
    "/predictions": "visualization_msgs/msg/MarkerArray",
    "/virtual_obstacles": "visualization_msgs/msg/MarkerArray",
}

FRAME = "map"
ROBOT_FRAME = "base_link"
_CYLINDER, _LINE_STRIP, _TRIANGLE_LIST, _TEXT = 3, 4, 11, 9
_DELETEALL = 3
_HEIGHT_M = 0.5  # drawn height of discs and boxes


class McapUnavailable(AnyplanError):
    """The ``mcap`` extra is not installed."""


@dataclass
class McapSummary:
    """What was written: ``path`` and the number of messages per topic."""

    path: Path
    counts: dict[str, int] = field(default_factory=dict)


def check_target(path: str | Path) -> None:
    """Fail early: the extra is missing, or ``path``'s folder does not exist.

    Raises:
        McapUnavailable: the ``mcap`` extra is missing.
        McapUnavailable: also when the folder of ``path`` does not exist.
    """
    try:
        import mcap_ros2.writer  # noqa: F401
    except ImportError:
        raise McapUnavailable.about("mcap", " needs the 'mcap' extra: pip install 'anyplan[mcap]'") from None
    folder = Path(path).parent
    if not folder.is_dir():
        raise McapUnavailable.about("mcap", f" {path}: folder {folder} does not exist")


def stamp(t: float) -> dict[str, int]:
    """``builtin_interfaces/Time`` of simulation time ``t`` [s] (t >= 0)."""
    ns = int(round(t * 1e9))
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _header(t: float, frame: str = FRAME) -> dict[str, Any]:
    return {"stamp": stamp(t), "frame_id": frame}


def _quat(yaw: float) -> dict[str, float]:
    return {"x": 0.0, "y": 0.0, "z": math.sin(0.5 * yaw), "w": math.cos(0.5 * yaw)}


def _pose(x: float, y: float, yaw: float, z: float = 0.0) -> dict[str, Any]:
    return {"position": {"x": float(x), "y": float(y), "z": z}, "orientation": _quat(yaw)}


def _color(r: float, g: float, b: float, a: float = 1.0) -> dict[str, float]:
    return {"r": r, "g": g, "b": b, "a": a}


def _marker(t: float, ns: str, mid: int, mtype: int, *, pose: dict | None = None,
            scale: tuple[float, float, float] = (1.0, 1.0, 1.0), color: dict | None = None,
            points: Iterable[tuple[float, float]] = (), text: str = "", z: float = 0.0) -> dict[str, Any]:
    return {
        "header": _header(t), "ns": ns, "id": mid, "type": mtype, "action": 0,
        "pose": pose or _pose(0.0, 0.0, 0.0),
        "scale": {"x": scale[0], "y": scale[1], "z": scale[2]},
        "color": color or _color(0.5, 0.5, 0.5),
        "lifetime": {"sec": 0, "nanosec": 0}, "frame_locked": False,
        "points": [{"x": float(x), "y": float(y), "z": z} for x, y in points],
        "colors": [], "texture_resource": "",
        "texture": {"header": _header(t), "format": "", "data": b""},
        "uv_coordinates": [], "text": text, "mesh_resource": "",
        "mesh_file": {"filename": "", "data": b""}, "mesh_use_embedded_materials": False,
    }


def _delete_all(t: float, ns: str) -> dict[str, Any]:
    m = _marker(t, ns, 0, 0)
    m["action"] = _DELETEALL
    return m


def _static_markers(scenario: Scenario) -> list[dict[str, Any]]:
    out = []
    x0, y0, x1, y1 = scenario.bounds
    out.append(_marker(0.0, "walls", 0, _LINE_STRIP, scale=(0.05, 0.0, 0.0), color=_color(0.1, 0.1, 0.1),
                       points=[(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]))
    grey = _color(0.45, 0.45, 0.5)
    for i, o in enumerate(scenario.static_obstacles):
        s = o.shape
        if isinstance(s, Circle):
            out.append(_marker(0.0, "static", i, _CYLINDER, pose=_pose(s.center[0], s.center[1], 0.0,
                                                                         0.5 * _HEIGHT_M),
                               scale=(2 * s.radius, 2 * s.radius, _HEIGHT_M), color=grey))
        elif isinstance(s, Polygon):
            v = np.asarray(s.vertices, dtype=float)
            tri = [tuple(p) for k in range(1, len(v) - 1) for p in (v[0], v[k], v[k + 1])]
            if s.is_convex:  # a fan fills a convex polygon; others get their outline only
                out.append(_marker(0.0, "static", i, _TRIANGLE_LIST, color=grey, points=tri))
            ring = [tuple(p) for p in v] + [tuple(v[0])]
            out.append(_marker(0.0, "static_outline", i, _LINE_STRIP, scale=(0.03, 0.0, 0.0),
                               color=_color(0.2, 0.2, 0.25), points=ring))
        cx, cy = np.mean(np.asarray(s.bounds).reshape(2, 2), axis=0)
        out.append(_marker(0.0, "static_names", i, _TEXT, pose=_pose(cx, cy, 0.0, _HEIGHT_M + 0.2),
                           scale=(0.0, 0.0, 0.3), color=_color(0.0, 0.0, 0.0), text=o.name))
    g = scenario.robot
    out.append(_marker(0.0, "goal", 0, _CYLINDER, pose=_pose(g.goal[0], g.goal[1], 0.0, 0.01),
                       scale=(2 * g.goal_tolerance, 2 * g.goal_tolerance, 0.02),
                       color=_color(0.1, 0.7, 0.2, 0.6)))
    return out


def _path_poses(t: float, path: np.ndarray) -> list[dict[str, Any]]:
    poses = []
    for k, (x, y) in enumerate(path):
        j = min(k, len(path) - 2)
        yaw = math.atan2(path[j + 1, 1] - path[j, 1], path[j + 1, 0] - path[j, 0]) if len(path) > 1 else 0.0
        poses.append({"header": _header(t), "pose": _pose(x, y, yaw)})
    return poses


def _state_at(traj: np.ndarray, t: float) -> RobotState:
    k = int(np.clip(np.searchsorted(traj[:, 0], t - 1e-9), 0, len(traj) - 1))
    return RobotState(*traj[k, 1:6])


def write_mcap(path: str | Path, scenario: Scenario, result: RunResult | Mapping[str, Any],
               prediction_horizon_s: float = 10.0) -> McapSummary:
    """Write ``result`` (a :class:`RunResult` or its ``result.json`` dictionary) of a run on
    ``scenario`` to the MCAP file ``path``.

    Raises:
        McapUnavailable: the ``mcap`` extra is missing.
    """
    try:
        from mcap_ros2.writer import Writer
    except ImportError:
        raise McapUnavailable.about("mcap", " needs the 'mcap' extra: pip install 'anyplan[mcap]'") from None
    res = result.to_dict() if isinstance(result, RunResult) else dict(result)
    traj = np.asarray(res["trajectory"], dtype=float).reshape(-1, 6)
    summary = McapSummary(Path(path), dict.fromkeys(TOPICS, 0))
    with open(path, "wb") as fh:
        w = Writer(fh)
        schemas = {name: w.register_msgdef(name, schema_text(name)) for name in set(TOPICS.values())}

        def put(topic: str, t: float, msg: dict[str, Any]) -> None:
            w.write_message(topic, schemas[TOPICS[topic]], msg, log_time=int(round(t * 1e9)),
                            sequence=summary.counts[topic])
            summary.counts[topic] += 1

        put("/map/static", 0.0, {"markers": _static_markers(scenario)})
        # Everything stamped at one time goes out in time order: log times never decrease.
        events: list[tuple[float, int, str, dict[str, Any]]] = []
        for t, x, y, th, _v, _w in traj:
            events.append((t, 0, "/robot/pose", {"header": _header(t), "pose": _pose(x, y, th)}))
            events.append((t, 1, "/tf", {"transforms": [{
                "header": _header(t), "child_frame_id": ROBOT_FRAME,
                "transform": {"translation": {"x": float(x), "y": float(y), "z": 0.0},
                              "rotation": _quat(th)}}]}))
            markers = [_delete_all(t, "moving")]
            for j, o in enumerate(scenario.moving_obstacles):
                if not o.motion.exists(float(t)):  # a recorded track outside its time span
                    continue
                ox, oy, oth, _, _ = o.motion.state(float(t))
                markers.append(_marker(t, "moving", j, _CYLINDER, pose=_pose(ox, oy, oth, 0.5 * _HEIGHT_M),
                                       scale=(2 * o.radius, 2 * o.radius, _HEIGHT_M),
                                       color=_color(0.85, 0.3, 0.1, 0.9)))
            r = scenario.robot.radius
            markers.append(_marker(t, "robot", 0, _CYLINDER, pose=_pose(x, y, th, 0.5 * _HEIGHT_M),
                                   scale=(2 * r, 2 * r, _HEIGHT_M), color=_color(0.1, 0.3, 0.9, 0.9)))
            events.append((t, 2, "/obstacles", {"markers": markers}))
        predictor = ConstantTwistPredictor()
        for p in res.get("plans") or []:
            t = float(p.get("t", 0.0))
            pts = np.asarray(p.get("path") or [], dtype=float).reshape(-1, 2)
            events.append((t, 3, "/plan", {"header": _header(t), "poses": _path_poses(t, pts)}))
            obs = observe(scenario, t, _state_at(traj, t))
            ts = np.linspace(t, t + prediction_horizon_s, 41)
            preds = [_delete_all(t, "predictions")]
            for j, pred in enumerate(predictor.predict(obs)):
                preds.append(_marker(t, "predictions", j, _LINE_STRIP, scale=(0.04, 0.0, 0.0),
                                     color=_color(0.9, 0.5, 0.0, 0.8),
                                     points=[tuple(q) for q in pred.positions(ts)], z=0.02))
            events.append((t, 4, "/predictions", {"markers": preds}))
        groups: dict[float, list[dict[str, Any]]] = {}
        for v in res.get("virtual_obstacles") or []:
            groups.setdefault(float(v.get("created_at_s", 0.0)), []).append(v)
        for t, squares in groups.items():
            ms = [_delete_all(t, "virtual")]
            for j, v in enumerate(squares):
                cx, cy = v["center"]
                ms.append(_marker(t, "virtual", j, _LINE_STRIP, scale=(0.04, 0.0, 0.0),
                                  color=_color(0.6, 0.0, 0.6), z=0.03,
                                  points=[(cx + a * v["side"] / 2, cy + b * v["side"] / 2)
                                          for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))]))
            events.append((t, 5, "/virtual_obstacles", {"markers": ms}))
        events.sort(key=lambda e: (e[0], e[1]))
        for t, _, topic, msg in events:
            put(topic, t, msg)
        w.finish()
    return summary
