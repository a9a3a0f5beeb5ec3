"""rospy plumbing shared by the nodes: imports, the start-up handshake, the clock, parameters.

The handshake: ROS 1 drops what is published before a subscriber has connected, so every
node creates its publishers with a listener and waits (on a condition, woken by each new
connection) until each has the number of subscribers the graph says it will have
(``graph.RosGraph.subscribers``); then it says so on the latched topic ``names.READY``. The
simulator starts the run only when every node has, and its own publishers are connected too.
"""

from __future__ import annotations

import os
import sys
import threading
import time
import warnings
from collections.abc import Callable
from fractions import Fraction
from typing import Any

from ...errors import ConfigError
from ...model.params import Param
from ...model.world import LeafSpec
from .. import names


def ros() -> Any:
    """``rospy``, importing ROS's Python packages from where Debian puts them if needed.

    The node runs in the Python that has amsa-phys (a venv); ROS's packages are Debian's
    (``/usr/lib/python3/dist-packages``). They are appended to ``sys.path``, after the venv,
    so the venv's numpy and PyYAML win.
    """
    try:
        import rospy
    except ImportError:
        extra = os.environ.get("AMSA_PHYS_ROS_PYTHONPATH", "/usr/lib/python3/dist-packages")
        for entry in extra.split(os.pathsep):
            if entry and entry not in sys.path:
                sys.path.append(entry)
        import rospy
    return rospy


def msgs() -> tuple[Any, Any, Any]:
    """``(Float64, String, Clock)`` message classes."""
    from rosgraph_msgs.msg import Clock
    from std_msgs.msg import Float64, String

    return Float64, String, Clock


def to_ns(t: Fraction) -> int:
    """Nanoseconds of a simulated instant, rounded down (the same everywhere: exact compare)."""
    return t.numerator * 1_000_000_000 // t.denominator


class Gate:
    """Publishers that must reach their number of subscribers before the node is ready."""

    def __init__(self, rospy: Any, cond: threading.Condition | None = None) -> None:
        self.rospy = rospy
        self.cond = cond or threading.Condition()
        self.pubs: list[tuple[Any, int, str]] = []
        rospy.on_shutdown(self.wake)

    def publisher(self, name: str, cls: Any, expected: int, latch: bool = False) -> Any:
        """A synchronous, TCP_NODELAY publisher counted by the handshake."""
        gate = self

        class _Listener(self.rospy.SubscribeListener):  # type: ignore[misc,name-defined]
            def peer_subscribe(self, *_: Any) -> None:
                gate.wake()

        pub = make_publisher(self.rospy, name, cls, latch=latch, listener=_Listener())
        self.pubs.append((pub, expected, name))
        return pub

    def missing(self) -> list[str]:
        """Topics still short of subscribers."""
        return [n for pub, want, n in self.pubs if pub.get_num_connections() < want]

    def wait(self, timeout: float, also: Callable[[], bool] = lambda: True) -> list[str]:
        """Wait until every publisher is connected and ``also()`` holds; what is missing."""
        deadline = time.monotonic() + timeout
        with self.cond:
            while not self.rospy.is_shutdown():
                if not self.missing() and also():
                    return []
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self.cond.wait(min(left, 0.5))
        return self.missing() or ["(shut down)" if self.rospy.is_shutdown() else "(waiting)"]

    def wake(self) -> None:
        """Re-check the condition (a subscriber connected, a message came, shutdown)."""
        with self.cond:
            self.cond.notify_all()


def make_publisher(
    rospy: Any, name: str, cls: Any, latch: bool = False, listener: Any = None
) -> Any:
    """A publisher that writes in the caller's thread (no queue: order and latency kept)."""
    with warnings.catch_warnings():  # rospy warns when no queue_size: synchronous is wanted
        warnings.simplefilter("ignore", SyntaxWarning)
        return rospy.Publisher(
            name, cls, subscriber_listener=listener, tcp_nodelay=True, latch=latch
        )


def announce_ready(rospy: Any, who: str) -> Any:
    """Say on the latched ``names.READY`` that ``who`` is connected (keep the publisher)."""
    _, String, _ = msgs()
    pub = make_publisher(rospy, names.READY, String, latch=True)
    pub.publish(String(who))
    return pub


class ClockFollower:
    """The latest ``/clock`` (latched by the simulator), with waiting until an instant."""

    def __init__(self, rospy: Any) -> None:
        _, _, Clock = msgs()
        self.rospy = rospy
        self.ns = -1
        self.cond = threading.Condition()
        self.sub = rospy.Subscriber(names.CLOCK, Clock, self._on_clock, tcp_nodelay=True)
        rospy.on_shutdown(self._wake)

    def _on_clock(self, msg: Any) -> None:
        with self.cond:
            self.ns = msg.clock.secs * 1_000_000_000 + msg.clock.nsecs
            self.cond.notify_all()

    def _wake(self) -> None:
        with self.cond:
            self.cond.notify_all()

    def wait_until(self, ns: int) -> bool:
        """Block until the clock reaches ``ns``; False if the node shuts down first."""
        with self.cond:
            while self.ns < ns:
                if self.rospy.is_shutdown():
                    return False
                self.cond.wait(0.5)
        return True


def ros_value(value: Any) -> Any:
    """A parameter value as the parameter server holds it (tuples as lists)."""
    if isinstance(value, tuple):
        return [ros_value(v) for v in value]
    return value


def fetch_param(rospy: Any, name: str) -> Any:
    """A parameter's value asked of the master now (KeyError if unset).

    Not ``rospy.get_param``: once a node has called ``get_param_cached`` for a key (free
    mode, to see live edits), ``get_param`` answers from that cache, which the master updates
    asynchronously — a timeline change read that way could be the old value.
    """
    code, _, value = rospy.get_master().target.getParam(rospy.get_name(), name)
    if code != 1:
        raise KeyError(name)
    return value


def read_param(rospy: Any, path: str, param: Param, cached: bool = False) -> Any:
    """A Leaf's parameter from the server, judged by the template (type and [min, max])."""
    name = names.param(path, param.name)
    try:
        raw = rospy.get_param_cached(name) if cached else fetch_param(rospy, name)
    except KeyError:
        raise ConfigError("is not on the parameter server", key=name) from None
    try:
        return param.coerce(raw)
    except ValueError as exc:
        raise ConfigError(str(exc), key=name) from None


def read_params(rospy: Any, leaf: LeafSpec) -> dict[str, Any]:
    """All of a Leaf's parameters from the server, checked together (``check_params``)."""
    values = {p.name: read_param(rospy, leaf.path, p) for p in leaf.template.params}
    try:
        leaf.template.check_params(values)
    except ValueError as exc:
        raise ConfigError(str(exc), key=names.ns(leaf.path)) from None
    return values


def fail(rospy: Any, message: str, code: int = 2) -> None:
    """Log a node's fatal error as one line and exit (roslaunch then stops the others)."""
    print(f"error: {message}", file=sys.stderr, flush=True)
    try:
        rospy.logfatal(message)
        rospy.signal_shutdown(message)
    finally:
        sys.exit(code)


def set_param(rospy: Any, path: str, name: str, value: Any) -> None:
    """Put a Leaf's parameter on the server (an ``adapt:`` rule's change): its node reads it
    from there (lockstep: when asked; free: at its next step)."""
    rospy.set_param(names.param(path, name), ros_value(value))
