"""Reconfiguration rules (a scenario's ``adapt:``): parsed, checked, written back.

A rule says: when every condition on the context estimators' outputs has held for ``hold``
seconds, and no rule has switched in the last ``dwell`` seconds (default: ``hold``), set
these parameters. The engine (``engine/adapt.py``) evaluates the rules; this
module only turns the YAML into :class:`Rule` values, judging what each names (the Data a
condition reads must exist, the values set go through the same ``Param.check`` as a
timeline's) so a bad rule is a one-line error before anything runs.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from . import schema
from .changes import resolve_change
from .ruleshapes import FILE
from .suggest import did_you_mean
from .yamlio import KeyPath, YamlDoc, load_yaml

#: The trace column holding the number (1-based) of the rule that fired last (0: none yet).
RULE_COLUMN = "adapt.rule"


@dataclass(frozen=True)
class Condition:
    """``signal`` (a Data buffer) strictly below ``below`` and/or strictly above ``above``."""

    signal: str
    below: float | None = None
    above: float | None = None

    def holds(self, value: float) -> bool:
        """Whether ``value`` satisfies the condition."""
        if self.below is not None and not value < self.below:
            return False
        return self.above is None or value > self.above


@dataclass(frozen=True)
class Rule:
    """One ``adapt:`` entry: conditions (all must hold), changes, hold time in seconds.

    ``dwell`` is the least time since the last switch (by any rule) before this one may
    fire; None: ``hold``. A fallback that waits out a switch's own transient has a dwell
    longer than its hold: it still reacts within ``hold`` of unsureness, but never in the
    first ``dwell`` seconds after a switch, while the estimate's window still holds the
    transient the switch itself caused.
    """

    number: int  # 1-based, as events and the trace name it
    when: tuple[Condition, ...]
    changes: tuple[Any, ...]  # model.scenario.Change
    hold: Fraction
    label: str = ""
    dwell: Fraction | None = None

    @property
    def least_gap(self) -> Fraction:
        """Seconds since the last switch before this rule may fire (``dwell``, or ``hold``)."""
        return self.hold if self.dwell is None else self.dwell

    def name(self) -> str:
        """``rule 2`` or ``rule 2 (worn motors)``."""
        return f"rule {self.number}" + (f" ({self.label})" if self.label else "")


def load_rules(doc: YamlDoc, entries: list[dict[str, Any]] | str, world: Any) -> list[Rule]:
    """A scenario's ``adapt:`` as rules: written inline, or in the file it names (resolved
    against the scenario's folder; errors then point into that file)."""
    if not isinstance(entries, str):
        return parse_rules(doc, entries, world)
    path = doc.path.parent / entries
    if not path.is_file():
        raise doc.error(("adapt",), f"rules file not found: {path}")
    rules_doc = load_yaml(path)
    schema.validate(rules_doc.data, FILE, rules_doc, quote=False)  # any file: no value shown
    return parse_rules(rules_doc, rules_doc.data["adapt"], world)


def parse_rules(doc: YamlDoc, entries: list[dict[str, Any]], world: Any) -> list[Rule]:
    """The ``adapt:`` entries of ``doc`` as rules (shape checked by ``ruleshapes.SCHEMA``)."""
    rules = []
    for i, entry in enumerate(entries):
        kp: KeyPath = ("adapt", i)
        conditions = []
        for signal, bound in entry["when"].items():
            signal = str(signal)
            if signal not in world.buffers:
                raise doc.error(
                    (*kp, "when", signal),
                    f"unknown Data {signal!r}"
                    + did_you_mean(signal, world.buffers)
                    + " (a condition reads an estimator's output, Component.output)",
                )
            below, above = bound.get("below"), bound.get("above")
            if below is not None and above is not None and below <= above:
                raise doc.error(
                    (*kp, "when", signal),
                    f"below {below:g} is not above above {above:g}: the condition never holds",
                )
            conditions.append(
                Condition(
                    signal,
                    None if below is None else float(below),
                    None if above is None else float(above),
                )
            )
        changes = []
        for key, value in entry["set"].items():
            try:
                changes.append(resolve_change(str(key), value, world))
            except ValueError as exc:
                raise doc.error((*kp, "set", key), str(exc)) from None
            template = world.leaves[changes[-1].leaf].template
            if changes[-1].param in template.fixed_once_running:
                raise doc.error(
                    (*kp, "set", key),
                    f"{changes[-1].param} is read only when the run starts; "
                    "a rule cannot change it",
                )
        hold = Fraction(str(entry.get("hold", 0)))
        dwell = Fraction(str(entry["dwell"])) if "dwell" in entry else None
        label = str(entry.get("label", ""))
        rules.append(Rule(i + 1, tuple(conditions), tuple(changes), hold, label, dwell))
    return rules


def _number(x: Fraction | float) -> float | int:
    f = float(x)
    return int(f) if f.is_integer() else f


def written_rules(rules: list[Rule]) -> list[dict[str, Any]]:
    """The rules as a resolved ``scenario.yaml`` writes them (they load back equal)."""
    out = []
    for rule in rules:
        when: dict[str, Any] = {}
        for c in rule.when:
            bound: dict[str, float] = {}
            if c.below is not None:
                bound["below"] = c.below
            if c.above is not None:
                bound["above"] = c.above
            when[c.signal] = bound
        item: dict[str, Any] = {
            "when": when,
            "set": {c.key: c.value for c in rule.changes},
            "hold": _number(rule.hold),
        }
        if rule.dwell is not None:
            item["dwell"] = _number(rule.dwell)
        if rule.label:
            item["label"] = rule.label
        out.append(item)
    return out


def describe_rules(rules: list[Rule]) -> list[str]:
    """One line per rule, for ``describe`` and ``validate``."""
    lines = []
    for rule in rules:
        conds = " and ".join(_condition_text(c) for c in rule.when)
        sets = ", ".join(f"{c.key}={c.value}" for c in rule.changes)
        dwell = "" if rule.dwell is None else f", {float(rule.dwell):g} s after a switch"
        lines.append(f"{rule.name()}: when {conds} for {float(rule.hold):g} s{dwell}: set {sets}")
    return lines


def _condition_text(c: Condition) -> str:
    """``0.375 < MotorMonitor.delivered < 0.75``."""
    text = c.signal if c.above is None else f"{c.above:g} < {c.signal}"
    return text if c.below is None else f"{text} < {c.below:g}"
