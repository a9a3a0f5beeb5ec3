"""Importing rclpy, or one line saying how to get it.

ROS 2's Python packages come either from a distribution (``source /opt/ros/jazzy/setup.bash``)
or, for tests, from the PyPI wheels in an environment of their own (``pip install
'amsa-phys[ros2]'``). They must never share an environment with ROS 1's: the message packages
have the same names (``std_msgs``, ``rosgraph_msgs``) and shadow each other.
"""

from __future__ import annotations

import os
import re
from types import ModuleType

from ...errors import ConfigError

HOW = (
    "ROS 2's rclpy is not importable here: source your ROS 2 distribution "
    "(source /opt/ros/<distro>/setup.bash) or pip install 'amsa-phys[ros2]' in a virtual "
    "environment of its own, never one with ROS 1 (docs/ros2.md)"
)


#: the largest domain FastDDS (the wheels' middleware, and ROS 2's default) can open: its
#: ports for a larger one are out of range
MAX_DOMAIN_ID = 232


def domain_problem(value: str | None) -> str | None:
    """What is wrong with ``value`` as ``ROS_DOMAIN_ID`` (None: unset, empty, or a domain).

    Why here: rcl refuses a value that is not a number with an rclpy traceback, and FastDDS
    ends the process for a domain over :data:`MAX_DOMAIN_ID` (its own log lines, exit 1, a
    half-made run directory left behind); a negative one becomes a domain nobody is in."""
    if not value:
        return None
    if re.fullmatch(r"[0-9]+", value) and int(value) <= MAX_DOMAIN_ID:
        return None
    return (
        f"ROS_DOMAIN_ID={value!r} is not a ROS 2 domain: an integer from 0 to "
        f"{MAX_DOMAIN_ID} (unset: 0)"
    )


def rclpy(key: str = "--ros2") -> ModuleType:
    """The rclpy module, or a ConfigError naming ``key`` (what asked for ROS 2): rclpy is
    missing, ROS 1's messages shadow ROS 2's, or ``ROS_DOMAIN_ID`` is no domain."""
    problem = domain_problem(os.environ.get("ROS_DOMAIN_ID"))
    if problem:
        raise ConfigError(problem, key=key)
    try:
        import rclpy as mod
        from rcl_interfaces.srv import SetParameters  # noqa: F401
        from rosgraph_msgs.msg import Clock  # noqa: F401
        from std_msgs.msg import Float64  # noqa: F401
    except ImportError as exc:
        raise ConfigError(f"{HOW} ({exc})", key=key) from None
    try:
        from rosgraph_msgs.msg import Log  # noqa: F401  ROS 1's: the wrong rosgraph_msgs
    except ImportError:
        return mod
    raise ConfigError(
        "ROS 1's message packages shadow ROS 2's in this environment (rosgraph_msgs/Log "
        "is importable): run ROS 2 from an environment of its own (docs/ros2.md)",
        key=key,
    )
