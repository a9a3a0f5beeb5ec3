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

from ...engine.adapt import MAX_SWITCH_EVENTS
from ...engine.runner import Simulation
from ...model.adaptrules import RULE_COLUMN
from ...model.scenario import Change, Scenario
from .. import names
from . import adaptlink, rosio
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
    from .simulator import Link


class RosSimulation(Simulation):
    """The engine with remote Leaves, parameters from the server, ``/clock`` published."""

    def __init__(self, scenario: Scenario, trace: Any, link: Link) -> None:
        super().__init__(
            scenario.world,
            # adapt: rules fire here, at the engine's exact instants (both modes); a change is
            # put on the parameter server before the Leaf is told (apply_change)
            **Simulation.scenario_kwargs(scenario),
            trace=trace,
            # remote Leaves and publishing local ones stand in for the world's (standins.py)
            wrap=stand_ins(link, lambda: self.now),
            # every Leaf is called on its own: a node per Leaf, a topic per output
            grouping=False,
        )
        # the STL requirements sampled as in process, so metrics.json judges them the same
        self.watch_requirements(scenario)
        self.link = link
        link.attach(self)
        graph = link.graph
        #: the adapt rules' changes (the very objects the engine applies when one fires)
        self.rule_changes = {id(c) for rule in scenario.adapt for c in rule.changes}
        #: the timeline's changes, each with the number of its point (1-based): the scenario
        #: node announces how many points it has applied, a phase's start or a step inside one
        points = enumerate(self.timeline.points(), start=1)
        self.point_of = {id(c): k for k, point in points for c in point.changes}
        # the parameter cache's values of every Leaf, as last seen (free mode: a change of the
        # cache is an edit, recorded as an event whether the Leaf steps here or in its node;
        # timeline changes are applied apart, at their instant)
        self.seen = {
            (path, p.name): rosio.fetch_param(link.rospy, names.param(path, p.name))
            for path in scenario.world.leaves
            for p in graph.leaf(path).template.params
        }
        self.live: list[Change] = []  # live edits queued, not yet applied
        #: free mode: the quality signal a node publishes, until its first message (its
        #: port's initial value before that is no measurement: no quality sample is taken)
        self.awaited = awaited_signal(scenario, graph.remote) if not link.lockstep else None
        self.log.quality_waits = self.awaited is not None
        if not link.lockstep:
            rate = (
                Fraction(str(scenario.world.physics["rate"])) if graph.local else scenario.log_rate
            )
            self.add_hook(rate, self._pace, "ros clock")
            self.add_hook(scenario.log_rate, self._live_params, "ros parameters")

    def advance(self, until_tick: int) -> None:
        """The engine's; at the run's end, pipelined lockstep's last answers checked."""
        super().advance(until_tick)
        if self.link.pipeline is not None and self.finished:
            self.link.pipeline.drain()

    def _pace(self) -> None:
        """Free mode: hold to the wall clock, then take what the nodes published meanwhile."""
        self.link.pace(self.now)
        awaited = self.awaited
        arrived = False
        if awaited is not None:
            with self.link.cond:  # only take() empties fresh: what is there now is taken now
                arrived = awaited in self.link.fresh
        self.link.take()
        if arrived:
            self.log.quality_waits = False
            self.awaited = None

    def apply_change(self, change: Change) -> None:
        """A timeline change, with the value the scenario node put on the parameter server."""
        if id(change) in self.rule_changes:  # an adapt: rule fired at this instant
            rosio.set_param(self.link.rospy, change.leaf, change.param, change.value)
            super().apply_change(change)
            return
        for i, queued in enumerate(self.live):
            if queued is change:  # a live edit (free mode), already judged
                del self.live[i]
                super().apply_change(change)
                return
        value = self.link.point_value(self.point_of[id(change)], self.now, change)
        super().apply_change(Change(change.leaf, change.param, value))

    def _apply_adapt(self) -> None:
        """``rules:=node``: the adapt node says which rule fires now; applied as the engine
        applies its own firing (``adaptlink.py``). Otherwise the engine's own rules."""
        if not self.link.cfg.rules_node:
            super()._apply_adapt()
            return
        fired = adaptlink.due(self.link, self, self.now)
        if fired is None:
            return
        number, detail = fired
        assert self._adapt is not None
        rule = next(r for r in self._adapt.rules if r.number == number)
        for change in rule.changes:
            self.apply_change(change)
        self.values[RULE_COLUMN] = float(number)
        # counted and capped as the engine's own firings are (metrics.json's adapt_switches)
        self._adapt.switches += 1
        if self._adapt.switches <= MAX_SWITCH_EVENTS:
            self.record_event("adapt", detail)

    def _live_params(self) -> None:
        """Free mode: a ``rosparam set`` lands at the next instant, recorded.

        Judged like the window's live changes (type, range, rules between parameters;
        parameters only ``initialize`` reads are refused); a refused value is one line in the
        log, the old value stays and is put back on the parameter server. Applied changes are
        events, and in ``scenario.yaml``; a Leaf that is a node takes the value at its own
        next step (judged the same way there), this process records it.
        """
        rospy = self.link.rospy
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
                leaf.template.check_params({**vars(self.components[path].p), name: value})
            except ValueError as exc:
                old = rosio.ros_value(getattr(self.components[path].p, name))
                rospy.logerr(f"{names.param(path, name)}: {exc}; keeping {old!r}")
                rospy.set_param(names.param(path, name), old)  # the server shows what runs
                self.seen[(path, name)] = old
                continue
            if value == getattr(self.components[path].p, name):
                continue  # the scenario node's own change, applied at its instant already
            change = Change(path, name, value)
            self.live.append(change)
            at = self.apply_live(change)
            print(f"{names.SIMULATOR}: live change {change.key}={value} at t={float(at):g} s")
