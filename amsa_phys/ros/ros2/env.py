"""Importing rclpy, or one line saying how to get it.

ROS 2's Python packages come either from a distribution (``source /opt/ros/jazzy/setup.bash``)
or, for tests, from the PyPI wheels in an environment of their own (``pip install
'amsa-phys[ros2]'``). They must never share an environment with ROS 1's: the message packages
have the same names (``std_msgs``, ``rosgraph_msgs``) and shadow each other.
"""

from __future__ import annotations

from types import ModuleType

from ...errors import ConfigError

HOW = (
    "ROS 2's rclpy is not importable here: source your ROS 2 distribution "
    "(source /opt/ros/<distro>/setup.bash) or pip install 'amsa-phys[ros2]' in a virtual "
    "environment of its own, never one with ROS 1 (docs/ros2.md)"
)


def rclpy(key: str = "--ros2") -> ModuleType:
    """The rclpy module, or a ConfigError naming ``key`` (what asked for ROS 2)."""
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
