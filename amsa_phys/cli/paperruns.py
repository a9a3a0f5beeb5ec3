"""The runs the paper's figures draw, and a run directory's ``metrics.json`` as plots read it.

``amsa-phys plot --paper ...`` (``plot.py``, ``paperplots.py``) runs the paper's scenarios
in memory or reads their run directories into a :class:`~amsa_phys.plots.paper.PaperRun`;
``plot`` and ``view`` read a run's metrics through :func:`read_metrics`. Below both commands,
so neither imports the other for them.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..errors import ConfigError, one_line
from ..model.scenario import load_scenario


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

    if source.is_dir():
        for name in ("trace.csv", "metrics.json", "scenario.yaml"):
            if not (source / name).is_file():
                raise ConfigError(f"not a run directory: {name} is missing", file=source)
        metrics = read_metrics(source / "metrics.json")
        columns, data = read_trace(source / "trace.csv")
        scenario = load_scenario(source / "scenario.yaml")
    else:
        from ..engine import interrupt
        from ..engine.tracemem import TraceMemory
        from ..runs.single import execute

        scenario = load_scenario(source, overrides)
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
    return PaperRun(run_label(source, scenario), kv_at_start(scenario), t, d, metrics)


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
    later = "".join(f", then {value:g} from {at:g} s" for at, value in kv_changes(scenario))
    return one_line(f"{scenario.name}: Kv = {kv:g}{later}")


def read_metrics(path: Path) -> dict[str, Any]:
    """A run's ``metrics.json``, checked for what the plots read (one line if it is not)."""
    try:
        metrics = json.loads(path.read_bytes())
    except json.JSONDecodeError as exc:
        raise ConfigError(f"invalid JSON: {exc.msg}", file=path, line=exc.lineno) from None
    except UnicodeDecodeError:
        raise ConfigError("invalid JSON: not UTF-8 text", file=path) from None
    except OSError as exc:
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    why = metrics_problem(metrics)
    if why is not None:
        raise ConfigError(f"not a run's metrics: {why}", file=path)
    return metrics


def metrics_problem(metrics: Any) -> str | None:
    if not isinstance(metrics, dict):
        return f"expected an object, got {type(metrics).__name__}"
    phases = metrics.get("phases", [])
    if not isinstance(phases, list):
        return "phases is not a list"
    for i, phase in enumerate(phases):
        if not isinstance(phase, dict):
            return f"phases[{i}] is not an object"
        if not is_number(phase.get("start")):
            return f"phases[{i}].start is not a number"
        if not isinstance(phase.get("set", {}), dict):
            return f"phases[{i}].set is not an object"
    quality = metrics.get("quality")
    if quality is not None:
        if not isinstance(quality, dict) or not isinstance(quality.get("signal"), str):
            return "quality is not an object with a signal"
        for key in ("reference", "tolerance"):
            if not is_number(quality.get(key)):
                return f"quality.{key} is not a number"
    return None


def is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)
