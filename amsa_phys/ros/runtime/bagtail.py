"""The simulator's side of ``bag:=``: never get too far ahead of the recorder, and wait for it
at the end (the recorder: ``bagrecord.py``).

The recorder reads every topic without a queue, so a Python publisher (the simulator's own,
a Python Leaf's) simply waits while the recorder is behind. A C++ Leaf's roscpp publisher
does not wait: it queues up to 1000 messages per subscriber and then drops the oldest. So
every :data:`EVERY` instants the simulator compares its count of each topic's messages with
the recorder's last answer, and when some topic is :data:`WINDOW` messages ahead it asks
(``rosnames.BAG_FLUSH``) and waits until the recorder has written all but half a window: the
recorder is never more than :data:`WINDOW` messages behind on a topic, well inside roscpp's
queue. At the run's end it asks for every message: roslaunch stops the recorder as soon as
the simulator (``required``) exits, and what it had not read then would be lost.

Waiting is bounded by the launch's ``timeout:=``: a recorder that does not answer (it died,
it was stopped) is given up with one line saying the bag is incomplete, and the run goes on.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from ...model.rosnames import BAG_FLUSH, BAG_WRITTEN
from .. import names
from . import rosio
from .bagrecord import NODE, format_counts, parse_counts

#: How many messages the recorder may be behind on one topic before the simulator waits.
WINDOW = 400
#: Every how many instants (``/clock`` ticks) the counts are compared.
EVERY = 16


class BagTail:
    """The ``BAG_FLUSH`` request publisher and ``BAG_WRITTEN`` answers of one run."""

    def __init__(self, rospy: object, counts: Callable[[], dict[str, int]], timeout: float) -> None:
        String = rosio.msgs()[1]
        self.rospy = rospy
        self.String = String
        self.counts = counts
        self.timeout = timeout
        self.cond = threading.Condition()
        #: the most the recorder has said it wrote, per topic
        self.written: dict[str, int] = {}
        self.given_up = False
        self.ticks = 0
        self.pub = rosio.make_publisher(rospy, BAG_FLUSH, String, latch=True)
        self.sub = rospy.Subscriber(  # type: ignore[attr-defined]
            BAG_WRITTEN, String, self._on_written, tcp_nodelay=True
        )

    def _on_written(self, msg: object) -> None:
        try:
            got = parse_counts(msg.data)  # type: ignore[attr-defined]
        except ValueError:
            return  # not the recorder's: the wait goes on, bounded
        with self.cond:
            for topic, n in got.items():
                self.written[topic] = max(n, self.written.get(topic, 0))
            self.cond.notify_all()

    def short(self, want: dict[str, int]) -> list[str]:
        """Topics the recorder has not written ``want`` messages of yet."""
        return [t for t, n in want.items() if self.written.get(t, 0) < n]

    def wait(self, want: dict[str, int]) -> list[str]:
        """Ask the recorder to say when it has written ``want`` messages of each topic, and
        wait for it (at most ``timeout``); the topics still short then."""
        with self.cond:
            if not self.short(want):
                return []
        self.pub.publish(self.String(format_counts(want)))
        deadline = time.monotonic() + self.timeout
        with self.cond:
            while self.short(want):
                if self.rospy.is_shutdown():  # type: ignore[attr-defined]
                    break
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self.cond.wait(min(left, 0.2))
            return self.short(want)

    def tick(self) -> None:
        """An instant passed: every :data:`EVERY`, wait if the recorder is a window behind."""
        self.ticks += 1
        if self.given_up or self.ticks % EVERY:
            return
        counts = self.counts()
        with self.cond:
            behind = any(n - self.written.get(t, 0) >= WINDOW for t, n in counts.items())
        if behind:
            want = {t: max(0, n - WINDOW // 2) for t, n in counts.items()}
            missing = self.wait(want)
            if missing:
                self.give_up(missing, want)

    def finish(self) -> bool:
        """The run is over: wait until every message counted is written; False if not."""
        if self.given_up:
            return False
        want = self.counts()
        with self.cond:
            behind = bool(self.short(want))
        if behind:  # as good as always: the recorder has not said so since the last instant
            print(
                f"{names.SIMULATOR}: waiting for the bag recorder ({NODE}) to write the run's "
                f"last messages (at most {self.timeout:g} s, timeout:=)",
                flush=True,
            )
        missing = self.wait(want)
        if missing:
            self.give_up(missing, want)
            return False
        return True

    def give_up(self, missing: list[str], want: dict[str, int]) -> None:
        """Say once that the bag is incomplete; wait for the recorder no more."""
        if self.given_up:
            return
        self.given_up = True
        topic = missing[0]
        print(
            f"{names.SIMULATOR}: the bag recorder ({NODE}) had written "
            f"{self.written.get(topic, 0)} of {want[topic]} messages of {topic} after waiting "
            f"{self.timeout:g} s (timeout:=): the bag is incomplete",
            file=sys.stderr,
            flush=True,
        )


def topic_counts(link: Any) -> dict[str, int]:
    """How many messages each Data topic has carried so far, as the simulator's ``link``
    knows: its own publications, and those of the nodes it received."""
    graph = link.graph
    with link.cond:
        return {
            names.topic(d): link.published[d]
            if graph.producer(d) in graph.local
            else link.received[d][0]
            for d in graph.data()
        }
