"""What the simulator node runs in place of the world's Leaves, given to the engine by ``wrap=``.

The engine builds every component and passes each through ``Simulation(wrap=...)``
(``engine/runner.py``); :func:`stand_ins` is that hook. A Leaf that is a node becomes a
:class:`RemoteLeaf` (stepping it is asking its node to step); a Leaf that steps here (it
shares the pymunk world) becomes a :class:`PublishingLeaf`, the component itself with its
outputs published on their topics after each step. Nothing replaces entries of
``Simulation.components`` or methods of a component after construction. In
pipelined lockstep a Leaf of the C++ container is a ``pipeline.CheckedLeaf``: its template
steps here and its node is asked to do the same, the answers checked.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from ...model.template import Template
from . import rosio
from .pipeline import CheckedLeaf

if TYPE_CHECKING:  # the link imports this module
    from .simulator import Link


class RemoteLeaf:
    """In the engine, a Leaf that is a node: stepping it is asking its node to step."""

    def __init__(self, path: str, p: Any, link: Link, now: Callable[[], Fraction]) -> None:
        self.path = path
        self.p = p
        self.link = link
        self._now = now

    def initialize(self, ctx: Any) -> None:
        """The node initialized itself."""

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """A round trip to the node (lockstep); nothing (free)."""
        return self.link.step(self.path, t)

    def on_param_change(self, name: str, value: Any) -> None:
        """The node re-reads the parameter now."""
        self.link.reload(self.path, name, self._now())


class PublishingLeaf:
    """A Leaf stepped here, its outputs published on their topics after each step.

    Everything but ``do_step`` is the component's own (its ``p``, ``initialize``, any
    attribute the engine or a test reads), so the physics sharing and parameter changes
    work as in ``amsa-phys run``.
    """

    def __init__(
        self, comp: Template, publish: Callable[[Fraction, Mapping[str, Any]], None]
    ) -> None:
        self._comp = comp
        self._publish = publish

    def __getattr__(self, name: str) -> Any:
        return getattr(self._comp, name)

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Any:
        """The component's step, then its outputs on their topics."""
        out = self._comp.do_step(t, inp)
        if out:
            self._publish(t, out)
        return out


def stand_ins(link: Link, now: Callable[[], Fraction]) -> Callable[[str, Template], Any]:
    """The ``wrap=`` hook: each built component, as the simulator node runs it.

    A local Leaf takes its parameters from the server here, at construction (the params
    file or a ``rosparam set`` before the launch is what runs).
    """
    graph = link.graph

    def wrap(path: str, comp: Template) -> Any:
        pipelined = link.pipeline is not None and path in graph.shared
        if path in graph.remote and not pipelined:
            return RemoteLeaf(path, comp.p, link, now)
        if path in graph.local or pipelined:
            for name, value in rosio.read_params(link.rospy, graph.leaf(path)).items():
                setattr(comp.p, name, value)
        if pipelined:  # stepped here too, its node asked to do the same (pipeline.py)
            return CheckedLeaf(path, comp, link, now)
        if path in graph.local:
            return PublishingLeaf(comp, link.publisher_of(path))
        return comp

    return wrap
