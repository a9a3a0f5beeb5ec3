"""Pipelined lockstep: the container's Leaves asked many instants at once, every answer checked.

In lockstep the simulator waits, at every instant, for the answers of the nodes stepped at
it: a round trip through rospy and roscpp per instant (0.24-0.31 ms on loopback here), which
alone makes a run of scenario1 ~5x its in-process loop however little the nodes compute.
When every remote Leaf is a C++ Leaf of the container (``graph.shared``; ``names.P_PIPELINE``,
set by the launch file), the simulator need not wait: it steps each Leaf's in-process
template (its *twin*, the very code ``amsa-phys run`` steps) and queues, for the Leaf's node,
a request that carries the inputs the twin was given (``call SEQ NUM DEN V1..Vn``, C hex
floats by input port) or a parameter's new value (``set SEQ NAME VALUE``). The queue goes
out as one message every :data:`BATCH` requests; the container runs them in order, on one
thread, and answers them all in one message (``files/amsa_container.h``: onPipelined).

Every answer is checked against what the twin did: the outputs the node published and their
values, bit for bit (``float.hex``), and that a parameter value was taken. A difference ends
the run with a fault naming the Leaf, the instant, the output and both values. So a run that
completes is one in which every node step, given the inputs of that step, published exactly
what the twin published; by induction over the instants it is the run the nodes would have
driven with the simulator waiting for them (``pipeline:=false``), byte for byte. What it
does not exercise is the nodes' data topics (their inputs come with the requests): the
exact protocol (``pipeline:=false``) and free mode do.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from ...errors import RunFault
from ...model.template import Template
from .. import names
from .container import stepped

if TYPE_CHECKING:  # the link imports this module
    from .simulator import Link

#: Requests a message: ~80 instants of scenario1's six Leaves (one message, one answer)
BATCH = 480
#: Messages sent and not yet answered before the simulator waits for the oldest: enough to
#: keep the container busy while the simulator steps on, few enough that a divergence is
#: reported within a few batches of where it happened
DEPTH = 2


def _hex(value: Any) -> str:
    """An input's value as the container reads it: a C hex float, an array's as ``[V,V,..]``."""
    if isinstance(value, float):
        return value.hex()
    try:
        return "[" + ",".join(float(v).hex() for v in value) + "]"
    except TypeError:
        return float(value).hex()


class Pipeline:
    """The simulator's side of pipelined lockstep: the queue, the batches, the checks."""

    def __init__(self, link: Link) -> None:
        self.link = link
        graph = link.graph
        self.lines: list[str] = []
        #: sequence number -> (Leaf, instant, the node's answer if it does what its twin did:
        #: ``done SEQ I J .. | VI VJ ..`` with the values as ``float.hex`` writes them, which
        #: is how the container writes them, or ``done SEQ`` for a parameter value taken)
        self.expected: dict[str, tuple[str, Fraction, str]] = {}
        self.answers: deque[list[tuple[str, str]]] = deque()
        self.in_flight = 0
        self.outputs = {p: graph.outputs(p) for p in graph.shared}
        #: each Leaf's request head, input ports (the template's order) and output ports
        #: (port, index)
        self.leaves = {
            p: (
                f"{names.ns(p)} call ",
                [i.name for i in graph.leaf(p).template.inputs],
                [(b.rpartition(".")[2], str(k)) for k, b in enumerate(self.outputs[p])],
            )
            for p in graph.shared
        }

    # -- the engine's side ------------------------------------------------------------------
    def stepped(self, path: str, t: Fraction, inp: Mapping[str, Any], out: Any) -> None:
        """The twin of ``path`` stepped at ``t`` on ``inp`` and published ``out``: queue the
        node's request, and what it must answer."""
        self.link.seq += 1
        seq = str(self.link.seq)
        head, ports, outputs = self.leaves[path]
        values = " ".join([v.hex() if type(v) is float else _hex(v) for v in map(inp.get, ports)])
        self.lines.append(f"{head}{seq} {t.numerator} {t.denominator} {values}")
        if out:
            done = [(k, _hex(out[port])) for port, k in outputs if port in out]
            want = "".join([" " + k for k, _ in done]) + " |" + "".join([" " + v for _, v in done])
        else:
            want = " |"
        self.expected[seq] = (path, t, f"done {seq}{want}")
        if len(self.lines) >= BATCH:
            self.send()

    def changed(self, path: str, name: str, value: Any, t: Fraction) -> None:
        """A parameter of ``path`` took ``value`` at ``t`` (timeline, rule or live edit): the
        node is told the value itself (the server may hold a later phase's by the time the
        container reads the request)."""
        seq = self._seq()
        self.lines.append(f"{names.ns(path)} set {seq} {name} {float(value).hex()}")
        self.expected[seq] = (path, t, f"done {seq}")

    def send(self) -> None:
        """The queued requests in one message; then take the answers in, waiting for the
        oldest batch if :data:`DEPTH` are out."""
        if self.lines:
            self.link.container.pub.publish(self.link.String("\n".join(self.lines)))
            self.lines = []
            self.in_flight += 1
        self._take(lambda: self.in_flight <= DEPTH)

    def drain(self) -> None:
        """The run's end: every request sent, answered and checked."""
        self.send()
        self._take(lambda: not self.expected)

    # -- answers ----------------------------------------------------------------------------
    def on_answers(self, answers: list[tuple[str, str]]) -> None:
        """The container's answer to one message (rospy's thread): kept for the engine's."""
        with self.link.cond:
            self.answers.append(answers)
            self.link.cond.notify_all()

    def _take(self, enough: Callable[[], bool]) -> None:
        """Check every answer arrived, then wait for more until ``enough()``."""
        while True:
            with self.link.cond:
                batches = list(self.answers)
                self.answers.clear()
            for batch in batches:
                self.in_flight -= 1
                for path, answer in batch:
                    self._check(path, answer)
            if enough():
                return
            oldest = min(self.expected.values(), key=lambda e: e[1])
            self.link._wait(
                lambda: bool(self.answers), names.CONTAINER, oldest[1], "pipelined answers"
            )

    def _check(self, path: str, answer: str) -> None:
        """One node's answer against what its twin did, as text: a fault if they differ."""
        kind, _, rest = answer.partition(" ")
        seq, _, text = rest.partition(" ")
        expected = self.expected.pop(seq, None)
        if expected is None:
            raise RunFault(names.CONTAINER, 0, f"an answer to no request: {answer[:200]}")
        leaf, t, want = expected
        if answer == want:
            return
        who = f"{leaf} ({self.link.graph.leaf(leaf).template.name()})"
        if kind == "fault":
            raise RunFault(who, t, text)
        if kind != "done":
            did = "failed" if "|" in want else "refused the parameter value"
            raise RunFault(who, t, f"its node {did} where its template did not: {text}")
        outputs = self.outputs[leaf]
        got = stepped(text, outputs)
        raise RunFault(who, t, diverged(leaf, got, stepped(want.split(" ", 2)[2], outputs)))

    def _seq(self) -> str:
        self.link.seq += 1
        return str(self.link.seq)


def diverged(path: str, got: list[tuple[str, float]], want: list[tuple[str, float]]) -> str:
    """What a node published that its in-process template did not, in one line."""

    def show(pairs: Sequence[tuple[str, float]]) -> str:
        return ", ".join(f"{b.rpartition('.')[2]}={v!r}" for b, v in pairs) or "nothing"

    return (
        f"its node {names.ns(path)} published {show(got)} where its in-process template "
        f"published {show(want)}, on the same inputs (the package is not this model's: "
        "export it again, or run with pipeline:=false to follow the node)"
    )


class CheckedLeaf:
    """Pipelined lockstep: a container Leaf stepped here by its template, its node asked to
    do the same (:class:`Pipeline`). Everything but ``do_step`` and ``on_param_change`` is
    the component's own, as for ``standins.PublishingLeaf``."""

    def __init__(self, path: str, comp: Template, link: Link, now: Callable[[], Fraction]) -> None:
        self._path = path
        self._comp = comp
        self._link = link
        self._now = now
        pipeline = link.pipeline
        assert pipeline is not None
        self._pipeline = pipeline

    def __getattr__(self, name: str) -> Any:
        return getattr(self._comp, name)

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Any:
        """The template's step; the node's, queued; the boundary told the values."""
        link = self._link
        if link.last_clock < 0:
            link.publish_clock(t)  # the first instant, as the exact protocol's first ask
        out = self._comp.do_step(t, inp)
        self._pipeline.stepped(self._path, t, inp, out)
        if out and link.values_pub is not None and link.values_pub.impl.connections:
            ports = self._pipeline.outputs[self._path]
            link.tell_boundary(
                t, [(b, out[b.rpartition(".")[2]]) for b in ports if b.rpartition(".")[2] in out]
            )
        return out

    def on_param_change(self, name: str, value: Any) -> None:
        """The template takes the value now; its node with the next message."""
        self._comp.on_param_change(name, value)
        self._pipeline.changed(self._path, name, value, self._now())
