"""The robot boundary of an exported package: which standard messages, which side runs.

The AMSA data topics (``std_msgs/Float64``, one per Data buffer) are the package's inside.
A robot speaks standard types instead, so the package's ``amsa_boundary`` node
(``runtime/boundary.py``) translates at the boundary, with the streams the ``stdmsgs``
room finds from the templates' declarations (the same topics and frames as the MCAP bag):

* ``sim:=true`` (default): every stream is published from the data topics (GPS fixes as
  ``sensor_msgs/NavSatFix``, a compass as ``sensor_msgs/Imu`` orientation, odometry, IMU,
  lidar, each robot's true pose as ``nav_msgs/Odometry`` and on ``/tf``, the wheel commands
  as ``sensor_msgs/JointState``), so rviz, rqt_plot or Foxglove see the simulated robot.
* ``sim:=false``: the simulator, the scenario node and every sensor model stay off; the
  real drivers' messages on the sensor streams' topics are translated into the data topics
  the controller side reads, and the controller side's wheel commands go out as
  ``sensor_msgs/JointState``. The controller side (:func:`controller_side`) is every node
  whose inputs can all be had from those sensor streams or from other nodes of that side.

Both targets' boundary nodes (ROS 1's ``runtime/boundary.py``, ROS 2's
``ros2/robot.py``) read a driver's message with :func:`judge` here: the one mapping of a
standard message's fields to the data values, and the one judgement of what a driver may
send. This module needs no ROS (it reads fields, which ROS 1's and ROS 2's messages share),
so the generators and the tests read it too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..model.rosnames import P_SIM
from ..stdmsgs import Source, find_sources, geodetic_to_enu, quaternion_yaw
from .graph import RosGraph
from .runtime.arrays import ScanShape, fit_scan

#: Roles a robot's drivers publish (read in with ``sim:=false``); the others are the
#: simulator's own (true poses) or the controller side's (wheel commands).
SENSOR_ROLES = frozenset({"NavSatFix", "Heading", "Imu", "Odometry", "LaserScan"})

#: The launch argument and parameter that choose the side.
SIM_PARAM = P_SIM

#: The name of the boundary node.
NODE = "amsa_boundary"


@dataclass(frozen=True)
class Plan:
    """The boundary of one world: streams out and in, and the nodes of each side."""

    sources: list[Source]
    #: sensor streams a robot's drivers publish when ``sim:=false`` (read in)
    inbound: list[Source]
    #: nodes that run with ``sim:=false`` (the controller side)
    controller: list[str]
    #: nodes that run only with ``sim:=true`` (sensor models, monitors of true values)
    sim_only: list[str]


def buffers_of(src: Source) -> list[str]:
    """Every Data buffer a stream's fields read (an array field's elements, in order)."""
    out: list[str] = []
    for buf in src.buffers.values():
        out.extend(buf if isinstance(buf, tuple) else [buf])
    return out


def controller_side(graph: RosGraph, inbound: list[Source]) -> list[str]:
    """The remote Leaves that can run from the robot's sensor streams alone.

    A Leaf belongs when it is not itself a sensor stream read in, and each of its inputs is
    a field of a stream read in or an output of a Leaf that belongs (found to a fixed point).
    A Leaf reading a robot's true state (a distance monitor on ground truth) does not.
    """
    sensors = {s.leaf for s in inbound}
    available = {b for s in inbound for b in buffers_of(s)}
    # an array port read in whole (a LaserScan's ranges) is its topic's Data
    arrays = graph.world.arrays
    available.update(a for a, elements in arrays.items() if set(elements) <= available)
    side: list[str] = []
    changed = True
    while changed:
        changed = False
        for path in graph.remote:
            if path in sensors or path in side:
                continue
            if all(b in available for b in graph.input_buffers(path)):
                side.append(path)
                available.update(graph.outputs(path))
                changed = True
    return [p for p in graph.remote if p in side]


def plan(graph: RosGraph) -> Plan:
    """The boundary of ``graph``'s world."""
    sources = find_sources(graph.world)
    # a sensor stream is read in whether its Leaf is a node or steps in the simulator (a
    # Lidar casts its rays there): with sim:=false the robot's driver takes its place
    inbound = [s for s in sources if s.role.name in SENSOR_ROLES]
    controller = controller_side(graph, inbound)
    sim_only = [p for p in graph.remote if p not in controller]
    return Plan(sources, inbound, controller, sim_only)


# -- a driver's message in (sim:=false): the one mapping, and what a driver may send ---------

#: NavSatStatus.STATUS_NO_FIX: a fix the receiver says it does not have
NO_FIX = -1

#: the most ranges a driver's LaserScan may hold (720 is a common driver's; fitting costs
#: beams x ranges, so a scan of millions would stall the boundary)
MAX_SCAN_RANGES = 65_536

#: REP 145: a covariance whose first element is -1 says "this quantity is not provided"
NOT_PROVIDED = -1.0


class Refused(ValueError):
    """A driver's message the boundary will not turn into data: why, in a few words.

    Input from outside, so it is judged: a NaN reaching the controller side would reach
    the robot's wheel commands. The message is dropped; the node says why in one line.
    """


def judge(
    src: Source,
    msg: Any,
    origin: tuple[float, float],
    scan: ScanShape | None = None,
    frame: str | None = None,
) -> dict[str, Any] | None:
    """A standard message's fields as the stream's Leaf outputs them, or None for a lost
    fix (NavSatFix status NO_FIX: the GPS Leaf publishes nothing either, no fault).

    ``scan``: a lidar Leaf's declared scan, to which a LaserScan is fitted; ``frame``: the
    ``header.frame_id`` the message must carry (None: not checked). Raises :class:`Refused`
    for a message whose numbers are not finite (a NaN latitude, an infinite quaternion), a
    quantity the message says it does not provide (REP 145's covariance -1, an all-zero
    quaternion), a scan with no ranges, more than :data:`MAX_SCAN_RANGES` or a non-finite
    geometry, or another frame than ``frame``.
    """
    if frame is not None:
        got = getattr(getattr(msg, "header", None), "frame_id", None)
        if got != frame:
            raise Refused(f"frame_id {got!r}, expected {frame!r}")
    fields = _fields(src, msg, origin, scan)
    if fields is None:
        return None
    for name, value in fields.items():
        if isinstance(value, list):
            continue  # ranges: made finite by the scan's own rules
        if not math.isfinite(value):
            raise Refused(f"{name} is {value!r}")
    return fields


def read_fields(
    src: Source, msg: Any, origin: tuple[float, float], scan: ScanShape | None = None
) -> dict[str, Any] | None:
    """:func:`judge` without a frame, None for a message dropped (a lost fix or refused)."""
    try:
        return judge(src, msg, origin, scan)
    except Refused:
        return None


def _provided(msg: Any, covariance: str, what: str) -> None:
    cov = getattr(msg, covariance, None)
    if cov is not None and len(cov) and cov[0] == NOT_PROVIDED:
        raise Refused(f"{what} not provided ({covariance}[0] = -1)")


def _yaw(q: Any, what: str) -> float:
    if not all(map(math.isfinite, (q.x, q.y, q.z, q.w) if hasattr(q, "x") else (q.z, q.w))):
        raise Refused(f"{what} is not finite")
    if q.z == 0 and q.w == 0:
        raise Refused(f"{what} is not a rotation (z = w = 0)")
    return quaternion_yaw(q)


def _finite(**values: float) -> None:
    for name, value in values.items():
        if not math.isfinite(value):
            raise Refused(f"{name} is {value!r}")


def _fields(
    src: Source, msg: Any, origin: tuple[float, float], scan: ScanShape | None
) -> dict[str, Any] | None:
    role = src.role.name
    if role == "NavSatFix":
        if msg.status.status <= NO_FIX:
            return None  # a lost fix: the GPS Leaf publishes nothing either
        _finite(latitude=msg.latitude, longitude=msg.longitude)
        x, y = geodetic_to_enu(msg.latitude, msg.longitude, origin)
        return {"x": x, "y": y}
    if role == "Heading":
        _provided(msg, "orientation_covariance", "orientation")
        return {"yaw": _yaw(msg.orientation, "orientation")}
    if role == "Imu":
        _provided(msg, "angular_velocity_covariance", "angular velocity")
        _provided(msg, "linear_acceleration_covariance", "linear acceleration")
        acc = msg.linear_acceleration
        return {"gyro_z": msg.angular_velocity.z, "accel_x": acc.x, "accel_y": acc.y}
    if role == "Odometry":
        pose = msg.pose.pose
        yaw = _yaw(pose.orientation, "pose.orientation")
        return {"x": pose.position.x, "y": pose.position.y, "yaw": yaw}
    if role == "LaserScan":
        geometry = (msg.angle_min, msg.angle_increment, msg.range_min, msg.range_max)
        if not all(map(math.isfinite, geometry)):
            raise Refused("the scan's angles or range limits are not finite")
        if len(msg.ranges) > MAX_SCAN_RANGES:
            raise Refused(f"{len(msg.ranges)} ranges, at most {MAX_SCAN_RANGES}")
        if not len(msg.ranges):
            raise Refused("no ranges")
        if scan is not None:
            return {"ranges": fit_scan(msg, scan)}
        far = msg.range_max
        near = msg.range_min
        # no return (inf) and an erroneous one (NaN) read as nothing within reach; too
        # close (-inf, REP 117) as the nearest the driver measures
        return {"ranges": [max(r, near) if r <= far else far for r in msg.ranges]}
    return None
