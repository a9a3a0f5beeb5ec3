"""A shipped Leaf as an rclpy node: the project's own template class behind ROS 2 topics.

What an exported ROS 2 package's node scripts run (``export ros2``): the node is named after
the Leaf (``/Team/Leader``), subscribes to its inputs' topics and ``/clock``, publishes its
outputs, and declares one ROS 2 parameter per template parameter with a descriptor (its
description, unit and range) and a set-parameters callback that refuses what the template
refuses (type, [min, max], rules between parameters).

It follows the lockstep contract of ``ros/external.py``: it steps when it holds one new
``/clock`` message and one new message on every input topic since its last step, and
publishes one message on every output. Under ``amsa-phys ros2 lockstep`` that is exactly
``amsa-phys run``; on a robot, with producers publishing at their own rates, a node steps
whenever a full set has arrived.
"""

from __future__ import annotations

import math
import sys
import time
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ...engine.timing import run_phases
from ...errors import AmsaError
from ...model.params import Param
from ...model.scenario import load_scenario
from .. import external, names
from ..graph import NodeContext
from . import env
from .spin import spin_until_shutdown


def _ros_value(value: Any) -> Any:
    """A parameter value as a ROS 2 parameter holds it (points: flat doubles)."""
    if isinstance(value, (tuple, list)):
        flat: list[float] = []
        for v in value:
            if isinstance(v, (tuple, list)):
                flat.extend(float(x) for x in v)
            else:
                flat.append(float(v))
        return flat
    return value


def _model_value(param: Param, raw: Any) -> Any:
    """A ROS 2 parameter's value as the template takes it (flat doubles: [x, y] pairs)."""
    if param.type == "points":
        seq = list(raw)
        raw = [seq[i : i + 2] for i in range(0, len(seq), 2)]
    return param.coerce(raw)


def _descriptor(param: Param) -> Any:
    from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor

    text = param.description + (f" [{param.unit}]" if param.unit else "")
    desc = ParameterDescriptor(description=text)
    if param.type == "float" and param.min is not None and param.max is not None:
        desc.floating_point_range = [
            FloatingPointRange(from_value=float(param.min), to_value=float(param.max), step=0.0)
        ]
    elif param.type == "int" and param.min is not None and param.max is not None:
        desc.integer_range = [
            IntegerRange(from_value=int(param.min), to_value=int(param.max), step=1)
        ]
    return desc


def declare(node: Any, param: Param, value: Any) -> None:
    """Declare ``param`` on ``node`` with ``value``, typed as ``describe --ros2`` lists it.

    Points are a double array even when empty (a leader without waypoints): rclpy infers a
    list's type from its items and takes an empty one for a byte array, which then refused
    the double array amsa-phys sets (``run --ros2``, ``ros2 lockstep``)."""
    if param.type != "points":
        node.declare_parameter(param.name, value, _descriptor(param))
        return
    from rclpy.parameter import Parameter

    node.declare_parameter(param.name, Parameter.Type.DOUBLE_ARRAY, _descriptor(param))
    node.set_parameters([Parameter(param.name, Parameter.Type.DOUBLE_ARRAY, value)])


def main(path: str, scenario_file: str) -> None:
    """Run the node of Leaf ``path`` of the package's scenario until shut down.

    ``step_topic``: step on the node's own trigger (``names.step_topic``: a Clock of the
    instant, published by ``ros2 lockstep`` with the inputs of each of the Leaf's steps) and
    one new message on each input, in whatever order they arrive. Without it (a robot), the
    node steps on each full set of inputs at the latest ``/clock`` (a Leaf without inputs: at
    the first ``/clock`` at or past each instant of its own grid, its phase plus a whole
    number of periods, as that instant).
    """
    rclpy = env.rclpy("node")
    from rcl_interfaces.msg import SetParametersResult
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock
    from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension

    try:
        scenario = load_scenario(Path(scenario_file))
    except AmsaError as exc:
        sys.exit(f"error: {exc}")
    world = scenario.world
    leaf = world.leaves[path]
    (wiring,) = external.describe(world, [path])
    values = external.start_values(scenario)[path]
    qos = QoSProfile(
        depth=10,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.VOLATILE,
        history=HistoryPolicy.KEEP_LAST,
    )
    types = {external.SCALAR: Float64, external.ARRAY: Float64MultiArray}
    parts = path.split(".")
    namespace = "/" + "/".join(parts[:-1])
    phase = run_phases(world, scenario.seed)[path]

    class LeafNode(Node):  # type: ignore[misc]
        """The Leaf's component, its topics and parameters."""

        def __init__(self) -> None:
            super().__init__(parts[-1], namespace=namespace)
            self.comp = leaf.template(path, dict(values))
            self.comp.initialize(NodeContext(scenario.seed, path, world))
            self.templ = {p.name: p for p in leaf.template.params}
            for name, p in self.templ.items():
                if name in values:
                    declare(self, p, _ros_value(values[name]))
            self.add_on_set_parameters_callback(self._amsa_judge)
            #: the wired inputs only, as the run's step gets them: a template tells an
            #: optional input left unwired by its absence (the IMU's pose: without it, no
            #: sideslip), and a default in its place changed what it computed
            self.inp: dict[str, Any] = {
                p.name: p.initial for p in leaf.template.inputs if p.name in leaf.inputs
            }
            self.last_out: dict[str, Any] = {}
            for w in wiring.outputs:
                init = (
                    tuple(float(world.buffers[e].initial) for e in world.arrays[w.buffer])
                    if w.buffer in world.arrays
                    else float(world.buffers[w.buffer].initial)
                )
                self.last_out[w.port] = init
            for port, buffer in leaf.inputs.items():  # its own output: the last it published
                if buffer.rpartition(".")[0] == path:
                    self.inp[port] = self.last_out.get(buffer.rpartition(".")[2], 0.0)
            self.fresh: set[str] = set()
            self.t: Fraction | None = None
            self.last_t: Fraction | None = None  # of the last step: earlier, a new run
            #: an inputless Leaf on /clock: the index of its last grid instant (a /clock
            #: from the wall clock, as on a robot, seldom falls on the instant itself)
            self.grid: int | None = None
            self.triggered = "--amsa-step" in sys.argv
            if self.triggered:
                self.create_subscription(Clock, names.step_topic(path), self._amsa_on_trigger, qos)
            else:
                self.create_subscription(Clock, names.CLOCK, self._amsa_on_clock, qos)
            for w in wiring.inputs:
                self.create_subscription(
                    types[w.type], w.topic, lambda m, w=w: self._amsa_on_input(w, m), qos
                )
            self.pubs = {
                w.port: (w, self.create_publisher(types[w.type], w.topic, qos))
                for w in wiring.outputs
            }
            #: whether every output's writer has matched a reader (see _amsa_wait_matched)
            self.matched = not wiring.outputs

        def _amsa_judge(self, params: list[Any]) -> Any:
            new = dict(vars(self.comp.p))
            changed = []
            try:
                for p in params:
                    if p.name not in self.templ:
                        raise ValueError(f"{p.name} is not a parameter of {path}")
                    value = _model_value(self.templ[p.name], p.value)
                    if value != new.get(p.name):
                        changed.append((p.name, value))
                    new[p.name] = value
                leaf.template.check_params(new)
            except ValueError as exc:
                return SetParametersResult(successful=False, reason=str(exc))
            for name, value in changed:
                setattr(self.comp.p, name, value)
                self.comp.on_param_change(name, value)
            return SetParametersResult(successful=True)

        def _amsa_wait_matched(self) -> None:
            """Hold the first answer until each output's writer has matched a reader, when a
            run waits for it (lockstep's own trigger, or amsa-phys's node on the graph).

            Why: a RELIABLE, VOLATILE writer never delivers a message to a reader it had not
            discovered when it wrote, and discovery is not symmetric: the run can see this
            node's writer (and step it) before this node has seen the run's reader. Under load
            the first answer was then lost, and the run waited for it in vain. Discovery runs
            on the middleware's own threads, so a wait here sees it complete. A robot's node
            (nobody to answer to) is never held."""
            self.matched = True
            if not self.triggered and external.BRIDGE_NODE not in self.get_node_names():
                return
            deadline = time.monotonic() + external.START_TIMEOUT_S
            while time.monotonic() < deadline and any(
                pub.get_subscription_count() < 1 for _, pub in self.pubs.values()
            ):
                time.sleep(0.005)

        def _amsa_on_trigger(self, msg: Any) -> None:
            self.t = Fraction(msg.clock.sec) + Fraction(msg.clock.nanosec, 1_000_000_000)
            self._amsa_maybe_step()

        def _amsa_on_clock(self, msg: Any) -> None:
            self.t = Fraction(msg.clock.sec) + Fraction(msg.clock.nanosec, 1_000_000_000)
            if not wiring.inputs:  # on its grid: at the first /clock at or past each instant
                k = math.floor((self.t - phase) * leaf.freq)
                if self.t >= phase and k != self.grid:
                    self.grid = k
                    self._amsa_step(phase + Fraction(k) / leaf.freq)
            else:
                self._amsa_maybe_step()

        def _amsa_on_input(self, w: external.Wire, msg: Any) -> None:
            if w.type == external.SCALAR:
                self.inp[w.port] = float(msg.data)
            else:
                self.inp[w.port] = np.asarray(msg.data[msg.layout.data_offset :], dtype=float)
            self.fresh.add(w.port)
            self._amsa_maybe_step()

        def _amsa_maybe_step(self) -> None:
            if self.t is None or len(self.fresh) < len(wiring.inputs):
                return
            t = self.t
            self.fresh = set()
            if self.triggered:
                self.t = None  # the next step waits for its own trigger
            self._amsa_step(t)

        def _amsa_step(self, t: Fraction) -> None:
            if self.last_t is not None and t < self.last_t:  # a new run: a fresh component
                self.comp = leaf.template(path, dict(vars(self.comp.p)))
                self.comp.initialize(NodeContext(scenario.seed, path, world))
            self.last_t = t
            out = self.comp.do_step(t, dict(self.inp)) or {}
            if not self.matched:
                self._amsa_wait_matched()
            for port, (w, pub) in self.pubs.items():
                value = out.get(port, self.last_out[port])
                self.last_out[port] = value
                if w.type == external.SCALAR:
                    pub.publish(Float64(data=float(value)))
                else:
                    data = [float(v) for v in value]
                    msg = Float64MultiArray(data=data)
                    msg.layout.dim = [
                        MultiArrayDimension(label=port, size=len(data), stride=len(data))
                    ]
                    pub.publish(msg)
            for port, buffer in leaf.inputs.items():
                if buffer.rpartition(".")[0] == path:
                    self.inp[port] = self.last_out[buffer.rpartition(".")[2]]

    rclpy.init(args=[a for a in sys.argv if a != "--amsa-step"])
    node = LeafNode()
    try:
        spin_until_shutdown(node)  # not rclpy.spin: spin.py says why
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
