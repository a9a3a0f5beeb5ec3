"""A user's ROS 2 nodes as Leaves of a run: inputs published, outputs awaited, on ``/clock``.

The engine runs as in ``amsa-phys run``; each external Leaf (``ros/external.py``) is built,
then passed through the ``wrap=`` hook, which puts an ``ExternalLeaf`` (``insim.py``) in its place.
Stepping it is one round trip over ROS 2: ``/clock`` at the instant, one message on every
input topic, then one message awaited on every output topic (``external.py`` states the
contract). Parameters are the node's: all of them set through its ``set_parameters``
service before the first step, and each change at the instant the scenario makes it; a
refused value ends the run.

Everything a node can do wrong ends the run with one line naming the node and the topic, a
:class:`NodeFault` (exit 2: the node under test is the user's input): no answer within the
timeout (never, or late), a non-finite value, an array of the wrong length, a publisher of
another message type on an output topic, the node gone, an answer nobody asked for. The
trace holds every instant before it.

One thread: the bridge spins its own executor only while it waits, so the callbacks run
between two engine calls and nothing is shared with another thread.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from typing import Any

from ...engine import interrupt
from ...errors import RunFault
from .. import external, names
from ..external import ExternalLeaf as Wiring
from . import env, notice

#: How long one idle wait lasts before the bridge looks at the graph (a node gone, a
#: publisher of the wrong type): a poll of the graph, not a sleep.
_LOOK_S = 0.2
#: How long a service request waits for its answer before it is sent again (``_call``).
_RESEND_S = 1.0
#: Topics every rclpy node has of its own, left out of what a node is said to use.
_ROS_OWN_TOPICS = frozenset({"/rosout", "/parameter_events"})


class NodeFault(RunFault):
    """An external node broke the lockstep contract (exit 2: the node is the user's input)."""

    exit_code = 2


class Bridge:
    """amsa-phys's node on the ROS 2 graph: ``/clock``, the external Leaves' topics, their
    parameter services, and the count of each node's steps and answers."""

    def __init__(
        self,
        leaves: Sequence[Wiring],
        timeout_s: float,
        now: Callable[[], Fraction],
        arrays: Mapping[str, Sequence[str]],
        watch: Callable[[], tuple[str, str] | None] | None = None,
        step_topics: bool = False,
    ) -> None:
        rclpy = env.rclpy()
        from rclpy.event_handler import SubscriptionEventCallbacks
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock
        from std_msgs.msg import Float64, Float64MultiArray

        self.rclpy = rclpy
        self.timeout_s = float(timeout_s)
        self._now = now
        #: says which Leaf's node cannot answer any more and why (a process amsa-phys
        #: started exited): (leaf path, why), or None
        self._watch = watch or (lambda: None)
        #: array port -> its element buffers (the length a message must have)
        self.arrays = {k: len(v) for k, v in arrays.items()}
        self.context = rclpy.Context()
        rclpy.init(args=[], context=self.context)
        self.node = rclpy.create_node(
            external.BRIDGE_NODE, context=self.context, start_parameter_services=False
        )
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        qos = QoSProfile(
            depth=10,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.VOLATILE,
            history=HistoryPolicy.KEEP_LAST,
        )
        self.qos = qos
        self.Clock = Clock
        self.types = {external.SCALAR: Float64, external.ARRAY: Float64MultiArray}
        self.clock_pub = self.node.create_publisher(Clock, "/clock", qos)
        self.last_clock: Fraction | None = None
        self.leaves = {leaf.path: leaf for leaf in leaves}
        self.pubs: dict[str, Any] = {}
        self.subs: dict[str, Any] = {}
        self.inbox: dict[str, deque[Any]] = {}
        self.clients: dict[str, Any] = {}
        #: ``step_topics``: each node's step trigger (``names.step_topic``, a Clock of the
        #: instant published after its inputs), so nodes at different rates never take
        #: another's ``/clock`` for theirs (an exported package's nodes under lockstep)
        self.step_pubs: dict[str, Any] = {}
        #: per node: steps asked, answers received (every output of a step), params set
        self.counts: dict[str, dict[str, int]] = {}
        from rcl_interfaces.srv import SetParameters

        for leaf in leaves:
            self.counts[leaf.path] = {"steps": 0, "answers": 0, "params_set": 0}
            for w in leaf.inputs:
                if w.topic not in self.pubs:
                    self.pubs[w.topic] = self.node.create_publisher(
                        self.types[w.type], w.topic, qos
                    )
            for w in leaf.outputs:
                box: deque[Any] = deque()
                self.inbox[w.topic] = box
                self.subs[w.topic] = self.node.create_subscription(
                    self.types[w.type],
                    w.topic,
                    lambda m, box=box: box.append(m),
                    qos,
                    # rclpy's own warning would be a second line: _check_qos says it
                    event_callbacks=SubscriptionEventCallbacks(incompatible_qos=_ignore),
                )
            self.clients[leaf.path] = self.node.create_client(SetParameters, leaf.set_parameters)
            if step_topics:
                self.step_pubs[leaf.path] = self.node.create_publisher(
                    Clock, names.step_topic(leaf.path), qos
                )

    # -- start ----------------------------------------------------------------------------
    def connect(self, leaf: Wiring) -> None:
        """Wait until the node listens on every input and ``/clock``, publishes every output
        and offers its parameter service (else a fault naming what is missing)."""
        wait = max(self.timeout_s, external.START_TIMEOUT_S)
        notice.waiting(leaf.node, wait)  # at once: a node that never comes is a long wait
        deadline = time.monotonic() + wait
        while True:
            missing = self._missing(leaf)
            if missing is None:
                return
            # a Ctrl-C now is the user's (the node they forgot to start, say): the run only
            # notes it (engine/interrupt.py) and nothing steps yet, so act on it here, not a
            # minute later with the start fault
            interrupt.check()
            self._check_types(leaf)
            self._check_qos(leaf)
            self._check_watch(leaf)
            if time.monotonic() >= deadline:
                hint = self._where(leaf, missing)
                raise self._fault(leaf, f"{missing} within {wait:g} s: {hint}")
            self.executor.spin_once(timeout_sec=0.05)

    def _where(self, leaf: Wiring, missing: str) -> str:
        """What to look at when the node did not connect (``missing``: what ``_missing``
        said). A node on the graph under the Leaf's name is running: what it publishes or
        subscribes to is then the lead (outputs on relative names, ``/LeftPower``, are a
        common slip), not its domain or its name."""
        ns, _, name = leaf.node.rpartition("/")
        ns = ns or "/"
        if not any((n, s) == (name, ns) for n, s in self.node.get_node_names_and_namespaces()):
            return f"is the node {leaf.node} running (ROS_DOMAIN_ID, the node's name)?"
        if missing.startswith("no publisher"):
            what, found = "publishes", self.node.get_publisher_names_and_types_by_node(name, ns)
        elif missing.startswith("no subscriber"):
            what, found = (
                "subscribes to",
                self.node.get_subscriber_names_and_types_by_node(name, ns),
            )
        else:
            return f"the node {leaf.node} is running without it"
        own = sorted(t for t, _ in found if t not in _ROS_OWN_TOPICS)
        return (
            f"the node {leaf.node} is running but {what} {', '.join(own) or 'nothing'} "
            "(describe --ros2 lists the topics to use)"
        )

    def _missing(self, leaf: Wiring) -> str | None:
        if self.clock_pub.get_subscription_count() < 1:
            return "no subscriber on /clock"
        for w in leaf.inputs:
            if self.pubs[w.topic].get_subscription_count() < 1:
                return f"no subscriber on {w.topic}"
        step = self.step_pubs.get(leaf.path)
        if step is not None and step.get_subscription_count() < 1:
            return f"no subscriber on {names.step_topic(leaf.path)}"
        for w in leaf.outputs:
            if self.subs[w.topic].get_publisher_count() < 1:
                return f"no publisher on {w.topic}"
        if leaf.params and not self.clients[leaf.path].service_is_ready():
            return f"no service {leaf.set_parameters}"
        return None

    # -- parameters -----------------------------------------------------------------------
    def set_params(self, leaf: Wiring, values: Mapping[str, Any], start: bool = False) -> None:
        """Set the node's parameters through its service; a refusal is the run's fault.

        ``start``: before the first step, where a Ctrl-C may end the wait at once (mid-run,
        between the instant's other steps, the run's own grace period handles it)."""
        if not values:
            return
        from rcl_interfaces.srv import SetParameters

        req = SetParameters.Request()
        req.parameters = [_parameter(k, v).to_parameter_msg() for k, v in values.items()]
        future = self._call(self.clients[leaf.path], req, start)
        if future is None:
            raise self._fault(
                leaf, f"{leaf.set_parameters} did not answer within {self.timeout_s:g} s"
            )
        for (name, value), result in zip(values.items(), future.result().results, strict=False):
            if not result.successful:
                raise self._fault(leaf, _refusal(name, value, result.reason))
        self.counts[leaf.path]["params_set"] += len(values)

    def _call(self, client: Any, req: Any, interruptible: bool = False) -> Any:
        """The first answer to ``req``, sent again every :data:`_RESEND_S` until one comes
        (None after the timeout). A service's first answer can be lost while the discovery
        of the client's reply reader is still under way (a DDS race: the node answered, the
        answer went nowhere); setting the same values again is harmless."""
        deadline = time.monotonic() + self.timeout_s
        sent: list[Any] = []
        answered = None
        while answered is None:
            if interruptible:  # as in connect: a node that does not answer is waited for
                interrupt.check()
            now = time.monotonic()
            if now >= deadline:
                break
            sent.append(client.call_async(req))
            until = min(deadline, now + _RESEND_S)
            while answered is None and time.monotonic() < until:
                self.executor.spin_once(
                    timeout_sec=max(0.0, min(_LOOK_S, until - time.monotonic()))
                )
                answered = next((f for f in sent if f.done()), None)
        for f in sent:
            if f is not answered:
                client.remove_pending_request(f)
        return answered

    # -- one step ---------------------------------------------------------------------------
    def step(self, leaf: Wiring, t: Fraction, inp: Mapping[str, Any]) -> dict[str, Any]:
        """Publish ``/clock`` and the inputs at ``t``; wait for one message per output."""
        self.executor.spin_once(timeout_sec=0)  # anything the node sent unasked is here now
        for w in leaf.outputs:
            if self.inbox[w.topic]:
                raise self._fault(
                    leaf,
                    f"published on {w.topic} before its inputs of t={float(t):g} s "
                    "(a node answers each step exactly once)",
                    t,
                )
        if self.last_clock != t:
            self.last_clock = t
            self.clock_pub.publish(self._clock_msg(t))
        for w in leaf.inputs:
            self.pubs[w.topic].publish(self._pack(w, inp[w.port]))
        step = self.step_pubs.get(leaf.path)
        if step is not None:  # an exported node's own trigger, after its inputs
            step.publish(self._clock_msg(t))
        self.counts[leaf.path]["steps"] += 1
        waiting = [w for w in leaf.outputs]
        deadline = time.monotonic() + self.timeout_s
        while True:
            waiting = [w for w in waiting if not self.inbox[w.topic]]
            if not waiting:
                break
            left = deadline - time.monotonic()
            if left <= 0:
                raise self._fault(
                    leaf,
                    f"no message on {waiting[0].topic} within {self.timeout_s:g} s "
                    f"of its inputs of t={float(t):g} s",
                    t,
                )
            self.executor.spin_once(timeout_sec=min(left, _LOOK_S))
            if all(not self.inbox[w.topic] for w in waiting):
                self._check_types(leaf, t)
                self._check_alive(leaf, waiting, t)
                self._check_watch(leaf, t)
        out: dict[str, Any] = {}
        for w in leaf.outputs:
            out[w.port] = self._unpack(leaf, w, self.inbox[w.topic].popleft(), t)
        self.counts[leaf.path]["answers"] += 1
        return out

    def _clock_msg(self, t: Fraction) -> Any:
        msg = self.Clock()
        whole = math.floor(t)
        msg.clock.sec = int(whole)
        msg.clock.nanosec = round((t - whole) * 1_000_000_000)
        return msg

    def _pack(self, w: external.Wire, value: Any) -> Any:
        cls = self.types[w.type]
        if w.type == external.SCALAR:
            return cls(data=float(value))
        from std_msgs.msg import MultiArrayDimension

        data = [float(v) for v in value]
        msg = cls(data=data)
        msg.layout.dim = [MultiArrayDimension(label=w.port, size=len(data), stride=len(data))]
        return msg

    def _unpack(self, leaf: Wiring, w: external.Wire, msg: Any, t: Fraction) -> Any:
        if w.type == external.SCALAR:
            value = float(msg.data)
            if not math.isfinite(value):
                raise self._fault(leaf, f"published {value!r} on {w.topic}", t)
            return value
        data = tuple(float(v) for v in msg.data)[msg.layout.data_offset :]
        size = self.arrays[w.buffer]
        if len(data) != size:
            raise self._fault(
                leaf, f"published {len(data)} values on {w.topic}, the port declares {size}", t
            )
        bad = [v for v in data if not math.isfinite(v)]
        if bad:
            raise self._fault(leaf, f"published {bad[0]!r} on {w.topic}", t)
        return data

    # -- what went wrong --------------------------------------------------------------------
    def _check_types(self, leaf: Wiring, t: Fraction | None = None) -> None:
        """A publisher of another type on an output topic never matches: say so at once."""
        for w in leaf.outputs:
            want = w.type
            for info in self.node.get_publishers_info_by_topic(w.topic):
                if info.node_name == external.BRIDGE_NODE:
                    continue
                if info.topic_type != want:
                    raise self._fault(
                        leaf,
                        f"publishes {info.topic_type} on {w.topic}, expected {want}",
                        t,
                    )

    def _check_qos(self, leaf: Wiring) -> None:
        """A node whose publisher or subscription cannot match the contract's QoS is on the
        graph but never connects: say so at once rather than a minute later as a node that
        is not running. The run's side is RELIABLE and VOLATILE, so only two choices of the
        node's cannot match: a BEST_EFFORT publisher of an output, a TRANSIENT_LOCAL
        subscription of an input or ``/clock``. (rclpy's ``qos_check_compatible`` is not
        used: on profiles read from the graph it reports deadlines nobody set.)"""
        from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

        for w in leaf.outputs:
            for info in self.node.get_publishers_info_by_topic(w.topic):
                if info.node_name == external.BRIDGE_NODE:
                    continue
                if info.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT:
                    raise self._fault(leaf, _qos_line("publishes on", w.topic, "BEST_EFFORT"))
        for topic in [w.topic for w in leaf.inputs] + ["/clock"]:
            for info in self.node.get_subscriptions_info_by_topic(topic):
                if info.node_name == external.BRIDGE_NODE:
                    continue
                if info.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL:
                    raise self._fault(leaf, _qos_line("subscribes to", topic, "TRANSIENT_LOCAL"))

    def _check_alive(self, leaf: Wiring, waiting: Sequence[external.Wire], t: Fraction) -> None:
        """The node gone (its publishers left the graph) while a step waits for it."""
        for w in waiting:
            if self.subs[w.topic].get_publisher_count() < 1:
                raise self._fault(
                    leaf, f"the node left the graph: no publisher on {w.topic} any more", t
                )

    def _check_watch(self, leaf: Wiring, t: Fraction | None = None) -> None:
        """The fault of a node the watch found gone, named after that node (not after the
        Leaf being waited for, which only noticed)."""
        found = self._watch()
        if found is not None:
            path, why = found
            raise self._fault(self.leaves.get(path, leaf), why, t)

    def _fault(self, leaf: Wiring, why: str, t: Fraction | None = None) -> NodeFault:
        return NodeFault(f"ROS 2 node {leaf.node}", self._now() if t is None else t, why)

    # -- end --------------------------------------------------------------------------------
    def close(self) -> None:
        """Leave the graph (idempotent)."""
        if self.context is None:
            return
        try:
            self.executor.shutdown(timeout_sec=0)
            self.node.destroy_node()
        finally:
            self.rclpy.try_shutdown(context=self.context)
            self.context = None

    def report(self) -> dict[str, Any]:
        """What each node was asked and answered (``metrics.json``'s ``ros2``)."""
        return {
            self.leaves[p].node: {**c, "complete": c["steps"] == c["answers"]}
            for p, c in self.counts.items()
        }


def _ignore(_event: Any) -> None:
    """An event callback that does nothing (in place of rclpy's default warning)."""


def _qos_line(verb: str, topic: str, theirs: str) -> str:
    return f"{verb} {topic} with a QoS that cannot match the run's (RELIABLE, VOLATILE): {theirs}"


def _param_value(value: Any) -> Any:
    """A parameter value as ROS 2 types it (``points``, pairs: a flat list of doubles)."""
    if isinstance(value, (tuple, list)):
        flat: list[float] = []
        for v in value:
            if isinstance(v, (tuple, list)):
                flat.extend(float(x) for x in v)
            else:
                flat.append(float(v))
        return flat
    return value


def _refusal(name: str, value: Any, reason: str) -> str:
    """What the fault line says of a refused parameter. A parameter the node never declared
    is refused by rclpy with a reason that names none (``Invalid access to undeclared
    parameter(s): []``), so the line names it and says what to do."""
    if "undeclared" in reason or "not declared" in reason:
        return (
            f"refused parameter {name}={value!r}: the node has not declared {name} "
            "(declare every parameter describe --ros2 lists, with its type)"
        )
    return f"refused parameter {name}={value!r} ({reason or 'refused'})"


def _parameter(name: str, value: Any) -> Any:
    """The rclpy ``Parameter`` a node is given: a list is always a double array, as
    ``describe --ros2`` says (rclpy infers a list's type from its items, and an empty one,
    a leader without waypoints, became a byte array the node's declared type refused)."""
    from rclpy.parameter import Parameter

    flat = _param_value(value)
    if isinstance(flat, list):
        return Parameter(name, Parameter.Type.DOUBLE_ARRAY, flat)
    return Parameter(name, value=flat)
