"""Which Leaves of a scenario are a user's ROS 2 nodes, and what each one's wire looks like.

``--ros2 COMP`` (or ``ros2: [COMP]`` in a scenario) leaves the Leaf ``COMP`` to a node the
user runs: amsa-phys publishes the Leaf's inputs, waits for its outputs, and steps on. This
module is the middleware-free half of that: the names, message types, QoS and parameters of
each external Leaf, judged once (a bad name is one line, before anything starts) and read by
the rclpy runtime (``ros/ros2/bridge.py``), ``describe --ros2`` and the docs' table.

The names are the ROS 1 export's (``names.py``): the node is ``/Comp``, an input port reads
the topic of the buffer it is wired to (``/Producer/output``), an output is published on
``/Comp/output``, a parameter is the node's own ``Kv``. Scalars are ``std_msgs/msg/Float64``,
an array port ``std_msgs/msg/Float64MultiArray``; time is ``/clock``
(``rosgraph_msgs/msg/Clock``).

**Lockstep contract** (what a user's node must do): once per period of the Leaf, amsa-phys
publishes ``/clock`` (the instant), then one message on every input topic. The node steps when
it holds one new ``/clock`` message and one new message on each input topic since its last
step, and publishes exactly one message on each output topic. amsa-phys waits for all of them
(``--ros2-timeout``, :data:`DEFAULT_TIMEOUT_S`) before it goes on.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from ..model.externals import parse_list, problem, producer
from ..model.scenariospec import DEFAULT_ROS2_TIMEOUT_S, Scenario
from ..model.world import WorldSpec
from . import names

__all__ = ["describe", "parse_list", "problem", "table"]

#: Seconds of wall time amsa-phys waits for an external node's answer (and for the node to
#: appear at the start) before the run is a fault naming the node and the topic.
DEFAULT_TIMEOUT_S = DEFAULT_ROS2_TIMEOUT_S
#: Wall seconds a run waits at its start for the nodes to appear on the graph (a Python node
#: on a loaded machine takes seconds to import rclpy): at least the answer timeout.
START_TIMEOUT_S = 60.0
SCALAR = "std_msgs/msg/Float64"
ARRAY = "std_msgs/msg/Float64MultiArray"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
#: The QoS of every lockstep topic: nothing may be lost or reordered, one step at a time
#: (depth 10 leaves room for a slow subscriber's one message in flight).
DATA_QOS = "RELIABLE, VOLATILE, KEEP_LAST(10)"
#: What amsa-phys calls its own node on the ROS 2 graph.
BRIDGE_NODE = "amsa_simulator"


@dataclass(frozen=True)
class Wire:
    """One topic of an external Leaf: the port, the topic and its message type."""

    port: str
    topic: str
    type: str
    #: the trace buffer the value comes from (an input) or goes to (an output)
    buffer: str


@dataclass(frozen=True)
class ParamWire:
    """One parameter of an external Leaf, as the node must declare it."""

    name: str
    type: str  # "double", "integer", "bool", "string"
    lo: float | None
    hi: float | None


@dataclass(frozen=True)
class ExternalLeaf:
    """An external Leaf's node name, topics and parameters."""

    path: str
    node: str
    inputs: tuple[Wire, ...]
    outputs: tuple[Wire, ...]
    params: tuple[ParamWire, ...]

    @property
    def set_parameters(self) -> str:
        """The node's parameter service (``rcl_interfaces/srv/SetParameters``)."""
        return self.node + "/set_parameters"


#: a template parameter's type as a ROS 2 parameter's (an enum: its value's; points: the
#: [x, y] pairs flattened)
_PARAM_TYPES = {
    "float": "double",
    "int": "integer",
    "bool": "bool",
    "str": "string",
    "enum": "integer or string",
    "points": "double_array",
}


def describe(
    world: WorldSpec, paths: Iterable[str], private_inputs: bool = False
) -> list[ExternalLeaf]:
    """Each external Leaf's wiring, in world order (``paths`` already judged).

    ``private_inputs``: each input on a topic of the Leaf's own (``names.input_topic``)
    instead of its producer's: ``ros2 lockstep`` remaps an exported node's subscriptions
    there, so that amsa-phys delivers every input (delays included) even between two nodes.
    """
    wanted = set(paths)
    out = []
    for path, leaf in world.leaves.items():
        if path not in wanted:
            continue
        inputs = []
        for port, buffer in leaf.inputs.items():
            if producer(world, buffer) == path:
                continue  # a Leaf reading its own output keeps it: no topic
            typ = ARRAY if buffer in world.arrays else SCALAR
            where = names.input_topic(path, port) if private_inputs else names.topic(buffer)
            inputs.append(Wire(port, where, typ, buffer))
        outputs = []
        for p in leaf.template.outputs:
            buffer = f"{path}.{p.name}"
            typ = ARRAY if buffer in world.arrays else SCALAR
            outputs.append(Wire(p.name, names.topic(buffer), typ, buffer))
        params = tuple(
            ParamWire(
                p.name,
                _PARAM_TYPES.get(p.type, "double"),
                _bound(p.min),
                _bound(p.max),
            )
            for p in leaf.template.params
        )
        out.append(ExternalLeaf(path, names.ns(path), tuple(inputs), tuple(outputs), params))
    return out


def start_values(scenario: Scenario) -> dict[str, dict[str, Any]]:
    """Every Leaf's parameters at t = 0: the world's values with the scenario's ``set:``.

    What both targets' parameter files hold (ROS 1's rosparam YAML, ROS 2's
    ``ros__parameters``) and what an exported ROS 2 node declares.
    """
    values = {path: dict(leaf.params) for path, leaf in scenario.world.leaves.items()}
    for change in scenario.timeline.initial:
        values[change.leaf][change.param] = change.value
    return values


def _bound(value: object) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def table(leaves: Sequence[ExternalLeaf], timeout_s: float = DEFAULT_TIMEOUT_S) -> list[str]:
    """The lines ``describe --ros2`` prints: every topic with its type, direction and QoS."""
    lines = [
        f"ROS 2 lockstep (a node steps on one /clock and one message per input; "
        f"answers within {timeout_s:g} s)",
        f"  /clock  {CLOCK_TYPE}  published by {BRIDGE_NODE}  {DATA_QOS}",
    ]
    for leaf in leaves:
        lines.append(f"  node {leaf.node}")
        for w in leaf.inputs:
            lines.append(f"    in   {w.port:<24} {w.topic}  {w.type}  {DATA_QOS}")
        for w in leaf.outputs:
            lines.append(f"    out  {w.port:<24} {w.topic}  {w.type}  {DATA_QOS}")
        for p in leaf.params:
            lo = "-inf" if p.lo is None else f"{p.lo:g}"
            hi = "inf" if p.hi is None else f"{p.hi:g}"
            rng = "" if p.lo is None and p.hi is None else f"  [{lo}, {hi}]"
            lines.append(f"    param {p.name:<23} {p.type}{rng}  via {leaf.set_parameters}")
    return lines
