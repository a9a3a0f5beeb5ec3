"""One scenario into a run directory: trace, metrics, resolved scenario, distance plot.

Whatever ends the run — its duration, a fault, Ctrl-C — the trace and the metrics up to
that instant are finalised (written under temporary names, then renamed), so a run
directory never holds a half-written file under its final name.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml
from tqdm import tqdm

from ..engine import interrupt
from ..engine.metrics import block_metrics
from ..engine.recorder import TraceWriter, write_atomic
from ..engine.runner import RunResult, Simulation
from ..errors import Interrupted, RunFault
from ..model.scenario import Scenario
from ..view.drive import FrameSink, advance
from ..view.encoder import EncoderError
from .plotjob import PlotJob
from .resolve import resolved_scenario

if TYPE_CHECKING:  # pygame is imported only by runs that draw
    from ..view.recorder import Recorder, RecordOptions, Snapshot, SnapshotOptions


#: libyaml's emitter when PyYAML has it: the same text as ``yaml.safe_dump``, 3-4x faster (a
#: 200-car platoon's resolved scenario: 0.66 s -> 0.19 s).
_YAML_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


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
    scenario: Scenario,
    out_dir: Path,
    *,
    progress: bool | None = None,
    plot: bool = True,
    record: RecordOptions | None = None,
    snapshot: SnapshotOptions | None = None,
    window: bool | WindowDriver = False,
    plotter: PlotJob | None = None,
    simulation: SimulationFactory | None = None,
) -> RunOutcome:
    """Run ``scenario`` and write its run directory (which must exist and be empty).

    ``record`` also writes a video, ``snapshot`` a PNG of one instant (in a window session:
    of the moment it was closed, without trails). ``window`` runs the scenario in the
    interactive window (until the user closes it) instead of as fast as possible; a callable
    ``window`` replaces the window's own loop (tests drive it with scripted events and an
    exact clock). ``plotter`` draws the plots (a child started early, ``runs/plotjob.py``);
    without one they are drawn in-process. ``simulation`` builds the Simulation from the
    scenario and the trace callback (the ROS simulator node's, whose Leaves run as nodes).

    Ctrl-C (SIGINT, and SIGTERM from the CLI) during the run stops it between two instants
    (``engine/interrupt.py``): the outputs describe whole instants, then
    :class:`~amsa_phys.errors.Interrupted` is raised. A second Ctrl-C stops at once.
    """
    with interrupt.deferred():
        return _run_scenario(
            scenario,
            Path(out_dir),
            progress=progress,
            plot=plot,
            record=record,
            snapshot=snapshot,
            window=window,
            plotter=plotter,
            simulation=simulation,
        )


TraceFn = Callable[[float, list[float]], None]
SimulationFactory = Callable[[Scenario, TraceFn], Simulation]


def _default_simulation(scenario: Scenario, trace: TraceFn) -> Simulation:
    return Simulation.from_scenario(scenario, trace=trace)


def _run_scenario(
    scenario: Scenario,
    out_dir: Path,
    *,
    progress: bool | None,
    plot: bool,
    record: RecordOptions | None,
    snapshot: SnapshotOptions | None,
    window: bool | WindowDriver,
    plotter: PlotJob | None,
    simulation: SimulationFactory | None = None,
) -> RunOutcome:
    trace = TraceWriter(out_dir / "trace.csv", list(scenario.world.buffers))
    sim = (simulation or _default_simulation)(scenario, trace.write)
    status = "completed"
    error: BaseException | None = None
    recorder: Recorder | None = None
    still: Snapshot | None = None
    t0 = time.perf_counter()
    try:
        sim.initialize()
        if record is not None:
            from ..view.recorder import Recorder

            recorder = Recorder(sim, record, scenario.quality)
        if snapshot is not None:
            from ..view.recorder import Snapshot

            still = Snapshot(sim, snapshot, scenario.quality)
        if window:
            driver = window if callable(window) else _open_window
            driver(sim, scenario, recorder)
            if not sim.finished:
                status = f"closed in the window at t={float(sim.now):g} s"
        else:
            sinks = [s for s in (recorder, still) if s is not None]
            _advance_with_progress(sim, scenario, progress, sinks)
    except RunFault as exc:
        status, error = f"fault: {exc}", exc
    except EncoderError as exc:
        error = RunFault("recorder", sim.now, str(exc))
        status = f"fault: {error}"
    except KeyboardInterrupt as exc:
        status, error = "interrupted", exc
    wall = time.perf_counter() - t0
    trace.close()
    video = _finish_video(recorder, error)
    result = sim.result()
    metrics = compute_metrics(scenario, sim, result, wall, status)
    if video is not None:
        metrics["video"] = video
    if still is not None:
        metrics["snapshot"] = {"path": str(still.close()), "t": float(still.at)}
    write_atomic(out_dir / "metrics.json", json.dumps(metrics, indent=2) + "\n")
    stopped_early = window and not sim.finished and error is None and sim.now > 0
    resolved = resolved_scenario(
        scenario, extra=sim.live_changes, duration=sim.now if stopped_early else None
    )
    text = yaml.dump(resolved, Dumper=_YAML_DUMPER, sort_keys=False)
    write_atomic(out_dir / "scenario.yaml", text)
    plotter = plotter or PlotJob()
    if plot:
        plotter.draw(
            out_dir / "trace.csv", metrics, out_dir / "distance.png", out_dir / "trajectory.png"
        )
    plotter.close()
    if isinstance(error, KeyboardInterrupt):
        raise Interrupted(
            f"interrupted at t={result.t_end:.2f} s; outputs so far are in {out_dir}"
        ) from None
    if error is not None:
        raise error
    if interrupt.requested():  # Ctrl-C after the last instant: the outputs are complete
        raise Interrupted(
            f"interrupted after the run ended at t={result.t_end:.2f} s; "
            f"its outputs are complete in {out_dir}"
        )
    return RunOutcome(out_dir, metrics, sim)


WindowDriver = Callable[[Simulation, Scenario, "Recorder | None"], None]


def _open_window(sim: Simulation, scenario: Scenario, recorder: Recorder | None) -> None:
    from ..view.window import Window

    Window(sim, scenario.quality, title=scenario.name, recorder=recorder).run()


def _finish_video(recorder: Recorder | None, error: BaseException | None) -> dict[str, Any] | None:
    """Finalise the video whatever ended the run; what ``metrics.json`` says about it."""
    if recorder is None:
        return None
    opts = recorder.options
    try:
        path = recorder.close()
    except EncoderError as exc:
        if error is None:
            raise RunFault("recorder", recorder.sim.now, str(exc)) from None
        if not (isinstance(error, RunFault) and error.component == "recorder"):
            print(f"amsa-phys: {exc}", file=sys.stderr)  # besides the run's own error
        return None
    return {
        "path": str(path),
        "frames": recorder.encoder.written,  # what the file holds, even after Ctrl-C
        "fps": opts.fps,
        "size": list(opts.size),
        "speedup": float(opts.speedup),
    }


def _advance_with_progress(
    sim: Simulation, scenario: Scenario, progress: bool | None, sinks: list[FrameSink]
) -> None:
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
        tick = 0  # chunks end on whole seconds: a Ctrl-C stops at t=3.0, not 2.95
        while tick < end:
            tick = min(end, tick + per_second)
            advance(sim, tick, sinks)
            bar.update(float(grid.time(tick)) - bar.n)
