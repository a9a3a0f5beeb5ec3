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

This module is the plan only (no rospy), so the generator and the tests read it too.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..model.rosnames import P_SIM
from ..stdmsgs import Source, find_sources
from .graph import RosGraph

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


def _buffers(src: Source) -> list[str]:
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
    available = {b for s in inbound for b in _buffers(s)}
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
