"""The fully resolved scenario: world inlined, every parameter value, enough to replay."""

from __future__ import annotations

import copy
from collections.abc import Sequence
from fractions import Fraction
from typing import Any

from ..model.adaptrules import written_rules
from ..model.scenario import Change, Expectation, Scenario
from ..model.timing import TIMING_KEYS, LeafTiming
from ..model.world import LeafSpec
from ..stl.requirement import reads_until


def _number(x: Fraction | float) -> float | int:
    f = float(x)
    return int(f) if f.is_integer() else f


def _write_timing(body: dict[str, Any], timing: LeafTiming) -> None:
    """A Leaf's latency, jitter and phase as the run used them (a scenario's ``set:``
    included); keys left at their defaults are left out."""
    for key in TIMING_KEYS:
        body.pop(key, None)
    if timing.latency:
        body["latency"] = _time(timing.latency)
    if timing.jitter:
        body["jitter"] = _time(timing.jitter)
    if timing.phase is not None:
        body["phase"] = timing.phase if isinstance(timing.phase, str) else _time(timing.phase)


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
    drop: Sequence[Expectation] = (),
) -> dict[str, Any]:
    """A scenario dict with the world inlined and every Leaf parameter written out.

    ``extra`` adds changes made live (the window): each becomes a timeline entry labelled
    ``live`` with ``new_phase: false`` — a change inside the phase it landed in, so the
    replay has the session's phases and ``expect: {phase: i}`` judges the same phase. A
    change made before the first instant ran becomes part of ``set``. ``duration`` cuts the
    scenario where a window session was closed, so replaying it gives the same trace.
    ``drop`` lists the expectations the run could not judge (a phase cut short or never
    reached): they are left out, so the replay judges what the run judged.
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
            _write_timing(body, leaf.timing)

    fill(world["components"], "")
    if scenario.world.schedule:
        world["schedule"] = list(scenario.world.schedule)  # copies' schedules written out
    world["physics"] = copy.deepcopy(scenario.world.physics)
    if world["physics"].get("walls") is None:
        world["physics"].pop("walls", None)
    entries: dict[Fraction, dict[str, Any]] = {}

    def entry(at: Fraction, label: str, new_phase: bool) -> dict[str, Any]:
        if at not in entries:
            entries[at] = {"set": {}, "label": label, "new_phase": new_phase}
        return entries[at]

    timeline = scenario.timeline
    for point in timeline.points():
        entry(point.at, point.label, point.starts_phase)["set"].update(
            {c.key: _plain(c.value) for c in point.changes}
        )
    initial = {c.key: _plain(c.value) for c in timeline.initial}
    for at, change in extra or []:
        if at == 0:
            initial[change.key] = _plain(change.value)
        else:
            entry(at, "live", False)["set"][change.key] = _plain(change.value)
    end = scenario.duration if duration is None else Fraction(duration)
    out: dict[str, Any] = {
        "name": scenario.name,
        "world": world,
        "duration": _time(end),
        "seed": scenario.seed,
        "log_rate": _number(scenario.log_rate),
        "set": initial,
    }
    if scenario.trace_columns is not None:
        out["trace_columns"] = list(scenario.trace_columns)
    if scenario.quality:
        q = scenario.quality
        out["quality"] = {"signal": q.signal, "reference": q.reference, "tolerance": q.tolerance}
        if q.dwell is not None:
            out["quality"]["dwell"] = q.dwell
    timeline = [at for at in sorted(entries) if at < end]
    if timeline:
        out["timeline"] = []
        for at in timeline:
            e = entries[at]
            item: dict[str, Any] = {"at": _time(at), "set": e["set"]}
            if e["label"]:
                item["label"] = e["label"]
            if not e["new_phase"]:
                item["new_phase"] = False
            out["timeline"].append(item)
    if scenario.adapt:
        out["adapt"] = written_rules(scenario.adapt)
    kept = kept_expectations(scenario, duration, drop)
    if kept:
        out["expect"] = []
        for e in kept:
            fields = (
                ("stl", e.stl),
                ("name", e.name),
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


def kept_expectations(
    scenario: Scenario, duration: Fraction | None, drop: Sequence[Expectation] = ()
) -> list[Expectation]:
    """The expectations a resolved scenario keeps: not those in ``drop``, nor any its loader
    would refuse at the written end: an STL one reading past it, a check of a phase that
    starts at or after it (``falsify --duration`` writes ``worst.yaml`` at the runs' length),
    a window opening after it."""
    end = Fraction(duration if duration is not None else scenario.duration)
    phases = 1 + sum(1 for p in scenario.timeline.points() if p.starts_phase and p.at < end)
    return [
        e
        for e in scenario.expect
        if not any(e is d for d in drop)
        and (e.stl is None or reads_until(e.stl) <= float(end))
        and (e.phase is None or e.phase < phases)
        and (e.after is None or Fraction(str(e.after)) <= end)
    ]


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
