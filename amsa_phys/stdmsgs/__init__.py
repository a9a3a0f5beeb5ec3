"""Standard ROS 2 messages from an amsa-phys world: which Leaves form which message, how.

A library for any code that speaks ROS at the robot boundary (the bag writer, an exporter):
:func:`find_sources` reads a world's template declarations and links and returns every
stream of standard messages (``sensor_msgs/NavSatFix``, ``sensor_msgs/Imu``,
``nav_msgs/Odometry``, ``sensor_msgs/LaserScan``, ``sensor_msgs/JointState`` wheel commands,
the robots' poses for ``/tf``) with its topic and frames; :func:`build` makes one message
from the Data values; :func:`msgdef` gives each type's ROS 2 definition text.
"""

from .build import (
    GRAVITY,
    Context,
    build,
    fields_of,
    odom_frame,
    static_transform,
    transform,
    variance,
)
from .defs import msgdef, schema_name
from .geo import DEFAULT_ORIGIN, enu_to_geodetic, geodetic_to_enu, quaternion_yaw, yaw_quaternion
from .names import data_topic, ros_path
from .roles import ROLES, WORLD_FRAME, Role, Source, find_sources

__all__ = [
    "DEFAULT_ORIGIN",
    "GRAVITY",
    "ROLES",
    "WORLD_FRAME",
    "Context",
    "Role",
    "Source",
    "build",
    "data_topic",
    "enu_to_geodetic",
    "fields_of",
    "find_sources",
    "geodetic_to_enu",
    "msgdef",
    "odom_frame",
    "quaternion_yaw",
    "ros_path",
    "schema_name",
    "static_transform",
    "transform",
    "variance",
    "yaw_quaternion",
]
