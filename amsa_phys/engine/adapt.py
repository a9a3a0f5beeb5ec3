"""Reconfiguration rules at run time: which parameter changes are due at an instant.

The Simulation asks :meth:`AdaptRules.due` at the start of every instant at which
components run (after the timeline's changes, before the components), with the Data as the
estimators last published them; it applies what comes back exactly as a timeline change at
that instant. So a rule's change lands at an exact instant, the components due then already
see it, and the run stays a pure function of (scenario, seed): the replay of its resolved
``scenario.yaml`` (which keeps the rules) fires the same rules at the same instants.

Semantics (README, "Adaptive reconfiguration"): a rule's conditions must hold at every
instant evaluated for ``hold`` seconds (hysteresis: a condition that flickers restarts the
count); then, if no rule fired in the last ``dwell`` seconds (the least time between two
switches; ``hold`` unless the rule says) and the rule's values are not already in force, it
fires: its changes are applied, once. Rules are tried in file order and at most one fires
per instant.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from ..model.adaptrules import Rule

#: Firings kept in memory (the first ones); a run counts every switch in ``switches``.
KEPT_FIRINGS = 1000
#: Switch events a run records (metrics.json's events); later switches are counted only.
MAX_SWITCH_EVENTS = 1000


@dataclass(frozen=True)
class Firing:
    """A rule that fired at ``t``: its changes and the estimates that triggered it."""

    t: Fraction
    rule: Rule
    estimates: tuple[tuple[str, float], ...]

    def detail(self) -> str:
        """The event's text: which rule, what it set, on which estimates."""
        sets = ", ".join(f"{c.key}={c.value}" for c in self.rule.changes)
        seen = ", ".join(f"{name}={value:.3g}" for name, value in self.estimates)
        return f"{self.rule.name()}: {sets} ({seen})"


class AdaptRules:
    """The rules of one run and their state (since when each condition holds)."""

    def __init__(self, rules: Sequence[Rule], current: Callable[[str, str], Any]) -> None:
        """``current(leaf, param)`` is the value in force now (what a rule would change)."""
        self.rules = list(rules)
        self._current = current
        self._since: list[Fraction | None] = [None] * len(self.rules)
        self._last_switch: Fraction | None = None
        #: the first :data:`KEPT_FIRINGS` firings (memory stays bounded on any run length)
        self.fired: list[Firing] = []
        #: every switch of the run, kept or not
        self.switches = 0

    def due(self, now: Fraction, values: Mapping[str, float]) -> Firing | None:
        """The rule that fires at ``now`` (None if none); its state is updated either way."""
        firing = None
        for i, rule in enumerate(self.rules):
            if all(c.holds(values[c.signal]) for c in rule.when):
                if self._since[i] is None:
                    self._since[i] = now
            else:
                self._since[i] = None
                continue
            since = self._since[i]
            if firing is not None or since is None or now - since < rule.hold:
                continue
            if self._last_switch is not None and now - self._last_switch < rule.least_gap:
                continue
            if all(self._current(c.leaf, c.param) == c.value for c in rule.changes):
                continue  # already in force: nothing to switch
            estimates = tuple((c.signal, float(values[c.signal])) for c in rule.when)
            firing = Firing(now, rule, estimates)
        if firing is not None:
            self._last_switch = now
            self.switches += 1
            if len(self.fired) < KEPT_FIRINGS:
                self.fired.append(firing)
        return firing
