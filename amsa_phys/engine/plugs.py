"""The points where a runtime changes what the engine does, without subclassing it.

A runtime that steps some components elsewhere (the ROS 1 simulator: a Leaf is a node, a
timeline value comes from the parameter server, the rules may fire in a node) hands the
engine a :class:`Plugs` of its own (``Simulation(plugs=...)``) instead of overriding the
engine's private methods, so the hot loop stays the engine's to change. The defaults here
are the engine's own behaviour, and each point is called where the engine would act anyway:
nothing runs per instant that did not before.
"""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Mapping

    from ..model.adaptrules import Rule
    from ..model.scenario import Change
    from .adapt import AdaptRules


class Plugs:
    """The engine's own behaviour at each point; a runtime overrides what it changes."""

    def timeline_change(self, change: Change, at: Fraction) -> Change:
        """The change a timeline entry makes at ``at`` (a ROS runtime: with the value the
        scenario node put on the parameter server). Called once per entry, at its instant."""
        return change

    def rule_change(self, change: Change) -> None:
        """An ``adapt:`` rule's change, about to be applied (before the Leaf is told)."""

    def rule_due(
        self, rules: AdaptRules, now: Fraction, values: Mapping[str, float]
    ) -> tuple[Rule, str] | None:
        """The rule that fires at ``now`` and the event's text, or None: by default the
        engine's own ``rules`` decide (they count the switch). A runtime that asks elsewhere
        counts its firings in ``rules.switches`` itself."""
        firing = rules.due(now, values)
        return None if firing is None else (firing.rule, firing.detail())

    def run_ended(self) -> None:
        """The run reached its end (called after each ``advance`` that finds it there)."""
