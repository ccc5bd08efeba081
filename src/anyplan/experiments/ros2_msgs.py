"""ROS 2 message definitions (the ``.msg`` interface text) that :mod:`anyplan.experiments.mcap_log`
writes into MCAP files as ``ros2msg`` schemas.

These are the public interface definitions of ROS 2 (Humble and later) for the types a run log
uses, fields only, in the concatenated form rosbag2 stores: the type's own fields, then each type
it depends on after a line of ``=`` and a ``MSG: package/Type`` line. A reader (Foxglove, the
``mcap-ros2-support`` decoder, ``ros2 bag``) needs nothing else to decode the messages.
"""

from __future__ import annotations

__all__ = ["DEFINITIONS", "schema_text"]

_SEP = "=" * 80

#: Each type's own fields, by full ROS 2 name ``package/msg/Type``; and its dependencies.
DEFINITIONS: dict[str, tuple[str, tuple[str, ...]]] = {
    "builtin_interfaces/msg/Time": ("int32 sec\nuint32 nanosec\n", ()),
    "builtin_interfaces/msg/Duration": ("int32 sec\nuint32 nanosec\n", ()),
    "std_msgs/msg/Header": ("builtin_interfaces/Time stamp\nstring frame_id\n",
                            ("builtin_interfaces/msg/Time",)),
    "std_msgs/msg/ColorRGBA": ("float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n", ()),
    "geometry_msgs/msg/Point": ("float64 x\nfloat64 y\nfloat64 z\n", ()),
    "geometry_msgs/msg/Vector3": ("float64 x\nfloat64 y\nfloat64 z\n", ()),
    "geometry_msgs/msg/Quaternion": ("float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n", ()),
    "geometry_msgs/msg/Pose": ("Point position\nQuaternion orientation\n",
                               ("geometry_msgs/msg/Point", "geometry_msgs/msg/Quaternion")),
    "geometry_msgs/msg/PoseStamped": ("std_msgs/Header header\nPose pose\n",
                                      ("std_msgs/msg/Header", "geometry_msgs/msg/Pose")),
    "geometry_msgs/msg/Transform": ("Vector3 translation\nQuaternion rotation\n",
                                    ("geometry_msgs/msg/Vector3", "geometry_msgs/msg/Quaternion")),
    "geometry_msgs/msg/TransformStamped": (
        "std_msgs/Header header\nstring child_frame_id\nTransform transform\n",
        ("std_msgs/msg/Header", "geometry_msgs/msg/Transform")),
    "tf2_msgs/msg/TFMessage": ("geometry_msgs/TransformStamped[] transforms\n",
                               ("geometry_msgs/msg/TransformStamped",)),
    "nav_msgs/msg/Path": ("std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n",
                          ("std_msgs/msg/Header", "geometry_msgs/msg/PoseStamped")),
    "sensor_msgs/msg/CompressedImage": ("std_msgs/Header header\nstring format\nuint8[] data\n",
                                        ("std_msgs/msg/Header",)),
    "visualization_msgs/msg/UVCoordinate": ("float32 u\nfloat32 v\n", ()),
    "visualization_msgs/msg/MeshFile": ("string filename\nuint8[] data\n", ()),
    "visualization_msgs/msg/Marker": (
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n"
        "int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n"
        "int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n"
        "int32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n"
        "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
        "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
        "builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n"
        "std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\n"
        "UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\nMeshFile mesh_file\n"
        "bool mesh_use_embedded_materials\n",
        ("std_msgs/msg/Header", "geometry_msgs/msg/Pose", "geometry_msgs/msg/Vector3",
         "std_msgs/msg/ColorRGBA", "builtin_interfaces/msg/Duration", "geometry_msgs/msg/Point",
         "sensor_msgs/msg/CompressedImage", "visualization_msgs/msg/UVCoordinate",
         "visualization_msgs/msg/MeshFile")),
    "visualization_msgs/msg/MarkerArray": ("Marker[] markers\n", ("visualization_msgs/msg/Marker",)),
}


def _closure(name: str, seen: list[str]) -> None:
    for dep in DEFINITIONS[name][1]:
        if dep not in seen:
            seen.append(dep)
            _closure(dep, seen)


def schema_text(name: str) -> str:
    """The concatenated definition of ``name`` (e.g. ``"nav_msgs/msg/Path"``) with every type it
    uses, as stored in an MCAP ``ros2msg`` schema."""
    deps: list[str] = []
    _closure(name, deps)
    parts = [DEFINITIONS[name][0]]
    for d in deps:
        pkg, _, typ = d.split("/")
        parts.append(f"{_SEP}\nMSG: {pkg}/{typ}\n{DEFINITIONS[d][0]}")
    return "".join(p if p.endswith("\n") else p + "\n" for p in parts)
