"""The ROS graph of a world: which Leaf runs where, and who listens to what.

A Leaf whose ``initialize`` asks for a shared service of the run (``ctx.shared``: the pymunk
world) or adds an engine hook cannot live alone in a process: it runs inside the simulator
node, which owns the physics (the Leader and the Follower share one pymunk space). Every
other Leaf is its own node. :func:`classify` finds out by initializing each Leaf with a
context that refuses those two calls, so a new template that needs the physics (a lidar's
ray casts) lands in the simulator without anyone listing it.

The expected number of subscribers of every topic is computed here, by every node from the
same inputs, for the start-up handshake: a publisher is ready when that many subscribers
are connected, since ROS 1 drops what is published before a subscriber connects.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from ..engine.rng import component_rng
from ..errors import ConfigError
from ..model import placement
from ..model.placement import AloneContext
from ..model.world import LeafSpec, WorldSpec
from . import names


class NodeContext(AloneContext):
    """What a Leaf's ``initialize`` gets in its own node: the run's random stream for its
    path, no shared world; ``events`` are sent to the simulator with its next answer."""

    def __init__(self, seed: int, path: str, world: WorldSpec) -> None:
        super().__init__(path, world, component_rng(seed, path))


def classify(world: WorldSpec, seed: int = 0, paths: Iterable[str] | None = None) -> list[str]:
    """The Leaves (of ``paths``, default all) that must run inside the simulator node, in
    world order (:func:`amsa_phys.model.placement.classify` with the nodes' own context)."""
    return placement.classify(world, lambda path: NodeContext(seed, path, world), paths)


@dataclass
class RosGraph:
    """The nodes and topics of one exported world."""

    world: WorldSpec
    local: frozenset[str]
    bag: bool = False
    #: the Leaves hosted together in one process (the C++ container, ``names.P_CONTAINER``)
    shared: frozenset[str] = frozenset()
    #: the signals the adapt node reads when it runs the rules beside the simulator
    #: (``rules:=node``): it is one more subscriber of each
    adapt_signals: frozenset[str] = frozenset()

    @classmethod
    def of(
        cls,
        world: WorldSpec,
        local: Iterable[str],
        bag: bool = False,
        shared: Iterable[str] = (),
        adapt_signals: Iterable[str] = (),
    ) -> RosGraph:
        """The graph with ``local`` Leaves in the simulator and ``shared`` ones in the C++
        container (checked against the world)."""
        local = frozenset(local)
        shared = frozenset(shared)
        for what, leaves in ((names.P_LOCAL, local), (names.P_CONTAINER, shared)):
            unknown = sorted(leaves - set(world.leaves))
            if unknown:
                raise ConfigError(f"unknown Leaf {unknown[0]!r} in {what}")
        return cls(world, local, bag, shared, frozenset(adapt_signals))

    @property
    def remote(self) -> list[str]:
        """The Leaves that are nodes of their own, in world order."""
        return [p for p in self.world.leaves if p not in self.local]

    def leaf(self, path: str) -> LeafSpec:
        """The Leaf at ``path``."""
        return self.world.leaves[path]

    def input_buffers(self, path: str) -> list[str]:
        """The distinct buffers a remote Leaf subscribes to, in port order (its own excluded).

        A Leaf reading its own output keeps its last value: no subscription.
        """
        out: list[str] = []
        for buffer in self.leaf(path).inputs.values():
            if buffer.rpartition(".")[0] != path and buffer not in out:
                out.append(buffer)
        return out

    def outputs(self, path: str) -> list[str]:
        """A Leaf's buffers, in its template's output order."""
        return [f"{path}.{p.name}" for p in self.leaf(path).template.outputs]

    def subscribers(self, buffer: str) -> int:
        """How many subscribers the topic of ``buffer`` has once everything is connected.

        ROS 1 counts processes, not subscriptions: the Leaves of the C++ container
        (:attr:`shared`) that read a topic are one subscriber of it (roscpp subscribes a
        process once per topic), as the master registers them (one node).
        """
        producer = buffer.rpartition(".")[0]
        readers = [p for p in self.remote if p != producer and buffer in self.input_buffers(p)]
        n = sum(1 for p in readers if p not in self.shared)
        n += 1 if any(p in self.shared for p in readers) else 0
        if producer not in self.local:
            n += 1  # the simulator: the trace, and the Leaves it steps
        n += 1 if buffer in self.adapt_signals else 0  # the adapt node (rules:=node)
        return n + (1 if self.bag else 0)

    def data_topics(self) -> list[str]:
        """Every Data topic, in trace-column order (an array port's once, at its first element)."""
        return [names.topic(b) for b in self.data()]

    # -- array ports (a lidar's ranges): one topic per port, std_msgs/Float64MultiArray -------
    def data(self) -> list[str]:
        """Every Data as the package has topics: scalar buffers, and each array port by its
        name (``Scanner.ranges``, not its elements), in trace-column order."""
        element = {e: name for name, elements in self.world.arrays.items() for e in elements}
        out: list[str] = []
        for b in self.world.buffers:
            name = element.get(b, b)
            if name == b or b == self.world.arrays[name][0]:
                out.append(name)
        return out

    def is_array(self, data: str) -> bool:
        """Whether ``data`` (a buffer or port name, as :meth:`outputs` gives) is an array port."""
        return data in self.world.arrays

    def size(self, data: str) -> int:
        """How many numbers a Data's topic carries (1: a scalar, std_msgs/Float64)."""
        return len(self.world.arrays[data]) if data in self.world.arrays else 1

    def initial(self, data: str) -> float | tuple[float, ...]:
        """The value a Data holds before its producer first publishes (an array: a tuple)."""
        buffers = self.world.buffers
        if data in self.world.arrays:
            return tuple(float(buffers[e].initial) for e in self.world.arrays[data])
        return float(buffers[data].initial)

    def producer(self, data: str) -> str:
        """The Leaf that publishes ``data``."""
        if data in self.world.arrays:
            return data.rpartition(".")[0]
        return self.world.buffers[data].producer
