"""A Leaf as a ROS node: the project's own template class behind topics and parameters.

Inputs are ``std_msgs/Float64`` topics ``/Producer/output`` (an array port's:
``std_msgs/Float64MultiArray`` of the port's fixed length, ``rosio.pack``); outputs are
published on ``/Leaf/output``; parameters are read from ``/Leaf/param`` and judged by the
template (type, [min, max], rules between parameters) whenever they change.

**lockstep** (reproduces ``amsa-phys run``): the simulator sends ``step SEQ NUM DEN C1..Cn``
on ``names.step_topic(Leaf)`` — the instant as an exact fraction and, for each input topic, how many
of its messages the Leaf sees at that instant (all it has carried so far, less those a
producer's ``latency`` still holds in flight in the engine). The node steps once it has
received at least that many on each (messages on different topics travel on different
connections, so a count, not arrival order, says an input is current) and reads message
number C of each — the latest, unless a delayed producer has published later ones it must
not see yet (it keeps those until they are due) —, publishes its outputs, then
answers ``done SEQ I..`` (the outputs it published) on ``names.done_topic(Leaf)``.
``param SEQ NAME`` re-reads one parameter (a timeline change, at its exact instant). The
steps are driven by whichever callback completes the condition last: no thread ever blocks
waiting for another.

**free** (as the paper's generated nodes ran): the node steps on its own timer at its own
rate in simulated time (``/clock``), from its ``phase`` (drawn as the engine draws it for a
random one), with whatever its inputs hold then, and picks up parameter changes (the
scenario's, or a user's ``rosparam set``) at its next step. Latency and jitter are then the
real network's and timers', not the world's.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from ...engine.timing import leaf_phase
from ...errors import AmsaError, ConfigError
from .. import names
from ..boundary import SIM_PARAM
from ..graph import NodeContext
from . import notready, rosio, startup
from .arrays import array_msg, pack, unpack
from .config import load_config


@dataclass(frozen=True)
class BadMessage:
    """An array message of the wrong length, kept in its place: a step that would read it
    fails naming the topic (its count still advances, so the others stay in step)."""

    text: str


class LeafNode:
    """One remote Leaf: its component, subscriptions, publishers and protocol state."""

    def __init__(self, rospy: Any, path: str) -> None:
        self.rospy = rospy
        Float64, String, _ = rosio.msgs()
        self.Float64, self.String = Float64, String
        cfg = load_config(rospy)
        self.cfg = cfg
        graph = cfg.graph
        self.path = path
        self.leaf = leaf = graph.leaf(path)
        world = cfg.scenario.world
        self.params = rosio.read_params(rospy, leaf)
        self.raw = dict(self.params)
        self.comp = leaf.template(path, dict(self.params))
        self.ctx = NodeContext(cfg.scenario.seed, path, world)
        self.comp.initialize(self.ctx)
        self.lock = threading.Lock()
        self.ports = list(leaf.inputs.items())
        self.buffers = graph.input_buffers(path)
        self.outputs = graph.outputs(path)
        self.count = {b: 0 for b in self.buffers}
        self.value: dict[str, Any] = {b: graph.initial(b) for b in self.buffers}
        #: messages of delayed producers by number (0: the initial value), kept until the
        #: simulator says a later one is due; other producers' readers need only the latest
        self.delayed = {
            b for b in self.buffers if world.leaves[b.rpartition(".")[0]].timing.delayed
        }
        self.history: dict[str, dict[int, Any]] = {b: {0: self.value[b]} for b in self.delayed}
        self.own: dict[str, Any] = {b: graph.initial(b) for b in self.outputs}
        self.graph = graph
        Array = array_msg() if any(map(graph.is_array, self.buffers + self.outputs)) else None
        self.Array = Array
        kind = {b: Array if graph.is_array(b) else Float64 for b in self.buffers + self.outputs}
        self.pending: list[str] | None = None
        self.subs = [
            rospy.Subscriber(
                names.topic(b), kind[b], self._on_data, callback_args=b, tcp_nodelay=True
            )
            for b in self.buffers
        ]
        self.gate = rosio.Gate(rospy)
        # sim:=false (the controller side alone, ros/boundary.py): no simulator to wait for;
        # free mode needs no handshake, so the node starts at once
        sim = bool(rospy.get_param(SIM_PARAM, True))
        self.pubs = [
            self.gate.publisher(names.topic(b), kind[b], graph.subscribers(b) if sim else 0)
            for b in self.outputs
        ]
        if cfg.mode == "lockstep":
            self.done = self.gate.publisher(names.done_topic(path), String, 1)
            self.step_sub = rospy.Subscriber(
                names.step_topic(path), String, self._on_step, tcp_nodelay=True
            )
        else:
            for p in leaf.template.params:  # subscribe to updates from the start
                rosio.read_param(rospy, path, p, cached=True)

    # -- lockstep ---------------------------------------------------------------------------
    def _on_data(self, msg: Any, buffer: str) -> None:
        value: Any = msg.data
        if self.graph.is_array(buffer):
            try:
                value = unpack(msg, self.graph.size(buffer), names.topic(buffer))
            except ValueError as exc:
                if self.cfg.mode != "lockstep":  # free: the old value stays, said once a message
                    self.rospy.logerr(f"{self.path}: {exc}; keeping the last scan")
                    return
                value = BadMessage(str(exc))
        with self.lock:
            self.count[buffer] += 1
            self.value[buffer] = value
            if buffer in self.history:
                self.history[buffer][self.count[buffer]] = value
            if self.pending is not None:
                self._try()

    def _on_step(self, msg: Any) -> None:
        with self.lock:
            self.pending = msg.data.split()
            self._try()

    def _try(self) -> None:
        """Run the pending request if its inputs are all in (the lock is held)."""
        req = self.pending
        assert req is not None
        seq = req[1]
        if req[0] == "param":
            self.pending = None
            self._reply(seq, self._reload(req[2]))
            return
        counts = [int(c) for c in req[4:]]
        have = [self.count[b] for b in self.buffers]
        if any(h < c for h, c in zip(have, counts, strict=True)):
            return  # an input message is still on its way
        self.pending = None
        ahead = [
            h != c and b not in self.delayed
            for b, h, c in zip(self.buffers, have, counts, strict=True)
        ]
        if any(ahead):
            self._reply(seq, ("fault", f"inputs out of step: received {have}, expected {counts}"))
            return
        seen = dict(self.value)
        for b, c in zip(self.buffers, counts, strict=True):
            if b in self.history:  # message number c is what the Leaf sees now
                kept = self.history[b]
                seen[b] = kept[c]
                for old in [k for k in kept if k < c]:
                    del kept[old]
        bad = [v.text for v in seen.values() if isinstance(v, BadMessage)]
        if bad:
            self._reply(seq, ("fault", bad[0]))
            return
        self._reply(seq, self._step(Fraction(int(req[2]), int(req[3])), seen))

    def _reply(self, seq: str, result: tuple[str, str]) -> None:
        kind, text = result
        lines = [f"{kind} {seq} {text}".rstrip()]
        lines += [f"event {k}\t{d}" for k, d in self.ctx.events]
        self.ctx.events.clear()
        self.done.publish(self.String("\n".join(lines)))

    # -- stepping (both modes) --------------------------------------------------------------
    def _inputs(self, seen: dict[str, Any] | None = None) -> dict[str, Any]:
        value = self.value if seen is None else seen
        inp = {port: (self.own[b] if b in self.own else value[b]) for port, b in self.ports}
        for port, b in self.ports:  # an array port: a float array, as the engine gives it
            if self.graph.is_array(b):
                inp[port] = np.array(inp[port], dtype=float)
        return inp

    def _step(self, t: Fraction, seen: dict[str, float] | None = None) -> tuple[str, str]:
        """``do_step`` at ``t`` on ``seen`` (default: the latest messages); publish the
        outputs; the answer for the simulator."""
        try:
            out = self.comp.do_step(t, self._inputs(seen))
        except Exception as exc:  # the engine reports it as "do_step raised ..."
            return "error", repr(exc)
        values: list[tuple[int, Any]] = []
        ports = [b.rpartition(".")[2] for b in self.outputs]
        for key, value in (out or {}).items():
            if key not in ports:
                return "fault", f"published unknown output {key!r}"
            b = self.outputs[ports.index(key)]
            try:
                if self.graph.is_array(b):
                    number: Any = tuple(float(v) for v in value)
                    if len(number) != self.graph.size(b):
                        return "fault", (
                            f"output {key} has {len(number)} values, the port declares "
                            f"{self.graph.size(b)}"
                        )
                else:
                    number = float(value)
            except (TypeError, ValueError):
                return "fault", f"output {key} is not a number: {value!r}"
            values.append((ports.index(key), number))
        for index, number in values:
            b = self.outputs[index]
            if self.graph.is_array(b):
                self.pubs[index].publish(pack(self.Array, b.rpartition(".")[2], number))
            else:
                self.pubs[index].publish(self.Float64(number))
            self.own[b] = number
        return "done", " ".join(str(i) for i, _ in values)

    def _reload(self, name: str, cached: bool = False) -> tuple[str, str]:
        """Apply a parameter's value from the server (checked as a file value would be)."""
        param = self.leaf.template.param(name)
        try:
            value = rosio.read_param(self.rospy, self.path, param, cached=cached)
            self.leaf.template.check_params({**self.params, name: value})
        except ConfigError as exc:
            return "error", exc.message
        except ValueError as exc:
            return "error", str(exc)
        self.params[name] = value
        setattr(self.comp.p, name, value)
        try:
            self.comp.on_param_change(name, value)
        except Exception as exc:
            return "error", str(exc)
        return "done", ""

    # -- free -------------------------------------------------------------------------------
    def run_free(self) -> None:
        """Step at the Leaf's own rate in simulated time until shutdown."""
        clock = rosio.ClockFollower(self.rospy)
        period = 1 / self.leaf.freq
        world = self.cfg.scenario.world
        phase = leaf_phase(self.leaf, world, self.cfg.scenario.seed)
        k = 0
        missed = 0
        while not self.rospy.is_shutdown():
            t = phase + k * period
            if not clock.wait_until(rosio.to_ns(t)):
                break
            late = (Fraction(clock.ns, 1_000_000_000) - phase) // period
            if late > k:  # more than a period late: skip to the latest due instant
                missed += int(late - k)
                k = int(late)
                t = phase + k * period
            self._refresh_params()
            with self.lock:
                kind, text = self._step(t)
            if kind != "done":
                self.rospy.logerr(f"{self.path} at t={float(t):g} s: {text}")
            k += 1
        if missed:
            self.rospy.loginfo(f"{self.path}: {missed} steps skipped (the node ran late)")

    def _refresh_params(self) -> None:
        """Take parameter changes (scenario node, rosparam set) at this step; refuse bad ones."""
        for p in self.leaf.template.params:
            try:
                raw = self.rospy.get_param_cached(names.param(self.path, p.name))
            except KeyError:
                continue
            if raw == self.raw.get(p.name) or _same(raw, self.raw.get(p.name)):
                continue
            self.raw[p.name] = raw
            kind, text = self._reload(p.name, cached=True)
            if kind != "done":
                old = rosio.ros_value(self.params[p.name])
                self.rospy.logerr(f"{names.param(self.path, p.name)}: {text}; keeping {old!r}")
                # the server shows the value in use, not the refused one
                self.rospy.set_param(names.param(self.path, p.name), old)
                self.raw[p.name] = old


def _same(a: Any, b: Any) -> bool:
    return isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)


def main(path: str) -> None:
    """The node's entry point (the generated script calls it)."""
    rospy = rosio.ros()
    startup.init_node(rospy, path.rpartition(".")[2])
    try:
        node = LeafNode(rospy, path)
        started = time.monotonic()
        missing = node.gate.wait(node.cfg.timeout * 2)
        if rospy.is_shutdown():
            return  # roslaunch is stopping (another node failed, or Ctrl-C)
        if missing:
            rosio.fail(rospy, notready.message(path, node.gate, started))
        keep = rosio.announce_ready(rospy, path)
    except AmsaError as exc:
        rosio.fail(rospy, f"{path}: {exc}")
        return
    startup.started(rospy)
    if node.cfg.mode == "free":
        node.run_free()
    else:
        rospy.spin()
    del keep
