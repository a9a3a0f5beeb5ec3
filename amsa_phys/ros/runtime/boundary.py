"""The boundary node: AMSA data topics to standard ROS messages and back (``ros/boundary.py``).

Out (both sides): a stream's message is built by ``stdmsgs.build`` — the very builders of
the MCAP bag, so covariances come from the sensor's noise model the same way — once every
field of it has a new value since the last message (a Leaf publishes all of its outputs
at a step, each on its topic; a GPS that lost its fix publishes nothing, so no NavSatFix
either). Stamped with the simulated time at which its values were produced, as in the bag.
In lockstep the values come from the simulator, on :data:`VALUES`: one message per Leaf
step, its instant and the values of the buffers this node reads (the very floats of the
data topics). One connection carries both, so no race between a ``/clock`` connection and a
data connection can stamp a message with another instant, and ``/clock`` (published only
where a node steps: 4 Hz in scenario1) does not stamp a 10 Hz Leader's pose 0.25 s late
with repeated stamps. In free mode each node steps on its own timer and the simulator does
not know when a value was produced: the data topics, stamped with ``rospy.Time.now()``
(``/clock``). The tf tree is REP 105's
per robot, as in the bag: ``map`` -> ``<robot>/odom`` (identity, latched on ``/tf_static``)
-> ``<robot>/base_link`` (the true pose, on ``/tf``).

In (``sim:=false``): a message on a sensor stream's topic becomes the data topics of its
fields (a NavSatFix's latitude and longitude back to the plane's x and y at the same
origin; a fix with status NO_FIX is dropped, as a lost fix; ``ros/boundary.py``'s
``judge`` is the mapping, shared with ROS 2's boundary node), and this node publishes
``/clock`` from the wall clock (times ``speed:=``), since no simulator does: every node
of the package steps on ``/clock`` (``use_sim_time``), so a real robot's drivers stamp
with it too.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterable, Mapping
from fractions import Fraction
from typing import Any

from ...errors import AmsaError, one_line
from ...model.params import short_repr
from ...model.rosnames import BOUNDARY_FLUSHED, BOUNDARY_VALUES
from ...stdmsgs import DEFAULT_ORIGIN, Context, Source, build
from ...stdmsgs.build import static_transform, transform
from .. import names
from ..boundary import NODE, SIM_PARAM, buffers_of, plan, read_fields
from ..graph import RosGraph
from . import rosio, startup
from .arrays import ScanShape, array_msg, pack, unpack
from .config import load_config

#: ``/clock`` period with ``sim:=false`` (wall seconds): finer than any Leaf's period
CLOCK_PERIOD = 0.005

#: lockstep: the simulator's ``NUM DEN BUFFER VALUE ...`` per Leaf step (std_msgs/String):
#: the step's instant (a fraction of seconds) and the values it wrote that this node reads
VALUES = BOUNDARY_VALUES
#: Lockstep's end: the simulator sends :data:`FLUSH` on :data:`VALUES` after the run's last
#: values and waits for the answer on :data:`FLUSHED` (latched) before it ends the launch, so
#: the boundary has published every standard message of the run (a loaded machine's boundary
#: may lag seconds behind the simulator; shutting the launch down at once lost the tail).
FLUSH = "flush"
FLUSHED = BOUNDARY_FLUSHED


def ros1_classes() -> dict[str, Any]:
    """ROS 1 message classes by ``pkg/Type`` (Debian's python3-sensor-msgs and friends)."""
    rosio.ros()  # puts ROS's Python packages on the path
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Imu, JointState, LaserScan, NavSatFix
    from tf2_msgs.msg import TFMessage

    return {
        "sensor_msgs/NavSatFix": NavSatFix,
        "sensor_msgs/Imu": Imu,
        "nav_msgs/Odometry": Odometry,
        "sensor_msgs/LaserScan": LaserScan,
        "sensor_msgs/JointState": JointState,
        "tf2_msgs/TFMessage": TFMessage,
    }


def fill(rospy: Any, msg: Any, fields: Mapping[str, Any]) -> Any:
    """A ROS 1 message from ``stdmsgs``'s dict of a ROS 2 message (same fields but the
    stamp: ROS 2's ``{sec, nanosec}`` is ROS 1's ``rospy.Time``)."""
    for key, value in fields.items():
        if key == "stamp":
            msg.stamp = rospy.Time(value["sec"], value["nanosec"])
        elif isinstance(value, Mapping):
            fill(rospy, getattr(msg, key), value)
        else:
            setattr(msg, key, value)
    return msg


class Outbound:
    """One stream published from the data topics (see the module docstring)."""

    def __init__(self, node: BoundaryNode, src: Source) -> None:
        self.node = node
        self.src = src
        self.cls = node.classes[src.role.msg]
        self.pub = rosio.make_publisher(node.rospy, src.topic, self.cls)
        leaf = node.graph.leaf(src.leaf)
        #: the noise model's parameters as the launch set them (the covariances' source)
        self.params = rosio.read_params(node.rospy, leaf)
        self.period = 1 / float(leaf.freq)
        self.fresh: set[str] = set()
        self.wanted = set(buffers_of(src))

    def got(self, buffer: str, at: Fraction | None = None) -> None:
        """A field's buffer has a new value, produced at ``at`` (simulated seconds; None:
        now, by ``/clock``); the node's lock is held."""
        self.fresh.add(buffer)
        if self.fresh >= self.wanted:
            self.fresh.clear()
            self.publish(at)

    def publish(self, at: Fraction | None = None) -> None:
        rospy = self.node.rospy
        if at is None:
            now = rospy.Time.now()
            stamp, t_s = (now.secs, now.nsecs), now.to_sec()
        else:  # as the bag stamps it (``bag/runbag.py``)
            ns = rosio.to_ns(at)
            stamp, t_s = (ns // 10**9, ns % 10**9), float(at)
        ctx = Context(stamp, t_s, self.period, self.node.origin)
        values = self.node.values
        msg = build(self.src, values, self.params, ctx)
        self.pub.publish(fill(rospy, self.cls(), msg))
        if self.src.role.name == "Pose":
            fields = {k: values[b] for k, b in self.src.buffers.items() if isinstance(b, str)}
            tf = fill(rospy, self.node.TransformStamped(), transform(self.src, fields, ctx))
            self.node.tf_pub.publish(self.node.classes["tf2_msgs/TFMessage"]([tf]))


class BoundaryNode:
    """The boundary of the package's world (``ros/boundary.py`` says which streams)."""

    def __init__(self, rospy: Any) -> None:
        self.rospy = rospy
        cfg = load_config(rospy)
        self.graph = cfg.graph
        self.lockstep = cfg.mode == "lockstep"
        self.sim = bool(rospy.get_param(SIM_PARAM, True))
        self.plan = plan(self.graph)
        self.classes = ros1_classes()
        from geometry_msgs.msg import TransformStamped

        self.TransformStamped = TransformStamped
        self.Float64 = rosio.msgs()[0]
        world = self.graph.world
        self.Array = array_msg() if world.arrays else None
        #: an array port's element buffer -> the port (its topic carries them all)
        self.element = {e: a for a, elements in world.arrays.items() for e in elements}
        self.origin = DEFAULT_ORIGIN
        self.lock = threading.Lock()
        world = self.graph.world
        self.values: dict[str, float] = {b: float(s.initial) for b, s in world.buffers.items()}
        self.tf_pub = rosio.make_publisher(rospy, "/tf", self.classes["tf2_msgs/TFMessage"])
        inbound = {s.leaf for s in self.plan.inbound}
        out = [
            s
            for s in self.plan.sources
            if self.sim or (s.role.name == "WheelCommand" and s.leaf not in inbound)
        ]
        self.outbound = [Outbound(self, s) for s in out]
        robots = [o.src for o in self.outbound if o.src.role.name == "Pose"]
        if robots:  # REP 105: map -> <robot>/odom, the identity, latched once
            self.tf_static = rosio.make_publisher(
                rospy, "/tf_static", self.classes["tf2_msgs/TFMessage"], latch=True
            )
            tfs = [fill(rospy, TransformStamped(), static_transform(r, (0, 0))) for r in robots]
            self.tf_static.publish(self.classes["tf2_msgs/TFMessage"](tfs))
        readers: dict[str, list[Outbound]] = {}
        for o in self.outbound:
            for b in o.wanted:
                readers.setdefault(b, []).append(o)
        self.readers = readers
        self.subs: list[Any] = []
        self.data_pubs: dict[str, Any] = {}
        #: sim:=false: each lidar Leaf's declared scan, to which a robot's scan is fitted
        self.scans: dict[str, ScanShape] = {}
        if not self.sim:
            for src in self.plan.inbound:
                if src.role.name == "LaserScan":
                    p = rosio.read_params(rospy, self.graph.leaf(src.leaf))
                    self.scans[src.leaf] = ScanShape.of(p)
            for src in self.plan.inbound:
                for b in buffers_of(src):
                    d = self.element.get(b, b)
                    if d not in self.data_pubs:
                        cls = self.Array if d in world.arrays else self.Float64
                        self.data_pubs[d] = rosio.make_publisher(rospy, names.topic(d), cls)
                cls = self.classes[src.role.msg]
                self.subs.append(rospy.Subscriber(src.topic, cls, self._on_std, callback_args=src))

    def listen(self) -> None:
        """Subscribe to the data topics the outbound streams read (lockstep: to :data:`VALUES`).

        With the simulator in free mode, only once ``/clock`` runs: every node waits at
        start until each of its publishers has exactly the subscribers the graph counts, and
        a subscriber of ours counted in a consumer's place would let a producer publish before that
        consumer is connected (its lockstep step would then wait forever for a lost message).
        """
        if self.sim and self.lockstep:  # the values with their instants, from the simulator
            String = rosio.msgs()[1]  # (no count of subscribers waits for this one: at once)
            self.String = String
            self.flushed = rosio.make_publisher(self.rospy, FLUSHED, String, latch=True)
            self.subs.append(
                self.rospy.Subscriber(VALUES, String, self._on_values, tcp_nodelay=True)
            )
            return
        if self.sim:
            Clock = rosio.msgs()[2]
            self.rospy.wait_for_message(names.CLOCK, Clock)
        topics = {self.element.get(b, b) for b in self.readers}  # an array: its port's topic
        self.subs += [
            self.rospy.Subscriber(
                names.topic(d),
                self.Array if self.graph.is_array(d) else self.Float64,
                self._on_data,
                callback_args=d,
                tcp_nodelay=True,
            )
            for d in self.graph.data()
            if d in topics
        ]

    def _on_data(self, msg: Any, data: str) -> None:
        arrays = self.graph.world.arrays
        if data in arrays:  # an array port: its elements' buffers, which the streams read
            try:
                value = unpack(msg, len(arrays[data]), names.topic(data))
            except ValueError as exc:
                self.rospy.logerr(f"{NODE}: {exc}")
                return
            pairs = list(zip(arrays[data], value, strict=True))
        else:
            pairs = [(data, msg.data)]
        with self.lock:
            for buffer, v in pairs:
                self.values[buffer] = v
            for buffer, _ in pairs:
                for o in self.readers.get(buffer, ()):
                    o.got(buffer)

    def _on_values(self, msg: Any) -> None:
        """Lockstep: a Leaf step's values that this node reads, at the step's instant."""
        if msg.data == FLUSH:  # the run's values are all handled (one publisher: in order)
            self.flushed.publish(self.String(FLUSH))
            return
        try:
            at, values = parse_values(msg.data)
        except ValueError as exc:  # not the simulator's: said, dropped, the node goes on
            self.rospy.logerr(one_line(f"{NODE}: {VALUES}: {exc}"))
            return
        with self.lock:
            for buffer, value in values:
                if buffer in self.readers:
                    self.values[buffer] = value
                    for o in self.readers[buffer]:
                        o.got(buffer, at)

    def _on_std(self, msg: Any, src: Source) -> None:
        """A driver's message on a sensor stream: its fields on their data topics."""
        fields = read_fields(src, msg, self.origin, self.scans.get(src.leaf))
        if fields is None:
            return
        for name, value in fields.items():
            buf = src.buffers[name]
            if isinstance(buf, tuple):  # an array port: one message on its port's topic
                port = self.element[buf[0]]
                label = port.rpartition(".")[2]
                self.data_pubs[port].publish(pack(self.Array, label, value))
            else:
                self.data_pubs[buf].publish(self.Float64(value))

    def run_clock(self, speed: float) -> None:
        """``sim:=false``: ``/clock`` = wall seconds since start times ``speed``."""
        Clock = rosio.msgs()[2]
        pub = rosio.make_publisher(self.rospy, names.CLOCK, Clock, latch=True)
        wall0 = time.monotonic()
        while not self.rospy.is_shutdown():
            ns = int((time.monotonic() - wall0) * speed * 1e9)
            pub.publish(Clock(self.rospy.Time(ns // 10**9, ns % 10**9)))
            time.sleep(CLOCK_PERIOD)  # the clock's own tick: pacing is this node's job


def format_values(t: Fraction, values: Iterable[tuple[str, float]]) -> str:
    """A :data:`VALUES` message: ``t`` exactly, each float as ``repr`` (it reads back the same)."""
    return " ".join([str(t.numerator), str(t.denominator), *(f"{b} {v!r}" for b, v in values)])


def parse_values(text: str) -> tuple[Fraction, list[tuple[str, float]]]:
    """A :data:`VALUES` message: the instant and the values. Anything else on the topic
    (another publisher's text, a torn message) is ``ValueError`` saying what it is."""
    try:
        num, den, *rest = text.split(" ")
        if len(rest) % 2:
            raise ValueError
        values = [(rest[i], float(rest[i + 1])) for i in range(0, len(rest), 2)]
        at = Fraction(int(num), int(den))
    except (ValueError, ZeroDivisionError):
        raise ValueError(f"not a values message: {short_repr(text)}") from None
    if at < 0 or not all(math.isfinite(v) for _, v in values):
        raise ValueError(
            f"not a values message (a negative instant or a value not finite): {short_repr(text)}"
        )
    return at, values


def readable(graph: RosGraph) -> set[str]:
    """Every buffer the boundary publishes from with the simulator (what :data:`VALUES` carries)."""
    return {b for src in plan(graph).sources for b in buffers_of(src)}


def main() -> None:
    """The boundary node's entry point."""
    rospy = rosio.ros()
    startup.init_node(rospy, NODE)
    try:
        node = BoundaryNode(rospy)
        speed = float(rospy.get_param("~speed", 1.0))
        if not speed > 0 or math.isinf(speed):
            raise AmsaError(f"speed:= must be a positive number, got {speed}")
    except AmsaError as exc:
        rosio.fail(rospy, f"{NODE}: {exc}")
        return
    startup.started(rospy)
    if node.sim:
        try:
            node.listen()
        except rospy.ROSInterruptException:
            return  # the launch ended before the run started
        rospy.spin()
    else:
        node.listen()
        node.run_clock(speed)
