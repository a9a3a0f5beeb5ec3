"""The fully resolved scenario: world inlined, every parameter value, enough to replay."""

from __future__ import annotations

import copy
from fractions import Fraction
from typing import Any

from ..model.scenario import Change, Scenario
from ..model.world import LeafSpec


def _number(x: Fraction | float) -> float | int:
    f = float(x)
    return int(f) if f.is_integer() else f


def _time(t: Fraction) -> float | int | str:
    """An instant written so that loading it gives ``t`` back exactly.

    A float when its shortest repr is ``t`` itself (0.25, 2.51); otherwise the fraction
    ``"7/3"`` — an instant of a 3 Hz component has no exact decimal, and a float near it
    would replay the change just *after* the components due at ``t`` instead of before.
    """
    t = Fraction(t)
    if t.denominator == 1:
        return int(t)
    if Fraction(repr(float(t))) == t:
        return float(t)
    return f"{t.numerator}/{t.denominator}"


def _plain(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def resolved_scenario(
    scenario: Scenario,
    extra: list[tuple[Fraction, Change]] | None = None,
    duration: Fraction | None = None,
) -> dict[str, Any]:
    """A scenario dict with the world inlined and every Leaf parameter written out.

    ``extra`` adds changes made live (the window), merged into the timeline in time order;
    a change made before the first instant ran becomes part of ``set``. ``duration`` cuts
    the scenario where a window session was closed, so replaying it gives the same trace.
    """
    world = copy.deepcopy(scenario.world.data)

    def fill(comps: dict[str, Any], prefix: str) -> None:
        for name in list(comps):
            if "count" in comps[name]:
                _expand_copies(comps, name, prefix, scenario)
        for name, body in comps.items():
            path = f"{prefix}.{name}" if prefix else name
            if "components" in body:
                fill(body["components"], path)
                continue
            leaf: LeafSpec = scenario.world.leaves[path]
            body["freq"] = _number(leaf.freq)
            body["params"] = {k: _plain(v) for k, v in leaf.params.items()}

    fill(world["components"], "")
    if scenario.world.schedule:
        world["schedule"] = list(scenario.world.schedule)  # copies' schedules written out
    world["physics"] = copy.deepcopy(scenario.world.physics)
    if world["physics"].get("walls") is None:
        world["physics"].pop("walls", None)
    timeline: dict[Fraction, dict[str, Any]] = {}
    labels: dict[Fraction, str] = {}
    for phase in scenario.phases[1:]:
        timeline.setdefault(phase.at, {}).update({c.key: _plain(c.value) for c in phase.changes})
        if phase.label:
            labels[phase.at] = phase.label
    initial = {c.key: _plain(c.value) for c in scenario.phases[0].changes}
    for at, change in extra or []:
        if at == 0:
            initial[change.key] = _plain(change.value)
            continue
        if at not in timeline:
            labels[at] = "live"
        timeline.setdefault(at, {})[change.key] = _plain(change.value)
    end = scenario.duration if duration is None else Fraction(duration)
    timeline = {at: sets for at, sets in timeline.items() if at < end}
    out: dict[str, Any] = {
        "name": scenario.name,
        "world": world,
        "duration": _time(end),
        "seed": scenario.seed,
        "log_rate": _number(scenario.log_rate),
        "set": initial,
    }
    if scenario.quality:
        q = scenario.quality
        out["quality"] = {"signal": q.signal, "reference": q.reference, "tolerance": q.tolerance}
    if timeline:
        out["timeline"] = []
        for at in sorted(timeline):
            entry: dict[str, Any] = {"at": _time(at), "set": timeline[at]}
            if at in labels:
                entry["label"] = labels[at]
            out["timeline"].append(entry)
    if scenario.expect:
        out["expect"] = []
        for e in scenario.expect:
            fields = (
                ("metric", e.metric),
                ("trace", e.trace),
                ("phase", e.phase),
                ("after", e.after),
                ("before", e.before),
                ("below", e.below),
                ("above", e.above),
            )
            out["expect"].append({k: v for k, v in fields if v is not None})
    return out


def _expand_copies(comps: dict[str, Any], name: str, prefix: str, scenario: Scenario) -> None:
    """Replace a ``count:`` Composite by its copies, written out (names, params, links)."""
    body = comps[name]
    items = list(comps.items())
    comps.clear()
    for key, value in items:
        if key != name:
            comps[key] = value
            continue
        for i in range(1, body["count"] + 1):
            copy_path = f"{prefix}.{name}{i}" if prefix else f"{name}{i}"
            inner: dict[str, Any] = {}
            for leaf_name, leaf_body in body["components"].items():
                leaf: LeafSpec = scenario.world.leaves[f"{copy_path}.{leaf_name}"]
                out = {k: v for k, v in leaf_body.items() if k in ("template", "description")}
                if leaf.inputs:
                    out["inputs"] = dict(leaf.inputs)  # absolute: found from any scope
                inner[leaf_name] = out
            comps[f"{name}{i}"] = {"components": inner}
