"""Lockstep in waves: the remote Leaves of one instant that can be asked to step together.

The engine steps an instant's Leaves one after the other, in the world's execution order.
Asking each node in turn and waiting for its answer made a step of scenario1 six round
trips through ROS, one after another. But a Leaf's inputs at an instant are already fixed
when no Leaf due before it at that instant still has to write one of them: then its node
can be asked at once, with the message counts the simulator computes now, and its answer
is the same as if it had been asked in turn. So when the engine steps a remote Leaf, the
simulator asks, in one go, that Leaf and every later remote Leaf of the instant whose
inputs are fixed (a *wave*); the nodes step in parallel, and the engine, reaching each of
them in its order, takes the answer that is waiting.

A Leaf's inputs are *not* fixed if it reads an output of a Leaf due between the one stepped
now (included) and itself whose publications are visible at once. And a Leaf whose own
publications are visible at once does not join a wave if a node due between the one stepped
now (included) and itself reads them, in the wave or not: that reader (the schedule cut a
loop there) must step on the older message, and a node holds its reader to the exact count
of messages, so the new one must not reach it first. In the platoon (each car's actuator
scheduled before its controller, the controller before its sensors) the ten actuators form
one wave, then each car's controller and its four sensors two more. A producer with latency
or jitter does not count: what its reader sees now is what was sent earlier and is no
longer in flight (``published - in_flight``), a number its step leaves unchanged (its new
message goes in flight, never visible at the same instant). In scenario1 the four sensors
and the actuator (which reads the controller through its latency) form one wave, the
controller (which reads the sensors) a second: two waits an instant instead of six.

The Leaves of the C++ container (``graph.shared``: one process) go further: a container
Leaf whose unfixed inputs are all written by container Leaves already in the wave joins it
too, and its request counts those inputs as ``N+``: the messages before this instant plus
what the writer publishes in this step, which the container adds once the writer has
stepped (it steps the wave's Leaves in their order of dependence and answers for the whole
wave in one message). In scenario1 every remote Leaf is in the container: one wave, one
request and one answer an instant.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ..graph import RosGraph


def wave(graph: RosGraph, due: Sequence[str], start: str) -> list[str]:
    """``start`` and the remote Leaves after it in ``due`` whose inputs are fixed now.

    ``due`` is every Leaf (in the simulator or not) due at this instant, in execution
    order; ``start`` is the remote Leaf the engine steps now (every Leaf before it in
    ``due`` has stepped already).
    """
    remote = set(graph.remote)
    pending: set[str] = set()  # buffers a Leaf due later at this instant can still write
    read: set[str] = set()  # buffers the nodes due from ``start`` on read, up to here
    out: list[str] = []
    for path in due[due.index(start) :]:
        inputs = graph.input_buffers(path)
        outputs = graph.outputs(path)
        delayed = graph.leaf(path).timing.delayed
        waiting = [b for b in inputs if b in pending]
        if path in remote and (
            path == start
            or (
                (not waiting or _chained(graph, out, path, waiting))
                # a node due before this one (asked now or later) reads what this one
                # writes at once: it must step on the older message first (a loop the
                # schedule cut), and a node holds its reader to the exact count
                and (delayed or not any(b in read for b in outputs))
            )
        ):
            out.append(path)
        if path in remote:
            read.update(inputs)
        if not delayed:
            pending.update(outputs)
    return out


def _chained(graph: RosGraph, out: list[str], path: str, waiting: list[str]) -> bool:
    """Whether a Leaf of the C++ container whose inputs are not fixed yet may still join:
    every such input is written by a Leaf of the container already in the wave, which the
    container steps first and whose messages of this step it counts in (:func:`chained`)."""
    shared = graph.shared
    return path in shared and all(
        (p := b.rpartition(".")[0]) in shared and p in out for b in waiting
    )


def chained(graph: RosGraph, asked: list[str], path: str) -> set[str]:
    """The inputs of ``path`` written at once by a Leaf asked before it in the same wave
    (``asked``): both are in the C++ container, and the count the simulator sends for such
    an input is the count before this instant's step, plus what that Leaf publishes now,
    which only the container knows when it steps ``path`` (``N+`` in the request)."""
    if path not in graph.shared:
        return set()
    before = set(asked[: asked.index(path)]) if path in asked else set(asked)
    world = graph.world
    return {
        b
        for b in graph.input_buffers(path)
        if (p := b.rpartition(".")[0]) in before and not world.leaves[p].timing.delayed
    }


class DueAt:
    """Which Leaves are due at an instant (in ticks), from their periods and timer phases.

    A Leaf steps at the ticks ``phase + k * period`` (``engine/schedule.py``), in the
    world's execution order.
    """

    def __init__(
        self, order: Sequence[str], period: Callable[[str], int], phase: Callable[[str], int]
    ) -> None:
        self.timers = [(p, period(p), phase(p)) for p in order]
        self.tick = -1
        self.due: list[str] = []

    def at(self, tick: int) -> list[str]:
        """The Leaves due at ``tick``, in execution order (kept for the last tick asked)."""
        if tick != self.tick:
            self.tick = tick
            self.due = [p for p, n, ph in self.timers if tick >= ph and (tick - ph) % n == 0]
        return self.due
