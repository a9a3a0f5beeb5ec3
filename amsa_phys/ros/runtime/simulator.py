"""The simulator node: the engine itself, with the Leaves that are nodes stepped over ROS.

It runs ``runs.single.run_scenario`` — the very code behind ``amsa-phys run`` — on a
:class:`RosSimulation`: the engine's own instant table decides who steps when and in what
order (so latency models, a compiled physics step or new templates carry over untouched).
The Leaves that need the shared pymunk world step in this process and publish their outputs
on their topics; every other Leaf is a :class:`RemoteLeaf` whose ``do_step`` is a round trip
to its node (lockstep) or nothing at all (free: the node runs on its own timer and this
process only listens). Timeline changes are the scenario node's: at a timeline point's
instant (a phase's start or a change inside a phase) the simulator publishes ``/clock`` and
waits until the scenario node has put the point's values on the parameter server, then
applies them from there. It publishes ``/clock`` (simulated time, latched), writes the
run directory (trace.csv, metrics.json, scenario.yaml, plots) exactly as ``amsa-phys run``
does, and exits, which ends the launch.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from fractions import Fraction
from typing import Any

from ...engine import interrupt
from ...engine.face import SimDriver
from ...errors import RunFault
from ...model.scenario import Change
from .. import names
from ..graph import RosGraph
from . import readiness, rosio
from .arrays import array_msg, elements, pack, read
from .bagtail import BagTail, topic_counts
from .boundary import FLUSH, FLUSHED, VALUES, format_values, readable
from .config import NodeConfig
from .container import Container, stepped
from .pipeline import Pipeline
from .remoteerror import RemoteError
from .waves import DueAt, chained, wave


class Link:
    """The simulator's side of the graph: publishers, subscriptions, replies, the clock."""

    def __init__(self, rospy: Any, cfg: NodeConfig) -> None:
        self.rospy = rospy
        self.cfg = cfg
        self.graph: RosGraph = cfg.graph
        self.lockstep = cfg.mode == "lockstep"
        Float64, String, Clock = rosio.msgs()
        self.Float64, self.String, self.Clock = Float64, String, Clock
        self.cond = threading.Condition()
        self.gate = rosio.Gate(rospy, self.cond)
        world = self.graph.world
        #: free mode: the outputs nodes published since the loop last took them (buffer ->
        #: latest value); the loop's own thread writes them into the engine (:meth:`take`)
        self.fresh: dict[str, Any] = {}
        self.sim: SimDriver | None = None
        self.published = dict.fromkeys(self.graph.data(), 0)
        #: array ports (a lidar's ranges): one std_msgs/Float64MultiArray topic each
        self.Array = array_msg() if world.arrays else None
        #: a remote array output of the wrong length (buffer -> the message saying so)
        self.bad: dict[str, str] = {}
        self.received: dict[str, list[Any]] = {}
        self.replies: dict[str, list[str] | None] = {}
        self.ready: set[str] = set()
        #: how many of the timeline's points the scenario node has applied (``names.PHASE``),
        #: and the most the simulator has waited for
        self.points_acked = 0
        self.points_asked = 0
        self.seq = 0
        #: lockstep: the Leaves asked and not yet answered (path -> instant, sequence number)
        self.asked: dict[str, tuple[Fraction, str]] = {}
        self.waves = True
        self.due: DueAt | None = None
        self.last_clock = -1
        self.wall0: float | None = None
        self.speed = 1.0
        self.clock_pub = rosio.make_publisher(rospy, names.CLOCK, Clock, latch=True)
        #: lockstep: the buffers the boundary node reads, each Leaf step's values of them
        #: published with the step's instant (``boundary.py``: its messages' stamps)
        self.boundary_reads = readable(self.graph) if self.lockstep else set()
        # boundary:=true (names.P_BOUNDARY): the run starts once the boundary node listens, or
        # a fast (pipelined) run could be over before its first standard message
        told = self.boundary_reads and bool(rospy.get_param(names.P_BOUNDARY, False))
        self.values_pub = (
            (
                self.gate.publisher(VALUES, String, 1)
                if told
                else rosio.make_publisher(rospy, VALUES, String)
            )
            if self.boundary_reads
            else None
        )
        #: pipelined lockstep (pipeline.py): the container's Leaves asked many instants at once
        self.pipeline = Pipeline(self) if cfg.pipeline else None
        quiet = self.pipeline is not None  # no node reads a data topic: inputs come inline
        self.data_pubs = {
            b: self.gate.publisher(
                names.topic(b), self._kind(b), 0 if quiet else self.graph.subscribers(b)
            )
            for p in self.graph.local
            for b in self.graph.outputs(p)
        }
        self.step_pubs = {}
        self.subs = []
        self.data_subs: dict[str, Any] = {}
        #: lockstep: the Leaves of the C++ container, asked a wave at a time (container.py)
        self.shared = self.graph.shared if self.lockstep else frozenset()
        answers = self.pipeline.on_answers if self.pipeline else self._on_answers
        self.container = Container(rospy, self.gate, String, self.shared, answers)
        for path in self.graph.remote:
            for b in self.graph.outputs(path):
                self.received[b] = [0, self.graph.initial(b)]
                if path in self.shared:
                    continue  # lockstep: the container's answers carry the values
                self.data_subs[b] = rospy.Subscriber(
                    names.topic(b), self._kind(b), self._on_data, callback_args=b, tcp_nodelay=True
                )
                self.subs.append(self.data_subs[b])
            if self.lockstep:
                self.replies[path] = None
            if self.lockstep and path not in self.shared:
                self.step_pubs[path] = self.gate.publisher(names.step_topic(path), String, 1)
                self.subs.append(
                    rospy.Subscriber(
                        names.done_topic(path),
                        String,
                        self._on_done,
                        callback_args=path,
                        tcp_nodelay=True,
                    )
                )
        self.subs.append(rospy.Subscriber(names.PHASE, String, self._on_phase, tcp_nodelay=True))
        self.subs.append(rospy.Subscriber(names.READY, String, self._on_ready, tcp_nodelay=True))
        self.expected_ready = {*self.graph.remote, names.SCENARIO}
        #: bag:= (the recorder counted among every topic's subscribers): keep within a window
        #: of it, and wait for it at the end (``bagtail.py``)
        self.bag_tail: BagTail | None = None
        if self.graph.bag:
            self.bag_tail = BagTail(rospy, lambda: topic_counts(self), cfg.timeout)

    def _kind(self, data: str) -> Any:
        """The message class of a Data's topic."""
        return self.Array if self.graph.is_array(data) else self.Float64

    # -- callbacks (rospy's threads) ---------------------------------------------------------
    def _on_data(self, msg: Any, buffer: str) -> None:
        value, bad = read(self.graph, buffer, msg)
        if bad and not self.lockstep:  # free: the message is dropped, the last value stays
            self.rospy.logerr(f"{names.SIMULATOR}: {bad}")
            return
        with self.cond:
            r = self.received[buffer]
            r[0] += 1
            if bad:  # the step that published it fails, naming the topic
                self.bad.setdefault(buffer, bad)
                self.cond.notify_all()
                return
            r[1] = value
            if not self.lockstep:
                self.fresh[buffer] = value  # free mode: the latest value is the value
            self.cond.notify_all()

    def _on_done(self, msg: Any, path: str) -> None:
        with self.cond:
            self.replies[path] = msg.data.split("\n")
            self.cond.notify_all()

    def _on_answers(self, answers: list[tuple[str, str]]) -> None:
        """The container's answers for a wave, each as the Leaf's own node would send it."""
        with self.cond:
            for path, answer in answers:
                self.replies[path] = [answer]
            self.cond.notify_all()

    def _on_phase(self, msg: Any) -> None:
        with self.cond:
            self.points_acked = max(self.points_acked, int(msg.data))
            self.cond.notify_all()

    def _on_ready(self, msg: Any) -> None:
        # one name per node; a process hosting several Leaves (the C++ container) latches
        # one message naming every Leaf ready so far, separated by spaces
        with self.cond:
            self.ready.update(msg.data.split())
            self.cond.notify_all()

    # -- start ------------------------------------------------------------------------------
    def wait_ready(self, timeout: float) -> list[str]:
        """Wait for every node and our own publishers' subscribers.

        A node is ready when it says so on ``names.READY`` (every generated node does, once
        its publishers have all their subscribers). In free mode a node that does not (a
        user's own node) is ready once its topics are: each output it publishes is connected
        to this process and has as many subscribers registered with the master as the graph
        expects. In lockstep every Leaf node must answer step requests, so it must be ours
        or speak the protocol, and say so.
        """
        waiting: set[str] = set(self.expected_ready)

        def ready() -> bool:
            waiting.difference_update(self.ready)
            if waiting and not self.lockstep:
                subscribers = readiness.registered_subscribers(self.rospy)
                waiting.difference_update(
                    [n for n in waiting if n in self.graph.remote and self._up(n, subscribers)]
                )
            return not waiting

        missing = self.gate.wait(timeout, also=ready)
        nodes = sorted(waiting)
        return ([f"node /{n.replace('.', '/')}" for n in nodes] + missing) if missing else []

    def _up(self, path: str, subscribers: dict[str, int]) -> bool:
        return readiness.topics_up(self.graph, self.data_subs, path, subscribers)

    def attach(self, sim: SimDriver) -> None:
        """The simulation whose values free mode updates and whose events remote Leaves add."""
        self.sim = sim

    def take(self) -> None:
        """Free mode: what the nodes published since the last call, into the engine.

        Called by the loop's own thread (a hook, between the components' steps), through
        :meth:`Simulation.write`: a rospy thread never touches the engine's buffers (the
        loop holds the store's lock through a whole ``advance``, so a callback that wrote
        would wait until the run ends).
        """
        sim = self.sim
        if sim is None or not self.fresh:
            return
        with self.cond:
            fresh, self.fresh = self.fresh, {}
        for data, value in fresh.items():
            for buffer, v in elements(self.graph.world.arrays, data, value):
                sim.write(buffer, v)

    # -- waiting ----------------------------------------------------------------------------
    def _wait(self, ready: Callable[[], bool], who: str, t: Fraction, what: str) -> None:
        """Wait (condition, woken by callbacks) until ``ready()``; Ctrl-C or a silent node end it.

        A Ctrl-C (or roslaunch's SIGINT) raises at once: the nodes are stopping too, so this
        instant cannot be finished; the outputs describe the instants before it.
        """
        deadline = time.monotonic() + self.cfg.timeout
        with self.cond:
            while not ready():
                if interrupt.requested() or self.rospy.is_shutdown():
                    raise KeyboardInterrupt
                left = deadline - time.monotonic()
                if left <= 0:
                    raise RunFault(
                        who,
                        t,
                        f"no answer from ROS node {names.ns(who)} within "
                        f"{self.cfg.timeout:g} s ({what}; see its log)",
                    )
                self.cond.wait(min(left, 0.2))

    # -- lockstep requests -------------------------------------------------------------------
    def _ask(self, path: str, verb: str, args: str, t: Fraction) -> None:
        """Send ``VERB SEQ ARGS`` to a node (a Leaf of the container: with the others of the
        wave, ``container.send``); :meth:`_answer` waits for its answer."""
        self.seq += 1
        seq = str(self.seq)
        with self.cond:
            self.replies[path] = None
        self.asked[path] = (t, seq)
        if path in self.shared:
            self.container.add(path, f"{verb} {seq} {args}")
        else:
            self.step_pubs[path].publish(self.String(f"{verb} {seq} {args}"))

    def _answer(self, path: str, t: Fraction, what: str) -> list[str]:
        """Wait for a node's answer to what it was asked; ``[kind, seq, text]``.

        The events the Leaf recorded come with its answer and are recorded now, when the
        engine steps it (in a wave the answer may have arrived earlier).
        """
        _, seq = self.asked.pop(path)

        def answered() -> bool:
            reply = self.replies[path]
            return reply is not None and reply[0].split(" ")[1] == seq

        self._wait(answered, path, t, what)
        reply = self.replies[path]
        assert reply is not None
        if self.sim is not None:
            for line in reply[1:]:
                kind, _, detail = line.removeprefix("event ").partition("\t")
                self.sim.record_event(kind, detail)
        return reply[0].split(" ", 2)

    def _request(self, path: str, verb: str, args: str, t: Fraction, what: str) -> list[str]:
        """Ask a node and wait for its answer."""
        self._ask(path, verb, args, t)
        self.container.send()
        return self._answer(path, t, what)

    def _counts(self, path: str, plus: set[str]) -> str:
        """How many messages of each input a remote Leaf sees now: every message so far, less
        a delayed producer's still in flight; ``N+`` for an input in ``plus``, whose writer,
        asked in the same wave, adds what it publishes (``waves.chained``)."""
        sim = self.sim
        arrays = self.graph.world.arrays
        return " ".join(  # an array's elements travel together: its first one's count
            str(self.published[b] - (sim.in_flight(arrays.get(b, [b])[0]) if sim else 0))
            + ("+" if b in plus else "")
            for b in self.graph.input_buffers(path)
        )

    def _wave(self, path: str, t: Fraction) -> list[str]:
        """``path`` and the remote Leaves of this instant that can be asked with it
        (``waves.py``); ``[path]`` alone with ``waves:=false``."""
        sim = self.sim
        if not self.waves or sim is None:
            return [path]
        if self.due is None:
            grid, leaves = sim.grid, self.graph.world.leaves
            self.due = DueAt(
                self.graph.world.order,
                lambda p: grid.ticks(1 / Fraction(leaves[p].freq)),
                lambda p: grid.ticks(Fraction(sim.timer_phases.get(p, 0))),
            )
        due = self.due.at(sim.grid.ticks(t))
        return wave(self.graph, due, path) if path in due else [path]

    def step(self, path: str, t: Fraction) -> dict[str, float]:
        """One step of a remote Leaf at ``t``: its outputs as its node published them.

        The first remote Leaf of a wave asks every node of the wave at once (each with
        the counts of what it sees now); the others find their answer waiting.
        """
        if not self.lockstep:
            return {}
        if self.graph.bag or self.last_clock < 0:
            # lockstep: no node steps by /clock (each request carries its instant), the
            # scenario node gets it at each timeline point's instant (point_value); a bag's
            # recorder stamps messages by it, so it ticks at every step only when bag:= records
            self.publish_clock(t)
        asked = self.asked.get(path)
        if asked is None or asked[0] != t:
            now = self._wave(path, t)
            batch: list[str] = []
            for p in now:
                if p != path and p in self.asked:  # once an instant: asked is a step
                    continue
                plus = chained(self.graph, now, p)
                if any(b.rpartition(".")[0] not in batch for b in plus):
                    continue  # its writer was asked in an earlier message: ask it later
                batch.append(p)
                counts = self._counts(p, plus)
                self._ask(p, "step", f"{t.numerator} {t.denominator} {counts}", t)
            self.container.send()
        head = self._answer(path, t, "a step")
        kind, text = head[0], head[2] if len(head) > 2 else ""
        who = f"{path} ({self.graph.leaf(path).template.name()})"
        if kind == "error":
            raise RemoteError(text)
        if kind == "fault":
            raise RunFault(who, t, text)
        outputs = self.graph.outputs(path)
        if path in self.shared:  # the values come with the answer
            values = stepped(text, outputs)
            for b, v in values:
                self.published[b] += 1
                self.received[b] = [self.published[b], v]
            self.tell_boundary(t, values)
            return {b.rpartition(".")[2]: v for b, v in values}
        got = [outputs[int(i)] for i in text.split()]
        for b in got:
            self.published[b] += 1
        self._wait(
            lambda: all(self.received[b][0] >= self.published[b] for b in got),
            path,
            t,
            "its outputs",
        )
        bad = [b for b in got if b in self.bad]
        if bad:
            raise RunFault(who, t, self.bad[bad[0]])
        extra = [b for b in got if self.received[b][0] != self.published[b]]
        if extra:  # a node that stepped more often than asked: what it sees is no longer known
            b = extra[0]
            raise RunFault(
                who,
                t,
                f"{self.received[b][0]} messages on {names.topic(b)}, {self.published[b]} "
                "answered steps (a step asked twice, or another publisher on the topic)",
            )
        self.tell_boundary(t, [(b, self.received[b][1]) for b in got])
        return {b.rpartition(".")[2]: self.received[b][1] for b in got}

    def tell_boundary(self, t: Fraction, values: list[tuple[str, Any]]) -> None:
        """Lockstep: the values of a Leaf's step at ``t`` that the boundary node reads (an
        array port's as its elements' buffers, which the standard messages read)."""
        if self.values_pub is None or not self.values_pub.get_num_connections():
            return
        arrays = self.graph.world.arrays
        flat = [e for b, v in values for e in elements(arrays, b, v)]
        told = [(b, v) for b, v in flat if b in self.boundary_reads]
        if told:
            self.values_pub.publish(self.String(format_values(t, told)))

    def drain_boundary(self, timeout: float) -> bool:
        """Lockstep's end: wait until the boundary node has handled every values message
        (:data:`FLUSH`; ``boundary.py``), at most ``timeout`` s; False if it did not say so."""
        if self.values_pub is None or not self.values_pub.get_num_connections():
            return True
        flushed = threading.Event()
        sub = self.rospy.Subscriber(FLUSHED, self.String, lambda _msg: flushed.set())
        try:
            self.values_pub.publish(self.String(FLUSH))
            return flushed.wait(timeout)
        finally:
            sub.unregister()

    def reload(self, path: str, name: str, t: Fraction) -> None:
        """A remote Leaf re-reads one parameter now (a timeline change at its instant)."""
        if not self.lockstep:
            return  # free: the node notices at its next step
        head = self._request(path, "param", name, t, "a parameter change")
        if head[0] != "done":
            raise ValueError(head[2] if len(head) > 2 else "refused")

    # -- local Leaves --------------------------------------------------------------------------
    def publisher_of(self, path: str) -> Callable[[Fraction, Mapping[str, Any]], None]:
        """What publishes the outputs of a Leaf stepped here, at ``t``, on their topics."""
        ports = [(b.rpartition(".")[2], b) for b in self.graph.outputs(path)]
        pubs = self.data_pubs
        Float64 = self.Float64
        published = self.published
        arrays = self.graph.world.arrays
        # pipelined: no node of the graph reads the topics, so only a listener's are sent
        quiet = self.pipeline is not None

        def publish(t: Fraction, out: Mapping[str, Any]) -> None:
            sent: list[tuple[str, Any]] = []
            for port, b in ports:
                if port in out:
                    if quiet and not pubs[b].impl.connections:  # get_num_connections()
                        sent.append((b, out[port]))
                        continue
                    try:
                        if b in arrays:
                            number: Any = tuple(float(v) for v in out[port])
                            if len(number) != len(arrays[b]):
                                continue  # the engine reports it
                            pubs[b].publish(pack(self.Array, port, number))
                        else:
                            number = float(out[port])
                            pubs[b].publish(Float64(number))
                    except (TypeError, ValueError):
                        continue  # the engine reports it
                    published[b] += 1
                    sent.append((b, number))
            self.tell_boundary(t, sent)

        return publish

    # -- time and the timeline ---------------------------------------------------------------
    def publish_clock(self, t: Fraction) -> None:
        """``/clock`` = ``t`` (latched), if it moved."""
        ns = rosio.to_ns(t)
        if ns != self.last_clock:
            self.last_clock = ns
            self.clock_pub.publish(self.Clock(self.rospy.Time(ns // 10**9, ns % 10**9)))
            if self.bag_tail is not None:
                self.bag_tail.tick()

    def pace(self, t: Fraction) -> None:
        """Free mode: hold simulated time to ``speed`` x the wall clock, then publish it."""
        now = time.perf_counter()
        if self.wall0 is None:
            self.wall0 = now - float(t) / self.speed
        wait = self.wall0 + float(t) / self.speed - now
        if wait > 0:
            time.sleep(wait)  # real-time pacing is the point of free mode
        if interrupt.requested() or self.rospy.is_shutdown():
            raise KeyboardInterrupt
        self.publish_clock(t)

    def point_value(self, point: int, t: Fraction, change: Change) -> Any:
        """The value the scenario node set for ``change`` when it applied the timeline's
        ``point``-th point (1-based, ``Timeline.points``: a phase's start or a change inside
        a phase) at ``t``."""
        if point > self.points_asked:
            self.points_asked = point
            self.publish_clock(t)
        self._wait(lambda: self.points_acked >= point, names.SCENARIO, t, f"timeline point {point}")
        leaf = self.graph.leaf(change.leaf)
        return rosio.read_param(self.rospy, change.leaf, leaf.template.param(change.param))
