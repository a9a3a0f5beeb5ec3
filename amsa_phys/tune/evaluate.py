"""One scenario run under given contexts and settings, reduced to its objective value.

``tune`` and ``adapt --validate`` evaluate many (context sequence, seed, settings) cases;
each is an ordinary run of the user's scenario with its timeline replaced by the sequence,
its ``set:`` extended by the settings and its rules on or off. Only the quality signal is
traced: the metrics are all a case needs.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

from ..engine import interrupt
from ..engine.tracemem import TraceMemory
from ..errors import RunFault
from ..model.configure import configure_scenario
from ..model.scenario import Scenario, traced_columns
from ..model.yamlio import YamlDoc
from ..requirements.objective import requirement_of
from ..runs.single import execute
from .contexts import Sequence
from .objective import objective_value


def case_data(
    scenario: Scenario,
    sequence: Sequence,
    settings: dict[str, Any],
    duration: float,
    rules: list[dict[str, Any]] | None,
    requirement: str | None = None,
) -> dict[str, Any]:
    """The scenario mapping of one case (``rules`` None: no adaptation). ``requirement``:
    the STL requirement the objective is the robustness of (``robustness.NAME``), kept
    among the checks a case otherwise drops (the run computes its robustness)."""
    data = copy.deepcopy(scenario.data)
    kept = [
        e
        for e in data.get("expect") or []
        if requirement is not None
        and isinstance(e, dict)
        and e.get("name") == requirement
        and "stl" in e
    ]
    for key in ("sweep", "timeline", "adapt", "expect", "trace_columns"):
        data.pop(key, None)
    if kept:
        data["expect"] = kept
    first = sequence.segments[0][1]
    data["set"] = {**(data.get("set") or {}), **first, **settings}
    data["duration"] = duration
    timeline = sequence.timeline()
    if timeline:
        data["timeline"] = timeline
    if rules:
        data["adapt"] = copy.deepcopy(rules)
    quality = data.get("quality") or {}
    if quality.get("signal"):
        data["trace_columns"] = [quality["signal"]]
    return data


def add_timeline_settings(data: dict[str, Any], timed: Any) -> None:
    """Add ``timed`` ((instant, {key: value}) pairs: the oracle's switches) to a case's
    document: at 0 into its ``set``, later into the timeline entry of that instant (one
    made, in time order, where there is none)."""
    for at, sets in timed:
        if at == 0:
            data["set"].update(sets)
            continue
        entries = data.setdefault("timeline", [])
        same = next((e for e in entries if e["at"] == at), None)
        if same is None:
            entries.append({"at": at, "set": dict(sets)})
            entries.sort(key=lambda e: e["at"])
        else:
            same["set"].update(sets)


def evaluate(
    scenario: Scenario,
    sequence: Sequence,
    settings: dict[str, Any],
    seed: int,
    objective: str,
    duration: float,
    rules: list[dict[str, Any]] | None = None,
    timeline_settings: list[tuple[float, dict[str, Any]]] | None = None,
) -> float | None:
    """The objective of one run (None: no value, or a fault: the worst there is).

    ``timeline_settings`` adds settings at given instants (the oracle's switches).
    """
    data = case_data(scenario, sequence, settings, duration, rules, requirement_of(objective))
    add_timeline_settings(data, timeline_settings or [])
    # the loader `run` and `ap.run` use, on the case as a document beside the scenario's
    # file (its relative paths resolve as the file's own)
    where = Path(scenario.path) if scenario.path else Path("<tune>")
    case = configure_scenario(YamlDoc(path=where, data=data), None, seed)
    memory = TraceMemory(traced_columns(case))
    with interrupt.deferred():
        ended = execute(case, memory, progress=False)
    if isinstance(ended.error, RunFault):
        return None
    if ended.error is not None:
        raise ended.error
    value, higher = objective_value(ended.metrics, objective)
    if value is None:
        return None
    return value if not higher else -value  # lower is better from here on
