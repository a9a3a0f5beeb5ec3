"""The engine as the simulator node runs it: remote Leaves, parameters from the server.

:class:`RosSimulation` is ``engine.runner.Simulation`` with the world's Leaves passed through
``standins.stand_ins`` (a Leaf that is a node is stepped over ROS by the :class:`Link`),
timeline values read from the parameter server where the scenario node put them, and, in
free mode, hooks that hold simulated time to the wall clock and take live ``rosparam set``
edits. Split from ``simulator.py`` (the node: the link, start-up and the run).
"""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING, Any

from ...engine.plugs import Plugs
from ...engine.runner import Simulation
from ...model.adaptrules import Rule
from ...model.scenario import Change, Scenario
from .. import names
from . import adaptlink, rosio
from .records import start_values
from .standins import stand_ins


def awaited_signal(scenario: Scenario, remote: list[str]) -> str | None:
    """The quality signal if a node publishes it (its producer is a remote Leaf), else None:
    in free mode such a buffer holds its port's initial value until the node's first
    message, which the metrics must not count as a measurement."""
    if scenario.quality is None:
        return None
    signal = scenario.quality.signal
    return signal if signal.rpartition(".")[0] in remote else None


if TYPE_CHECKING:  # the simulator node imports this module
    from collections.abc import Mapping

    from ...engine.adapt import AdaptRules
    from .simulator import Link


class RosSimulation(Plugs):
    """The engine (:attr:`sim`) with remote Leaves, parameters from the server, ``/clock``
    published: the plugs the engine calls at its instants, and the free-mode hooks."""

    def __init__(self, scenario: Scenario, trace: Any, link: Link) -> None:
        self.link = link
        #: the engine, driven by ``runs.single.run_scenario`` as any run's: adapt: rules fire
        #: here, at its exact instants (both modes; a change is put on the parameter server
        #: before the Leaf is told: rule_change), the STL requirements sampled as in process
        self.sim = Simulation.from_scenario(
            scenario,
            trace=trace,
            # remote Leaves and publishing local ones stand in for the world's (standins.py)
            wrap=stand_ins(link, lambda: self.sim.now),
            # every Leaf is called on its own: a node per Leaf, a topic per output
            grouping=False,
            plugs=self,
        )
        sim = self.sim
        link.attach(sim)
        graph = link.graph
        #: the timeline's changes, each with the number of its point (1-based): the scenario
        #: node announces how many points it has applied, a phase's start or a step inside one
        points = enumerate(sim.timeline.points(), start=1)
        self.point_of = {id(c): k for k, point in points for c in point.changes}
        # every Leaf's parameters as last seen (free mode: a value on the server that differs
        # is an edit, recorded as an event whether the Leaf steps here or in its node; timeline
        # changes are applied apart, at their instant). It starts from the values the run
        # starts with (the server's, folded into phase 0 when the run began: records.py),
        # not from a second read of the server: an edit landing between the two reads was
        # taken as already seen, and lost
        start = start_values(scenario)
        self.seen = {
            (path, p.name): rosio.ros_value(start[(path, p.name)])
            for path in scenario.world.leaves
            for p in graph.leaf(path).template.params
        }
        #: free mode: the quality signal a node publishes, until its first message (its
        #: port's initial value before that is no measurement: no quality sample is taken)
        self.awaited = awaited_signal(scenario, graph.remote) if not link.lockstep else None
        sim.hold_quality(self.awaited is not None)
        if not link.lockstep:
            rate = (
                Fraction(str(scenario.world.physics["rate"])) if graph.local else scenario.log_rate
            )
            sim.add_hook(rate, self.pace, "ros clock")
            sim.add_hook(scenario.log_rate, self.live_params, "ros parameters")

    # -- the engine's plugs (engine/plugs.py) --------------------------------------------
    def run_ended(self) -> None:
        """Pipelined lockstep: the last answers checked."""
        if self.link.pipeline is not None:
            self.link.pipeline.drain()

    def timeline_change(self, change: Change, at: Fraction) -> Change:
        """A timeline change, with the value the scenario node put on the parameter server."""
        value = self.link.point_value(self.point_of[id(change)], at, change)
        return Change(change.leaf, change.param, value)

    def rule_change(self, change: Change) -> None:
        """An ``adapt:`` rule fired: its value on the parameter server before the Leaf is
        told, so a node reading the server sees what runs."""
        rosio.set_param(self.link.rospy, change.leaf, change.param, change.value)

    def rule_due(
        self, rules: AdaptRules, now: Fraction, values: Mapping[str, float]
    ) -> tuple[Rule, str] | None:
        """``rules:=node``: the adapt node says which rule fires now; applied as the engine
        applies its own firing (``adaptlink.py``). Otherwise the engine's own rules."""
        if not self.link.cfg.rules_node:
            return super().rule_due(rules, now, values)
        fired = adaptlink.due(self.link, self.sim, now)
        if fired is None:
            return None
        number, detail = fired
        # counted as the engine's own firings are (metrics.json's adapt_switches)
        rules.switches += 1
        return next(r for r in rules.rules if r.number == number), detail

    # -- free mode's hooks -----------------------------------------------------------------
    def pace(self) -> None:
        """Free mode: hold to the wall clock, then take what the nodes published meanwhile."""
        self.link.pace(self.sim.now)
        awaited = self.awaited
        arrived = False
        if awaited is not None:
            with self.link.cond:  # only take() empties fresh: what is there now is taken now
                arrived = awaited in self.link.fresh
        self.link.take()
        if arrived:
            self.sim.hold_quality(False)
            self.awaited = None

    def live_params(self) -> None:
        """Free mode: a ``rosparam set`` lands at the next instant, recorded.

        Judged like the window's live changes (type, range, rules between parameters;
        parameters only ``initialize`` reads are refused); a refused value is one line in the
        log, the old value stays and is put back on the parameter server. Applied changes are
        events, and in ``scenario.yaml``; a Leaf that is a node takes the value at its own
        next step (judged the same way there), this process records it.
        """
        rospy = self.link.rospy
        components = self.sim.components
        for (path, name), seen in self.seen.items():
            try:
                raw = rospy.get_param_cached(names.param(path, name))
            except KeyError:
                continue
            if raw == seen:
                continue
            self.seen[(path, name)] = raw
            leaf = self.link.graph.leaf(path)
            try:
                if name in leaf.template.fixed_once_running:
                    raise ValueError("is read only when the run starts")
                value = leaf.template.param(name).coerce(raw)
                leaf.template.check_params({**vars(components[path].p), name: value})
            except ValueError as exc:
                old = rosio.ros_value(getattr(components[path].p, name))
                rospy.logerr(f"{names.param(path, name)}: {exc}; keeping {old!r}")
                rospy.set_param(names.param(path, name), old)  # the server shows what runs
                self.seen[(path, name)] = old
                continue
            if value == getattr(components[path].p, name):
                continue  # the scenario node's own change, applied at its instant already
            change = Change(path, name, value)
            at = self.sim.apply_live(change)
            print(f"{names.SIMULATOR}: live change {change.key}={value} at t={float(at):g} s")
