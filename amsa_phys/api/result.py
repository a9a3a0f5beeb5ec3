"""``amsa_phys.run``: one scenario run in memory, saved as a run directory only on request.

The run goes through ``runs.single.execute``, the function behind ``amsa-phys run
--headless``, with the trace kept in memory instead of streamed to a file; :meth:`Run.save`
writes the same files through the same writers (``write_run_files``, ``TraceWriter``) and the
same output-directory rules (``runs/rundir.py``). So a saved run is what the CLI writes, and
its ``trace.csv`` is byte-identical.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from ..bag import BagRecorder
from ..engine import interrupt
from ..engine.runner import Event
from ..engine.tracemem import TraceMemory
from ..errors import ConfigError, Interrupted
from ..model.configure import with_ros2
from ..model.scenario import Scenario, traced_columns
from ..runs.expect import Check, check_expectations
from ..runs.rundir import default_run_dir, run_dir_for
from ..runs.single import Ended, execute, write_run_files
from ..runs.suite import input_files
from .memory import check_trace_memory
from .source import Source, api_errors, load, switch


class Run:
    """A finished run of a scenario, in memory.

    Attributes:
        metrics: the ``metrics.json`` document (a dict: ``overall``, ``phases``, ``status``...).
        trace: every Data buffer at the log rate, a numpy structured array with one field per
            ``trace.csv`` column (``run.trace["t"]``, ``run.trace["Follower.posX"]``).
        columns: the trace's column names, ``"t"`` first, as in ``trace.csv``.
        events: every event of the run (collisions, ...) as ``Event(t, kind, detail)``.
        scenario: the resolved scenario (world inlined, every value) as ``scenario.yaml``
            holds it; ``amsa_phys.run(run.scenario)`` replays the run.
        checks: the scenario's ``expect`` entries, evaluated (``check.passed``, ``.value``).
    """

    def __init__(self, ended: Ended, memory: TraceMemory) -> None:
        self._loaded: Scenario = ended.scenario
        self._ended = ended
        self._memory = memory
        self.metrics: dict[str, Any] = ended.metrics
        self.scenario: dict[str, Any] = ended.resolved
        self.events: list[Event] = list(ended.simulation.events)
        self.trace: np.ndarray = memory.structured()
        self.columns: list[str] = ["t", *memory.columns]
        self.checks: list[Check] = check_expectations(
            ended.scenario.expect, self.metrics, (self.columns, memory.matrix())
        )

    @property
    def status(self) -> str:
        """``completed``, ``interrupted`` or ``fault: ...`` (as in ``metrics.json``)."""
        return str(self.metrics["status"])

    @property
    def passed(self) -> bool:
        """Whether no ``expect`` check failed (True for a scenario without any).

        As ``amsa-phys run`` exits 0 for a run cut short whose checks were skipped, a skipped
        check does not fail: look at :attr:`skipped` to tell "all held" from "none judged".
        A cut-short check that has already failed for good (a collision under
        ``collisions below 1``, a maximum past its ``below``) fails.
        """
        return all(c.passed for c in self.checks)

    @property
    def skipped(self) -> list[Check]:
        """The checks not judged (a phase cut short or never reached; a trace window the
        run never logged), each with ``why``."""
        return [c for c in self.checks if c.skipped]

    @api_errors
    def save(
        self, out: str | os.PathLike[str] | None = None, *, force: bool = False, plot: bool = True
    ) -> Path:
        """Write the run directory ``amsa-phys run --headless --out OUT`` writes; returns it.

        ``out`` defaults to ``runs/<scenario>-<YYYYmmdd-HHMMSS>``. The CLI's rules apply: a
        non-empty directory is refused unless ``force`` (and then only one amsa-phys made),
        one holding the scenario or its world, the current directory or a parent never.
        ``plot=False`` skips the two plots (``--no-plot``).
        """
        path = Path(out) if out is not None else default_run_dir(self._loaded.name)
        inputs = [p for p in input_files(self._loaded) if p.is_file()]  # a mapping has none
        with run_dir_for(path, force, inputs=inputs) as work:  # an earlier run whole till done
            self._memory.save(work / "trace.csv")
            unwritten = write_run_files(work, self._ended, plot=plot)
        if unwritten:  # a full disk: every file that could be written was, say the first
            raise unwritten[0]
        return path

    def __repr__(self) -> str:
        overall = self.metrics.get("overall", {})
        rms = overall.get("rms_error")
        shown = f", rms_error={rms:.3g}" if isinstance(rms, float) else ""
        return (
            f"<Run {self._loaded.name!r} seed={self.metrics['seed']} "
            f"{self.metrics['simulated']:g}/{self.metrics['duration']:g} s {self.status}"
            f"{shown}, {len(self.trace)} trace rows>"
        )


@api_errors
def run(
    source: Source,
    *,
    seed: int | None = None,
    duration: float | Fraction | None = None,
    set: Mapping[str, Any] | None = None,  # the CLI's --set, by its name
    log_rate: float | None = None,
    trace_columns: str | Sequence[str] | None = None,
    base_dir: str | os.PathLike[str] | None = None,
    progress: bool = False,
    bag: str | os.PathLike[str] | None = None,
    adapt: bool = True,
    ros2: str | Sequence[str] | None = None,
    ros2_timeout: float | None = None,
) -> Run:
    """Run a scenario (a file path or a mapping) as ``amsa-phys run --headless`` does.

    Nothing is written (call :meth:`Run.save` for the run directory). Options are the CLI's
    (see :func:`~amsa_phys.api.source.load`; ``adapt=False`` is ``--no-adapt``);
    ``progress=True`` shows the progress bar.
    Errors are the CLI's, raised: :class:`~amsa_phys.errors.ConfigError` for bad input and
    :class:`~amsa_phys.errors.RunFault` for a fault during the run, with the CLI's one-line
    message. The trace is kept in memory: a :class:`~amsa_phys.api.memory.TraceSizeWarning`
    above ~1 GB, a ConfigError if it could not fit in the machine's memory. Ctrl-C stops
    the run between two instants and raises
    :class:`~amsa_phys.errors.Interrupted`. A fault or an interrupt carries the run up to
    that instant as the exception's ``run`` attribute (inspect it, or ``save`` it).
    ``bag`` also writes the run as a ROS 2 MCAP bag there (``--bag``; an existing file is
    refused), finalised whatever ended the run. ``ros2`` is ``--ros2``: these Leaves are
    your ROS 2 nodes, stepped in lockstep (needs rclpy; ``docs/ros2.md``).
    """
    progress = switch(progress, "progress")
    scenario = load(
        source,
        seed=seed,
        duration=duration,
        set=set,
        log_rate=log_rate,
        trace_columns=trace_columns,
        base_dir=base_dir,
        adapt=adapt,
    )
    scenario = with_ros2(scenario, ros2, ros2_timeout)
    columns = traced_columns(scenario)
    check_trace_memory(scenario, columns)  # warn above 1 GB, refuse above the machine's RAM
    memory = TraceMemory(columns)
    recorder = bag_recorder(bag, scenario) if bag is not None else None
    try:
        with interrupt.deferred():
            ended = execute(
                scenario,
                memory,
                progress=progress,
                simulation=recorder.simulation if recorder is not None else None,
            )
            late_stop = interrupt.requested()  # Ctrl-C after the last instant
    finally:
        if recorder is not None:
            recorder.close()
    result = Run(ended, memory)
    error = ended.error
    t_end = result.metrics["simulated"]
    if isinstance(error, KeyboardInterrupt):
        error = Interrupted(f"interrupted at t={t_end:.2f} s; the run so far is the error's .run")
    elif error is None and late_stop:
        error = Interrupted(
            f"interrupted after the run ended at t={t_end:.2f} s; the error's .run is complete"
        )
    if error is None:
        return result
    error.run = result  # type: ignore[attr-defined]
    if isinstance(error, Interrupted):
        raise error from None
    raise error  # a RunFault keeps its cause: a user template's own traceback


def bag_recorder(path: str | os.PathLike[str], scenario: Scenario) -> BagRecorder:
    """The recorder of ``run(bag=path)``: a new ``.mcap`` file in an existing directory."""
    target = Path(path)
    if target.suffix.lower() != ".mcap":
        raise ConfigError("a bag is an .mcap file", key="bag", file=target)
    if target.exists():
        raise ConfigError("file exists (remove it or choose another name)", key="bag", file=target)
    if not (target.parent if str(target.parent) else Path(".")).is_dir():
        raise ConfigError("directory does not exist", key="bag", file=target)
    return BagRecorder(target, scenario)
