"""The runs the paper's figures draw, read from run directories as data or run in memory.

``amsa-phys plot --paper ...`` (``plot.py``, ``paperplots.py``) runs the paper's scenarios
in memory or reads their run directories into a :class:`~amsa_phys.plots.paper.PaperRun`.
A run directory is read as data only (:func:`~amsa_phys.runs.rundata.read_run`): nothing
its ``scenario.yaml`` names is imported. Below both commands, so neither imports the other.
"""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import ConfigError, one_line
from ..model.scenario import load_scenario
from ..model.template import Kind
from ..runs.rundata import read_run
from ..runs.runfiles import read_metrics

__all__ = ["paper_run", "paper_scenarios", "read_metrics"]


def paper_scenarios(figure: str) -> list[Path]:
    """The shipped scenarios of a figure, found under ./scenarios."""
    pattern = {"fig5": "paper_fig5_kv*.yaml", "fig6-sensed": "paper_fig6_sensed.yaml"}.get(
        figure, "paper_fig6.yaml"
    )
    found = sorted(Path("scenarios").glob(pattern))
    if not found:
        raise ConfigError(
            f"no scenarios/{pattern} here: run it from the project's folder or name the "
            "scenarios or run directories",
            key=f"--paper {figure}",
        )
    return found


def paper_run(source: Path, overrides: list[str] | None = None) -> Any:
    """A :class:`~amsa_phys.plots.paper.PaperRun` from a run directory or a scenario file
    (run with ``overrides``, ``--set`` texts)."""
    from ..plots.distance import read_trace
    from ..plots.paper import PaperRun

    if source.is_dir():  # data only: nothing the run directory names is imported
        run = read_run(source)
        columns, data = read_trace(run.trace)
        assert run.world is not None  # scenario.yaml is required
        assert run.resolved is not None
        kv, later = runkv_at_start(run, source)
        name = one_line(str(run.resolved.get("name", source.name)))
        label = name if kv is None else kvrun_label(name, kv, later)
        metrics = run.metrics
    else:
        from ..engine import interrupt
        from ..engine.tracemem import TraceMemory
        from ..runs.single import execute

        scenario = load_scenario(source, overrides)
        kv, label = kv_at_start(scenario), run_label(source, scenario)
        memory = TraceMemory(list(scenario.world.buffers))
        with interrupt.deferred():
            ended = execute(scenario, memory, progress=False)
        if ended.error is not None:
            raise ended.error
        metrics = ended.metrics
        columns, data = ["t", *memory.columns], memory.matrix()
    q = metrics.get("quality")
    if not q or q["signal"] not in columns:
        raise ConfigError("the run has no quality signal to draw", file=source)
    t, d = data[:, 0], data[:, columns.index(q["signal"])]
    return PaperRun(label, kv, t, d, metrics)


def kv_at_start(scenario: Any) -> float | None:
    """The controller's Kv at t = 0 (the world's, or the scenario's set:), if it has one."""
    for path, leaf in scenario.world.leaves.items():
        if "Kv" in leaf.params and leaf.kind.value == "controller":
            value = leaf.params["Kv"]
            for change in scenario.timeline.initial:
                if change.leaf == path and change.param == "Kv":
                    value = change.value
            return float(value)
    return None


def kv_changes(scenario: Any) -> list[tuple[float, float]]:
    """(time, Kv) of every later change of the controller's Kv (phases and steps)."""
    path = next(
        (
            p
            for p, leaf in scenario.world.leaves.items()
            if "Kv" in leaf.params and leaf.kind.value == "controller"
        ),
        None,
    )
    out = []
    for point in scenario.timeline.points():
        for change in point.changes:
            if change.leaf == path and change.param == "Kv":
                out.append((float(point.at), float(change.value)))
    return out


def run_label(source: Path, scenario: Any) -> str:
    """The panel's title: the scenario and every Kv it shows (``Kv = 0.35, then 0.05 from
    100 s``), not only the first."""
    kv = kv_at_start(scenario)
    if kv is None:
        return one_line(str(scenario.name))
    return kvrun_label(one_line(str(scenario.name)), kv, kv_changes(scenario))


def kvrun_label(name: str, kv: float, later: list[tuple[float, float]]) -> str:
    after = "".join(f", then {value:g} from {at:g} s" for at, value in later)
    return one_line(f"{name}: Kv = {kv:g}{after}")


def runkv_at_start(run: Any, source: Path) -> tuple[float | None, list[tuple[float, float]]]:
    """A run directory's controller Kv at t = 0 and its later changes, from the resolved
    scenario as data (the world's value, its ``set:``, its ``timeline:``)."""
    path = next(
        (
            p
            for p, leaf in run.world.leaves.items()
            if "Kv" in leaf.params and leaf.kind == Kind.CONTROLLER
        ),
        None,
    )
    if path is None:
        return None, []
    key = f"{path}.Kv"
    where = source / "scenario.yaml"
    try:
        kv = float(run.world.leaves[path].params["Kv"])
        initial = run.resolved.get("set") or {}
        if isinstance(initial, dict) and key in initial:
            kv = float(initial[key])
        later = []
        for entry in run.resolved.get("timeline") or []:
            sets = entry.get("set") or {} if isinstance(entry, dict) else {}
            if key in sets:
                later.append((float(Fraction(str(entry["at"]))), float(sets[key])))
    except (TypeError, ValueError, KeyError, ZeroDivisionError, AttributeError):
        why = f"not a resolved scenario: {key} or its changes are not numbers"
        raise ConfigError(why, file=where) from None
    if not all(math.isfinite(v) for pair in [(kv, 0.0), *later] for v in pair):
        why = f"not a resolved scenario: {key} or its changes are not finite"
        raise ConfigError(why, file=where)
    return kv, later
