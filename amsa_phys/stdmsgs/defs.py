"""ROS 2 message definitions (``.msg`` text) of the standard types amsa-phys speaks.

An MCAP file with the ``ros2msg`` schema encoding carries, for each type, its own fields
followed by every type it uses, each after a ``MSG: pkg/Type`` separator line (the text
``ros2 bag record`` stores). Each type is written once below, as in its package's ``.msg``
file (constants included: Foxglove shows them), and :func:`msgdef` assembles the full text,
dependencies in order of first use. A unit test compares every assembled text with the one
``rosbags`` generates from its own copy of ROS 2 Humble's interfaces, so a typo here fails.

Two small types are amsa-phys's own (``amsa_msgs``): ROS 2 has no stamped float
(``std_msgs/Float64`` has no header, so no plot can place it in time) and no event type.
"""

from __future__ import annotations

import re

#: type name (``pkg/Type``, without ``msg/``) -> its own fields, one per line
FIELDS: dict[str, str] = {
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Quaternion": "float64 x\nfloat64 y\nfloat64 z\nfloat64 w",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Pose": "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
    "geometry_msgs/PoseWithCovariance": "geometry_msgs/Pose pose\nfloat64[36] covariance",
    "geometry_msgs/Twist": "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
    "geometry_msgs/TwistWithCovariance": "geometry_msgs/Twist twist\nfloat64[36] covariance",
    "geometry_msgs/Transform": (
        "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation"
    ),
    "geometry_msgs/TransformStamped": (
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform"
    ),
    "tf2_msgs/TFMessage": "geometry_msgs/TransformStamped[] transforms",
    "sensor_msgs/NavSatStatus": (
        "int8 STATUS_NO_FIX=-1\nint8 STATUS_FIX=0\nint8 STATUS_SBAS_FIX=1\n"
        "int8 STATUS_GBAS_FIX=2\nuint16 SERVICE_GPS=1\nuint16 SERVICE_GLONASS=2\n"
        "uint16 SERVICE_COMPASS=4\nuint16 SERVICE_GALILEO=8\nint8 status\nuint16 service"
    ),
    "sensor_msgs/NavSatFix": (
        "uint8 COVARIANCE_TYPE_UNKNOWN=0\nuint8 COVARIANCE_TYPE_APPROXIMATED=1\n"
        "uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN=2\nuint8 COVARIANCE_TYPE_KNOWN=3\n"
        "std_msgs/Header header\nsensor_msgs/NavSatStatus status\nfloat64 latitude\n"
        "float64 longitude\nfloat64 altitude\nfloat64[9] position_covariance\n"
        "uint8 position_covariance_type"
    ),
    "sensor_msgs/Imu": (
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
        "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
        "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
        "float64[9] linear_acceleration_covariance"
    ),
    "sensor_msgs/LaserScan": (
        "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\n"
        "float32 angle_increment\nfloat32 time_increment\nfloat32 scan_time\n"
        "float32 range_min\nfloat32 range_max\nfloat32[] ranges\nfloat32[] intensities"
    ),
    "sensor_msgs/JointState": (
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
        "float64[] effort"
    ),
    "nav_msgs/Odometry": (
        "std_msgs/Header header\nstring child_frame_id\n"
        "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist"
    ),
    # amsa-phys's own: a stamped float that plots directly, and a run's events
    "amsa_msgs/Scalar": "std_msgs/Header header\nfloat64 data",
    "amsa_msgs/Event": "std_msgs/Header header\nstring kind\nstring detail",
}

#: The separator line between two types of one definition (a line of 80 ``=``).
SEPARATOR = "=" * 80

_TYPE = re.compile(r"^([A-Za-z0-9_]+/[A-Za-z0-9_]+)(\[\d*\])?\s")


def schema_name(name: str) -> str:
    """The name an MCAP ``ros2msg`` schema carries: ``sensor_msgs/msg/NavSatFix``."""
    pkg, typ = name.split("/")
    return f"{pkg}/msg/{typ}"


def _uses(name: str) -> list[str]:
    """The types ``name``'s own fields use, in field order."""
    found = []
    for line in FIELDS[name].splitlines():
        m = _TYPE.match(line)
        if m:
            found.append(m.group(1))
    return found


def msgdef(name: str) -> str:
    """The full ``ros2msg`` text of ``name`` (``pkg/Type``): its fields, then each type used.

    Dependencies are listed depth-first in order of first use, each once, as ROS 2's
    ``rosbag2`` and ``rosbags`` write them.
    """
    order: list[str] = []

    def visit(n: str) -> None:
        for dep in _uses(n):
            if dep not in order:
                order.append(dep)
                visit(dep)

    visit(name)
    parts = [FIELDS[name] + "\n"]
    parts += [f"{SEPARATOR}\nMSG: {dep}\n{FIELDS[dep]}\n" for dep in order]
    return "".join(parts)
