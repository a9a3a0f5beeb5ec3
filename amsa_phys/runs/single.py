"""One scenario into a run directory: trace, metrics, resolved scenario, distance plot.

Whatever ends the run — its duration, a fault, Ctrl-C — the trace and the metrics up to
that instant are finalised (written under temporary names, then renamed), so a run
directory never holds a half-written file under its final name.
"""

from __future__ import annotations

import importlib
import json
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import yaml

from ..atomic import write_atomic
from ..engine import interrupt
from ..engine.face import SimDriver
from ..engine.runner import Simulation
from ..engine.tracefile import TraceWriter
from ..errors import Interrupted, OutputError, RunFault, one_line
from ..model.metrics import compute_metrics
from ..model.scenario import Expectation, Scenario, traced_columns
from ..view.drive import FrameSink, advance
from ..view.encoder import EncoderError
from .expect import already_broken, describe_bound, describe_what, skip_reason
from .plotjob import PlotJob, plot_context
from .provenance import provenance
from .resolve import kept_expectations, resolved_scenario

if TYPE_CHECKING:  # pygame is imported only by runs that draw
    from ..view.video import Recorder, RecordOptions, Snapshot, SnapshotOptions


#: libyaml's emitter when PyYAML has it: the same text as ``yaml.safe_dump``, 3-4x faster (a
#: 200-car platoon's resolved scenario: 0.66 s -> 0.19 s).
_YAML_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


@dataclass
class RunOutcome:
    """What a finished run wrote and measured."""

    out_dir: Path
    metrics: dict[str, Any]
    simulation: SimDriver


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
    shown: Path | None = None,
) -> RunOutcome:
    """Run ``scenario`` and write its run directory (which must exist and be empty).

    ``shown`` is the directory the messages name, where ``out_dir`` is staged to become it
    once the run has ended (``rundir.run_dir_for``: a run replacing another with --force).

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
            shown=Path(shown) if shown is not None else Path(out_dir),
        )


TraceFn = Callable[[float, list[float]], None]
SimulationFactory = Callable[[Scenario, TraceFn], SimDriver]


#: Who builds the Simulation of a scenario with ``ros2:`` Leaves: the ROS 2 target, a layer
#: above this one (it needs rclpy, imported only then), found by name as a plugin is; every
#: command that runs scenarios (run, test, sweep, falsify) reaches it through the scenario.
ROS2_SIMULATION = "amsa_phys.ros.ros2.insim:ExternalSimulation"


def default_simulation(scenario: Scenario, trace: TraceFn) -> SimDriver:
    """The engine's Simulation of ``scenario``; with ``ros2:`` Leaves, the ROS 2 bridge's."""
    if scenario.ros2:  # Leaves stepped by a user's ROS 2 nodes: rclpy only then
        module, _, name = ROS2_SIMULATION.partition(":")
        external = getattr(importlib.import_module(module), name)
        return external(scenario, scenario.ros2_timeout, trace=trace)  # type: ignore[no-any-return]
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
    shown: Path,
) -> RunOutcome:
    trace = TraceWriter(out_dir / "trace.csv", traced_columns(scenario))
    ended = execute(
        scenario,
        trace,
        progress=progress,
        record=record,
        snapshot=snapshot,
        window=window,
        simulation=simulation,
    )
    unwritten = ended.unwritten + write_run_files(out_dir, ended, plot=plot, plotter=plotter)
    error = ended.error
    if error is None and unwritten:
        error, unwritten = unwritten[0], unwritten[1:]
    named = {error.path} if isinstance(error, OutputError) else set()
    for exc in unwritten:  # besides the error raised below, each file once
        if exc.path not in named:
            named.add(exc.path)
            print(one_line(f"amsa-phys: {exc}"), file=sys.stderr)
    t_end = ended.metrics["simulated"]
    if isinstance(error, KeyboardInterrupt):
        raise Interrupted(
            one_line(f"interrupted at t={t_end:.2f} s; outputs so far are in {shown}")
        ) from None
    if error is not None:
        raise error
    if interrupt.requested():  # Ctrl-C after the last instant: the outputs are complete
        raise Interrupted(
            one_line(
                f"interrupted after the run ended at t={t_end:.2f} s; "
                f"its outputs are complete in {shown}"
            )
        )
    return RunOutcome(shown, ended.metrics, ended.simulation)


class TraceSink(Protocol):
    """Where the trace rows go: a file (:class:`TraceWriter`) or memory (``TraceMemory``)."""

    def write(self, t_s: float, values: Sequence[float]) -> None:
        """Take one row (``t`` in seconds, then one value per Data buffer)."""

    def close(self) -> object:
        """Finalise (the file is renamed into place); called once the run has ended."""


@dataclass
class Ended:
    """A run that has ended (completed, faulted, interrupted or closed), in memory.

    What a run directory is written from (:func:`write_run_files`), and what
    ``amsa_phys.run`` keeps without writing anything: the two cannot drift apart. ``error``
    is the fault or interrupt that ended the run, for the caller to raise once the outputs
    so far are safe.
    """

    scenario: Scenario
    simulation: SimDriver
    metrics: dict[str, Any]
    resolved: dict[str, Any]
    error: BaseException | None
    note: str = ""  # a comment heading scenario.yaml (checks a cut run left out)
    has_trace: bool = True  # False: the trace could not be written (no plots from it)
    unwritten: list[OutputError] = field(default_factory=list)  # outputs that failed so far


def execute(
    scenario: Scenario,
    trace: TraceSink,
    *,
    progress: bool | None = None,
    record: RecordOptions | None = None,
    snapshot: SnapshotOptions | None = None,
    window: bool | WindowDriver = False,
    simulation: SimulationFactory | None = None,
) -> Ended:
    """Run ``scenario``, streaming its trace to ``trace``; measure it, resolve it.

    A fault or an interrupt ends the run and is returned in :attr:`Ended.error` (the trace
    holds every instant up to it); only a failure to finish the video with no other error
    is raised here. Call inside :func:`interrupt.deferred` so Ctrl-C stops between instants.
    ``simulation`` builds the Simulation (the ROS export's simulator node steps its Leaves
    through their nodes); by default the engine's own.
    """
    sim = (simulation or default_simulation)(scenario, trace.write)
    status = "completed"
    error: BaseException | None = None
    recorder: Recorder | None = None
    still: Snapshot | None = None
    t0 = time.perf_counter()
    idle = 0.0
    try:
        sim.initialize()
        if record is not None:
            from ..view.video import Recorder

            recorder = Recorder(sim, record, scenario.quality, scenario.timeline.planned)
        if snapshot is not None:
            from ..view.video import Snapshot

            still = Snapshot(sim, snapshot, scenario.quality, scenario.timeline.planned)
        if window:
            driver = window if callable(window) else _open_window
            idle = driver(sim, scenario, recorder) or 0.0
            if not sim.finished:
                status = f"closed in the window at t={float(sim.now):g} s"
        else:
            sinks = [s for s in (recorder, still) if s is not None]
            _advance_with_progress(sim, scenario, progress, sinks)
    except (RunFault, OutputError) as exc:  # OutputError: the trace's disk is full
        status, error = f"fault: {exc}", exc
    except EncoderError as exc:
        error = RunFault("recorder", sim.now, str(exc))
        status = f"fault: {error}"
    except KeyboardInterrupt as exc:
        status, error = "interrupted", exc
    wall = time.perf_counter() - t0
    external = getattr(sim, "external_report", None)  # a ROS 2 run: each node's answers
    sim.close()  # a ROS 2 run leaves its graph
    # Each output is written even if another could not be (a full disk): metrics.json
    # above all. The first failure is raised once the run's own error, if any, is.
    unwritten: list[OutputError] = []

    def keep(write: Callable[..., Any], *args: Any) -> Any:
        try:
            return write(*args)
        except OutputError as exc:
            unwritten.append(exc)
            return None

    closed = keep(trace.close)  # a file trace: its path, or None if a write failed
    has_trace = closed is not None or not isinstance(trace, TraceWriter)
    video = _finish_video(recorder, error)
    result = sim.result()
    metrics = compute_metrics(scenario, sim, result, wall, status, idle_s=idle)
    metrics.update(provenance(sim))  # which code and which physics step made this run
    if external is not None:
        metrics["ros2"] = external()
    if video is not None:
        metrics["video"] = video
    if still is not None:
        picture = keep(still.close)
        if picture is not None:
            metrics["snapshot"] = {"path": str(picture), "t": float(still.at)}
    stopped_early = window and not sim.finished and error is None and sim.now > 0
    end = sim.now if stopped_early else scenario.duration
    # left out of the replay: the checks this run did not judge (one it failed for good it
    # did judge), and windows starting after the replay's end, which its loader refuses
    drop = [
        e
        for e in scenario.expect
        if (skip_reason(e, metrics) is not None and already_broken(e, metrics) is None)
        or (e.after is not None and e.after > end)
    ]
    resolved = resolved_scenario(
        scenario,
        extra=sim.live_changes,
        duration=sim.now if stopped_early else None,
        drop=drop,
    )
    kept = kept_expectations(scenario, sim.now if stopped_early else None, drop)
    note = _cut_note(metrics, [e for e in scenario.expect if not any(e is k for k in kept)])
    return Ended(scenario, sim, metrics, resolved, error, note, has_trace, unwritten)


def write_run_files(
    out_dir: Path, ended: Ended, *, plot: bool = True, plotter: PlotJob | None = None
) -> list[OutputError]:
    """``metrics.json``, ``scenario.yaml`` and (with ``plot``) the two plots of a run whose
    ``trace.csv`` is already in ``out_dir``; each file is written atomically.

    Each file is written even if another could not be (a full disk): ``metrics.json`` first.
    Returns the failures, for the caller to report once the run's own error is.
    """
    unwritten: list[OutputError] = []

    def keep(write: Callable[..., Any], *args: Any) -> Any:
        try:
            return write(*args)
        except OutputError as exc:
            unwritten.append(exc)
            return None

    metrics = ended.metrics
    plotter = plotter or PlotJob()
    plotting = plot and ended.has_trace
    if plotting:  # the plotting child draws while the files below are written
        plotter.begin(
            out_dir / "trace.csv",
            metrics,
            out_dir / "distance.png",
            out_dir / "trajectory.png",
            plot_context(ended.scenario.world, ended.resolved),
        )
    keep(
        write_atomic,
        out_dir / "metrics.json",
        json.dumps(metrics, indent=2, allow_nan=False) + "\n",
    )
    text = ended.note + yaml.dump(ended.resolved, Dumper=_YAML_DUMPER, sort_keys=False)
    keep(write_atomic, out_dir / "scenario.yaml", text)
    if plotting:
        keep(plotter.finish)
    plotter.close()
    return unwritten


def _cut_note(metrics: dict[str, Any], dropped: list[Expectation]) -> str:
    """A comment heading a cut run's resolved scenario: what was left out, and why."""
    if not dropped:
        return ""
    names = "; ".join(f"{describe_what(e)} {describe_bound(e)}" for e in dropped)
    return (
        f"# this run stopped at t={metrics['simulated']:g} s, so these checks were not "
        f"judged and are left out: {names}\n"
    )


#: Runs a window session; returns the wall-clock seconds it was paused (None: never).
WindowDriver = Callable[[SimDriver, Scenario, "Recorder | None"], "float | None"]


def _open_window(sim: SimDriver, scenario: Scenario, recorder: Recorder | None) -> float:
    from ..view.window import Window

    return Window(
        sim,
        scenario.quality,
        title=scenario.name,
        recorder=recorder,
        planned=scenario.timeline.planned,
    ).run()


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
            print(one_line(f"amsa-phys: {exc}"), file=sys.stderr)  # besides the run's own
        return None
    return {
        "path": str(path),
        "frames": recorder.encoder.written,  # what the file holds, even after Ctrl-C
        "fps": opts.fps,
        "size": list(opts.size),
        "speedup": float(opts.speedup),
    }


def _advance_with_progress(
    sim: SimDriver, scenario: Scenario, progress: bool | None, sinks: list[FrameSink]
) -> None:
    """Advance in one-second chunks, updating a progress bar on a terminal."""
    total = float(scenario.duration)
    disable = (not sys.stderr.isatty()) if progress is None else not progress
    grid = sim.grid
    per_second = max(1, int(1 / grid.tick))
    end = grid.ticks(scenario.duration)
    tick = 0  # chunks end on whole seconds: a Ctrl-C stops at t=3.0, not 2.95
    if disable:  # tqdm (12 ms of imports) only when a bar is drawn
        while tick < end:
            tick = min(end, tick + per_second)
            advance(sim, tick, sinks)
        return
    from tqdm import tqdm

    with tqdm(
        total=total,
        unit="sim-s",
        leave=False,
        bar_format="{l_bar}{bar}| {n:.0f}/{total:.0f} s [{elapsed}<{remaining}]",
    ) as bar:
        while tick < end:
            tick = min(end, tick + per_second)
            advance(sim, tick, sinks)
            bar.update(float(grid.time(tick)) - bar.n)
