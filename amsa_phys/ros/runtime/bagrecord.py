"""The ``bag:=`` recorder (node ``amsa_bag``): topics to a ROS 1 bag, never dropping a message.

``rosbag record`` subscribes each topic with a queue of 100 messages and drops the oldest when
its writer falls behind. In lockstep the simulator outruns real time, so a recorder starved
for a moment (a loaded machine) silently lost messages from the middle of a run. Here every
topic is subscribed with ``rospy.AnyMsg`` and no queue: rospy then hands each message to the
writer in the thread that reads its connection, so a recorder that falls behind stops reading,
TCP fills, and the synchronous publishers of the run wait for it. The run slows down; the bag
stays whole.

A message is stamped with its time of receipt (``/clock``), as ``rosbag record`` stamps it,
and written with the connection header its publisher sent (type, md5sum, definition): a bag
``rosbag`` and ``rosbags`` read as one ``rosbag record`` wrote. It is written to
``FILE.active`` and renamed to ``FILE`` once closed, as ``rosbag record`` does.

The run's tail: the simulator is ``required``; when it ends, roslaunch stops every node, and
messages the recorder had not read yet would be lost. So the simulator says on the latched
``rosnames.BAG_FLUSH`` how many messages it saw on each topic (:func:`format_counts`), and
waits until the recorder answers on ``rosnames.BAG_WRITTEN`` that it has written at least that
many of each. Stopped otherwise (Ctrl-C, ``rosbag``'s ``-O FILE TOPIC...`` use of this node in
a launch file of the user's own), it reads what has already arrived before it closes the bag.
"""

from __future__ import annotations

import fcntl
import signal
import sys
import termios
import threading
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ...errors import one_line
from ...model.rosnames import BAG, BAG_FLUSH, BAG_WRITTEN
from . import rosio, startup

NODE = BAG
#: Stopped by a signal: how long the recorder reads what has arrived before it closes the bag.
DRAIN_S = 5.0
#: ... and how long every connection must have stayed empty for the recorder to be done.
QUIET_S = 0.2


def format_counts(counts: Mapping[str, int]) -> str:
    """``rosnames.BAG_FLUSH``'s text: one ``TOPIC COUNT`` line per topic (topics have no
    spaces: ROS names are letters, digits, ``_`` and ``/``)."""
    return "".join(f"{topic} {n}\n" for topic, n in counts.items())


def parse_counts(text: str) -> dict[str, int]:
    """The counts :func:`format_counts` wrote (ValueError on anything else)."""
    out: dict[str, int] = {}
    for line in text.splitlines():
        topic, _, n = line.rpartition(" ")
        if not topic.startswith("/") or not n.isdigit():
            raise ValueError(f"expected 'TOPIC COUNT' lines, got {line!r}")
        out[topic] = int(n)
    return out


def parse_args(argv: list[str]) -> tuple[Path, list[str]]:
    """``-O FILE TOPIC...`` (as ``rosbag record`` takes them; ``--tcpnodelay`` is accepted and
    always on). SystemExit with one line on anything else."""
    args = [a for a in argv if a != "--tcpnodelay"]
    if len(args) < 3 or args[0] != "-O" or not args[1]:
        raise SystemExit(f"error: {NODE}: expected -O FILE.bag TOPIC..., got {' '.join(argv)!r}")
    path = Path(args[1])
    if path.suffix != ".bag":
        path = path.with_name(path.name + ".bag")  # rosbag record's rule
    return path, args[2:]


class _Type:
    """What ``rosbag.Bag.write`` needs of a message class for a raw message: the publisher's
    md5sum and definition (no message package is imported: any type records)."""

    def __init__(self, header: Mapping[str, str]) -> None:
        self._md5sum = header["md5sum"]
        self._full_text = header.get("message_definition", "")


class Recorder:
    """The bag and its subscriptions; writes one message at a time, under :attr:`cond`."""

    def __init__(self, rospy: Any, path: Path, topics: list[str]) -> None:
        import rosbag  # Debian's, on the path rosio.ros() set up

        self.rospy = rospy
        self.path = path
        self.active = path.with_name(path.name + ".active")
        self.bag = rosbag.Bag(str(self.active), "w")
        self.cond = threading.Condition()
        self.counts = dict.fromkeys(topics, 0)
        self.types: dict[str, _Type] = {}
        self.closed = False
        self.subs = [
            rospy.Subscriber(
                topic,
                rospy.AnyMsg,
                self._on_message,
                callback_args=topic,
                queue_size=None,  # no queue: read in step with writing, never dropped
                tcp_nodelay=True,
            )
            for topic in topics
        ]
        String = rosio.msgs()[1]
        self.String = String
        self.written = rosio.make_publisher(rospy, BAG_WRITTEN, String, latch=True)
        self.flush_sub = rospy.Subscriber(BAG_FLUSH, String, self._on_flush, tcp_nodelay=True)

    def _on_message(self, msg: Any, topic: str) -> None:
        header = msg._connection_header
        stamp = self.rospy.Time.now()  # receipt time, as rosbag record stamps
        with self.cond:
            if self.closed:
                return
            kind = self.types.get(topic)
            if kind is None:
                kind = self.types[topic] = _Type(header)
            conn = {k: header[k] for k in ("callerid", "latching", "md5sum", "type") if k in header}
            conn["message_definition"] = kind._full_text
            conn["topic"] = topic
            self.bag.write(
                topic,
                (header["type"], msg._buff, header["md5sum"], kind),
                stamp,
                raw=True,
                connection_header=conn,
            )
            self.counts[topic] += 1
            self.cond.notify_all()

    def _on_flush(self, msg: Any) -> None:
        """The simulator's counts at the run's end: answer once that many are written."""
        try:
            want = parse_counts(msg.data)
        except ValueError as exc:
            self.rospy.logerr(one_line(f"{NODE}: {BAG_FLUSH}: {exc}"))
            return
        threading.Thread(target=self._answer, args=(want,), daemon=True).start()

    def _answer(self, want: dict[str, int]) -> None:
        with self.cond:
            while not self.closed and any(self.counts.get(t, 0) < n for t, n in want.items()):
                self.cond.wait(0.5)
            if self.closed:
                return
        self.written.publish(self.String(format_counts(self.counts)))

    def pending(self) -> int:
        """Bytes arrived on the recorder's connections and not read yet."""
        total = 0
        for sub in self.subs:
            for conn in list(sub.impl.connections):
                sock = getattr(conn, "socket", None)
                if sock is None:
                    continue
                try:
                    buf = fcntl.ioctl(sock.fileno(), termios.FIONREAD, b"\0\0\0\0")
                except OSError:
                    continue
                total += int.from_bytes(buf, sys.byteorder)
        return total

    def drain(self, limit: float = DRAIN_S) -> None:
        """Read what has arrived: until every connection stayed empty for :data:`QUIET_S` and
        no message came meanwhile, at most ``limit`` s."""
        deadline = time.monotonic() + limit
        last = -1
        quiet_since = time.monotonic()
        while time.monotonic() < deadline:
            total = sum(self.counts.values())
            if self.pending() or total != last:
                last, quiet_since = total, time.monotonic()
            elif time.monotonic() - quiet_since >= QUIET_S:
                return
            time.sleep(0.02)  # polling the sockets: no event says they are empty

    def close(self) -> None:
        """Close the bag (its index written) and give it its name."""
        with self.cond:
            if self.closed:
                return
            self.closed = True
            self.cond.notify_all()
            self.bag.close()
        self.active.replace(self.path)


def main() -> None:
    """The recorder node's entry point: ``amsa_bag.py -O FILE.bag TOPIC...``."""
    rospy = rosio.ros()
    path, topics = parse_args(rospy.myargv(sys.argv)[1:])
    startup.init_node(rospy, NODE)
    stop = threading.Event()
    try:
        recorder = Recorder(rospy, path, topics)
    except OSError as exc:
        rosio.fail(rospy, f"{NODE}: cannot write {path}: {exc.strerror}")
        return
    # whatever ends the loop (a signal, or an exception: a KeyboardInterrupt in the instant
    # between start-up's handlers and these), the bag is closed and given its name
    try:
        startup.started()
        for sig in startup.SIGNALS:
            signal.signal(sig, lambda *_: stop.set())
        rospy.on_shutdown(stop.set)
        print(f"{NODE}: recording {len(topics)} topics to {path}", flush=True)
        while not stop.wait(1.0):
            pass
        recorder.drain()
    finally:
        recorder.close()
    print(f"{NODE}: {sum(recorder.counts.values())} messages in {path}", flush=True)
    rospy.signal_shutdown("recorded")
