"""One scenario into a run directory: trace, metrics, resolved scenario, distance plot.

Whatever ends the run — its duration, a fault, Ctrl-C — the trace and the metrics up to
that instant are finalised (written under temporary names, then renamed), so a run
directory never holds a half-written file under its final name.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from tqdm import tqdm

from ..engine.metrics import block_metrics
from ..engine.recorder import TraceWriter, write_atomic
from ..engine.runner import RunResult, Simulation
from ..errors import Interrupted, RunFault
from ..model.scenario import Scenario
from ..plots.distance import plot_distance
from ..plots.trajectory import plot_trajectory
from .resolve import resolved_scenario


@dataclass
class RunOutcome:
    """What a finished run wrote and measured."""

    out_dir: Path
    metrics: dict[str, Any]
    simulation: Simulation


def compute_metrics(
    scenario: Scenario, sim: Simulation, result: RunResult, wall_s: float, status: str
) -> dict[str, Any]:
    """The ``metrics.json`` document (design.md) for a run that reached ``result.t_end``."""
    end = result.t_end
    q = scenario.quality
    collisions = [e.t for e in result.events if e.kind == "collision"]
    starts = [float(p.at) for p in scenario.phases]
    phases = []
    for i, phase in enumerate(scenario.phases):
        p_end = starts[i + 1] if i + 1 < len(starts) else float(scenario.duration)
        block: dict[str, Any] = {
            "start": starts[i],
            "end": p_end,
            "set": {c.key: _jsonable(c.value) for c in phase.changes},
        }
        if phase.label:
            block["label"] = phase.label
        if q is not None and result.samples_t.size:
            last = i + 1 == len(scenario.phases)
            block.update(
                block_metrics(
                    result.samples_t,
                    result.samples_s,
                    starts[i],
                    p_end,
                    q.reference,
                    q.tolerance,
                    collisions,
                    include_end=last,
                )
            )
        else:
            block["collisions"] = sum(1 for t in collisions if starts[i] <= t < p_end)
        phases.append(block)
    if q is not None and result.samples_t.size:
        overall = block_metrics(
            result.samples_t,
            result.samples_s,
            0.0,
            float(scenario.duration),
            q.reference,
            q.tolerance,
            collisions,
            include_end=True,
        )
    else:
        overall = {"collisions": len(collisions)}
    return {
        "scenario": scenario.name,
        "seed": scenario.seed,
        "duration": float(scenario.duration),
        "simulated": end,
        "status": status,
        "quality": (
            {"signal": q.signal, "reference": q.reference, "tolerance": q.tolerance} if q else None
        ),
        "overall": overall,
        "phases": phases,
        "events": [{"t": e.t, "kind": e.kind, "detail": e.detail} for e in result.events[:1000]],
        "wall_time_s": round(wall_s, 3),
        "real_time_factor": round(end / wall_s, 1) if wall_s > 0 else None,
    }


def _jsonable(value: Any) -> Any:
    return (
        [list(v) if isinstance(v, tuple) else v for v in value]
        if isinstance(value, tuple)
        else value
    )


def run_scenario(
    scenario: Scenario, out_dir: Path, *, progress: bool | None = None, plot: bool = True
) -> RunOutcome:
    """Run ``scenario`` and write its run directory (which must exist and be empty)."""
    out_dir = Path(out_dir)
    trace = TraceWriter(out_dir / "trace.csv", list(scenario.world.buffers))
    sim = Simulation.from_scenario(scenario, trace=trace.write)
    status = "completed"
    error: BaseException | None = None
    t0 = time.perf_counter()
    try:
        sim.initialize()
        _advance_with_progress(sim, scenario, progress)
    except RunFault as exc:
        status, error = f"fault: {exc}", exc
    except KeyboardInterrupt as exc:
        status, error = "interrupted", exc
    wall = time.perf_counter() - t0
    trace.close()
    result = sim.result()
    metrics = compute_metrics(scenario, sim, result, wall, status)
    write_atomic(out_dir / "metrics.json", json.dumps(metrics, indent=2) + "\n")
    resolved = resolved_scenario(scenario, extra=None)
    write_atomic(out_dir / "scenario.yaml", yaml.safe_dump(resolved, sort_keys=False))
    if plot:
        plot_distance(out_dir / "trace.csv", metrics, out_dir / "distance.png")
        plot_trajectory(out_dir / "trace.csv", metrics, out_dir / "trajectory.png")
    if isinstance(error, KeyboardInterrupt):
        raise Interrupted(
            f"interrupted at t={result.t_end:.2f} s; outputs so far are in {out_dir}"
        ) from None
    if error is not None:
        raise error
    return RunOutcome(out_dir, metrics, sim)


def _advance_with_progress(sim: Simulation, scenario: Scenario, progress: bool | None) -> None:
    """Advance in one-second chunks, updating a progress bar on a terminal."""
    total = float(scenario.duration)
    disable = (not sys.stderr.isatty()) if progress is None else not progress
    grid = sim.grid
    per_second = max(1, int(1 / grid.tick))
    end = grid.ticks(scenario.duration)
    with tqdm(
        total=total,
        unit="sim-s",
        disable=disable,
        leave=False,
        bar_format="{l_bar}{bar}| {n:.0f}/{total:.0f} s [{elapsed}<{remaining}]",
    ) as bar:
        tick = -1
        while tick < end:
            tick = min(end, tick + per_second)
            sim.advance(tick)
            bar.update(float(grid.time(tick)) - bar.n)
