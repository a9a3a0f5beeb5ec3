"""A run's engine with a user's ROS 2 nodes as Leaves: the engine's side of the bridge.

Each external Leaf (``ros/external.py``) is built, then passed through the engine's ``wrap=``
hook, which puts an :class:`ExternalLeaf` in its place: stepping it, and each parameter
change, is a round trip over ROS 2 through the :class:`~.bridge.Bridge` (which owns the
rclpy side and says what a node did wrong). :class:`ExternalSimulation` is the run's
``Simulation`` with those Leaves (``runs/single.py`` names it; ``ros2 lockstep`` builds it
with private input topics).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from fractions import Fraction
from typing import Any

from ...engine.runner import Simulation
from ...model.scenario import Scenario
from ...model.template import Template
from .. import external
from ..external import ExternalLeaf as Wiring
from .bridge import Bridge


class ExternalLeaf:
    """In the engine, a Leaf that is a user's ROS 2 node: stepping it is a round trip.

    Everything but stepping and parameter changes is the built component's own (its ``p``
    holds the values the node was given), so the engine and the metrics see the Leaf as in
    an in-process run.
    """

    def __init__(self, comp: Template, wiring: Wiring, bridge: Bridge) -> None:
        self._comp = comp
        self._wiring = wiring
        self._bridge = bridge

    def __getattr__(self, name: str) -> Any:
        return getattr(self._comp, name)

    def initialize(self, ctx: Any) -> None:
        """Wait for the node, then give it every parameter's value."""
        self._bridge.connect(self._wiring)
        self._bridge.set_params(
            self._wiring,
            {p.name: getattr(self._comp.p, p.name) for p in self._wiring.params},
            start=True,
        )

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The node's step."""
        return self._bridge.step(self._wiring, t, inp)

    def on_param_change(self, name: str, value: Any) -> None:
        """The node's parameter, set now (before anything steps at this instant)."""
        self._bridge.set_params(self._wiring, {name: value})


class ExternalSimulation(Simulation):
    """The engine with the scenario's ``ros2:`` Leaves stepped by the user's nodes.

    Every Leaf is called on its own (``grouping=False``): a node answers for one Leaf.
    ``private_inputs``: each node's inputs on topics of its own (``names.input_topic``, an
    exported package's nodes remapped to them by ``ros2 lockstep``), so nodes wired to each
    other see what the engine delivers (a producer's latency included).
    :meth:`close` leaves the graph; :meth:`external_report` is the count of every node's
    steps and answers, for ``metrics.json``.
    """

    def __init__(
        self,
        scenario: Scenario,
        timeout_s: float,
        private_inputs: bool = False,
        watch: Callable[[], tuple[str, str] | None] | None = None,
        **kw: Any,
    ) -> None:
        wirings = external.describe(scenario.world, scenario.ros2, private_inputs)
        self.bridge = Bridge(
            wirings, timeout_s, lambda: self.now, scenario.world.arrays, watch, private_inputs
        )
        by_path = {w.path: w for w in wirings}

        def wrap(path: str, comp: Template) -> Any:
            if path in by_path:
                return ExternalLeaf(comp, by_path[path], self.bridge)
            return comp

        try:
            super().__init__(
                scenario.world,
                **Simulation.scenario_kwargs(scenario),
                wrap=wrap,
                grouping=False,
                **kw,
            )
        except BaseException:
            self.bridge.close()
            raise
        # the STL requirements sampled as in process, so metrics.json judges them the same
        self.watch_requirements(scenario)

    def close(self) -> None:
        """Leave the ROS 2 graph."""
        self.bridge.close()

    def external_report(self) -> dict[str, Any]:
        """Each node's steps and answers."""
        return self.bridge.report()


def simulation(timeout_s: float = external.DEFAULT_TIMEOUT_S) -> Callable[..., Simulation]:
    """The factory ``runs/single.py`` calls for a scenario with ``ros2:`` Leaves."""

    def make(scenario: Scenario, trace: Any) -> Simulation:
        return ExternalSimulation(scenario, timeout_s, trace=trace)

    return make
