"""A run's two plots, drawn by a child process that imports matplotlib while the run runs.

Importing matplotlib costs ~0.6 s on the project's machines — as much as simulating 300 s of
scenario1 — and a headless run needs it only at its very end. ``amsa-phys run --headless``
therefore forks a child as it starts: the child imports matplotlib on the other core while
the parent loads the scenario and simulates, then waits for one job (the finished trace and
metrics), draws ``distance.png`` and ``trajectory.png`` (written atomically by the plotting
code itself) and exits. A headless run's process is ~0.4 s shorter.

Decisions:

* ``fork`` only (Linux): a spawned child would re-import the whole package and gain little;
  elsewhere, or when the child cannot be started, plots are drawn in-process as before.
* The child ignores SIGINT: Ctrl-C in a terminal reaches the whole process group, and the
  parent still draws the plots of an interrupted run. It exits when the parent goes away
  (end of file on its pipe), so it never outlives a killed parent for long.
* Whatever goes wrong in the child — it died, hung for :data:`TIMEOUT_S`, or plotting raised —
  the parent draws the plots itself, so errors surface exactly as for an in-process draw.
* Sweeps and ``amsa-phys test`` do not use it: their workers already keep every core busy.
* The job is handed over (:meth:`PlotJob.begin`) before ``metrics.json`` and
  ``scenario.yaml`` are written, with the terrain zones in it, so the child reads the trace
  while the parent writes (a 200-rover run's ``scenario.yaml`` takes ~0.3 s, as long as
  reading the plotted columns of its trace).
* When the child starts was measured on 2 cores shared with another busy process
  (``benchmarks/bench_plots.py``, 8 interleaved repetitions; process time with plots /
  without): forked at start 1.27 (scenario 1) and 1.38 (200 rovers); the same child at
  ``os.nice(10)`` 1.38 and 1.41; forked after the loop (import overlapping the file writing)
  1.65 and 1.39. Niceness did not keep the import off the loop measurably and made the
  drawing wait behind the other load; a late fork pays the import after the loop. So the
  child is forked at start, at normal priority.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # multiprocessing (~8 ms of imports) only when a child is forked
    import multiprocessing.process
    from multiprocessing.connection import Connection

    from ..model.world import WorldSpec

from ..errors import one_line
from ..palette import rover_names
from ..templatemarks import Zone as ZoneMark
from ..templatemarks import marked
from ..tracemarks import gps_links
from .rundata import timeline_of

#: How long the parent waits for the child's plots before drawing them itself.
TIMEOUT_S = 60.0


def draw_run_plots(
    trace: Path,
    metrics: dict[str, Any],
    distance: Path,
    trajectory: Path,
    world: dict[str, Any] | None = None,
) -> list[Path]:
    """The distance and trajectory plots of a run (imports matplotlib on first use).

    A run without a quality signal has no distance to plot: ``distance.png`` is not drawn
    (rather than left blank), and the caller says so. ``world`` is :func:`plot_context`.
    Returns the files written.
    """
    from ..plots.distance import plot_distance, trace_header
    from ..plots.trajectory import plot_trajectory, plotted_columns

    # titles show the scenario's name: printable, as on the terminal (an escape code would
    # be a missing glyph and a warning on stderr)
    metrics = {**metrics, "scenario": one_line(str(metrics.get("scenario", "")))}
    written = []
    with warnings.catch_warnings():  # a picture's imperfections are not the run's messages
        warnings.simplefilter("ignore")
        # both plots read one parse of only the columns they draw
        quality = metrics.get("quality") or {}
        links = (world or {}).get("gps")
        keep = plotted_columns(trace_header(trace), links) | {str(quality.get("signal"))}
        if quality:
            written.append(plot_distance(trace, metrics, distance, keep))
        written.append(plot_trajectory(trace, metrics, trajectory, world, keep))
    return written


def plot_context(world: WorldSpec, resolved: Any = None) -> dict[str, Any]:
    """What the trajectory plot needs from the world: its static arena (``physics``),
    which rover each GPS measures (``gps_of``: GPS path -> rover path) and the goals rovers
    steer to (``goals``: x, y, radius), plain data. With the run's ``resolved`` scenario
    also its terrain zones, so the plots need not wait for ``scenario.yaml``."""
    links = gps_links(world.leaves)
    gps_of = {link.path: link.rover for link in links if link.rover}
    goals: dict[tuple[float, float], dict[str, float]] = {}
    for leaf in world.leaves.values():
        goal = _goal_of(leaf.params)
        if goal is not None:  # a navigator and its monitor name the same goal: drawn once
            key = (goal["x"], goal["y"])
            goals[key] = {**goal, "radius": max(goal["radius"], goals.get(key, goal)["radius"])}
    context = {"physics": world.physics, "gps_of": gps_of, "goals": list(goals.values())}
    # the world's rovers in order (colours by rank, whatever the trace keeps) and each GPS's
    # period and loss settings (trajectory.png marks its lost fixes, as the window does)
    context["rovers"] = rover_names(list(world.buffers))
    context["gps"] = [vars(link) for link in links]
    if resolved is not None:  # the run's resolved scenario: its zones go with the job
        from ..plots.zones import zones_of  # matplotlib-free

        declared = {path: mark for path, _, mark in marked(world.leaves, ZoneMark)}
        params = {path: world.leaves[path].params for path in declared}
        context["zones"] = zones_of(params, declared, timeline_of(resolved))
    return context


def _goal_of(params: dict[str, Any]) -> dict[str, float] | None:
    """``{x, y, radius}`` of a Leaf steering to (or measuring the distance to) a goal: any
    template with numeric ``goalX`` and ``goalY`` parameters (``goalRadius`` if it has one)."""
    try:
        x, y = float(params["goalX"]), float(params["goalY"])
        radius = float(params.get("goalRadius", 0.0) or 0.0)
    except (KeyError, TypeError, ValueError):
        return None
    return {"x": x, "y": y, "radius": radius}


def _child(jobs: Connection, parent_end: Connection, parent_pid: int) -> None:
    """The child's life: import, wait for one job, draw it, report."""
    from .pool import die_with_parent

    die_with_parent(parent_pid)  # a SIGKILLed parent takes its plotter along at once
    parent_end.close()  # so that the parent's exit is an end of file here
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(Exception):  # on failure the parent draws (and reports)
        # the import this process exists for: matplotlib's Figure and Agg canvas, never
        # pyplot (its backend machinery is another ~20 ms the two plots do not use)
        from matplotlib.backends import backend_agg  # noqa: F401

        from ..plots import distance, trajectory  # noqa: F401
    try:
        job = jobs.recv()
    except EOFError:
        return
    if job is None:
        return
    try:
        draw_run_plots(*job)
        jobs.send("ok")
    except BaseException as exc:  # reported to the parent, which redraws
        jobs.send(f"failed: {exc!r}")


class PlotJob:
    """The run's plots in a child process, or in-process when that is not possible."""

    def __init__(self) -> None:
        self._conn: Connection | None = None
        self._proc: multiprocessing.process.BaseProcess | None = None
        self._job: tuple[Any, ...] | None = None  # handed over by begin(), awaited by finish()

    @classmethod
    def start(cls) -> PlotJob:
        """Fork the child now (it starts importing matplotlib at once)."""
        job = cls()
        if not sys.platform.startswith("linux"):
            return job
        for stream in (sys.stdout, sys.stderr):  # else the child re-flushes their buffers
            if stream is not None:
                stream.flush()
        import multiprocessing

        try:
            ctx = multiprocessing.get_context("fork")
            parent_end, child_end = ctx.Pipe()
            proc = ctx.Process(
                target=_child, args=(child_end, parent_end, os.getpid()), daemon=True
            )
            proc.start()
        except (OSError, ValueError):
            return job
        child_end.close()
        job._conn, job._proc = parent_end, proc
        return job

    @property
    def background(self) -> bool:
        """Whether a child is standing by."""
        return self._conn is not None

    def draw(
        self,
        trace: Path,
        metrics: dict[str, Any],
        distance: Path,
        trajectory: Path,
        world: dict[str, Any] | None = None,
    ) -> None:
        """Draw the plots: by the child if it answers in time, else here."""
        self.begin(trace, metrics, distance, trajectory, world)
        self.finish()

    def begin(
        self,
        trace: Path,
        metrics: dict[str, Any],
        distance: Path,
        trajectory: Path,
        world: dict[str, Any] | None = None,
    ) -> None:
        """Hand the plots to the child, which draws them while the caller writes its other
        files (a wide run's ``scenario.yaml`` takes as long as reading its trace);
        :meth:`finish` waits for them."""
        self._job = (Path(trace), metrics, Path(distance), Path(trajectory), world)
        conn = self._conn
        if conn is None:
            return
        try:
            conn.send(self._job)
        except (OSError, ValueError):
            self.close()  # finish draws here

    def finish(self) -> None:
        """The plots :meth:`begin` handed over, done: by the child if it answers in time,
        else drawn here (errors then surface as for an in-process draw)."""
        job, self._job = self._job, None
        if job is None:
            return
        if not self._wait():
            draw_run_plots(*job)

    def _wait(self) -> bool:
        conn = self._conn
        if conn is None:
            return False
        try:
            done = conn.poll(TIMEOUT_S) and conn.recv() == "ok"
        except (OSError, EOFError, ValueError):
            done = False
        self.close()
        return done

    def close(self) -> None:
        """Dismiss the child (no plots wanted, or they are done); safe to call twice."""
        conn, proc = self._conn, self._proc
        self._conn = self._proc = None
        if conn is not None:
            with contextlib.suppress(OSError, ValueError):  # the child may be gone
                conn.send(None)
            conn.close()
        if proc is not None:
            proc.join(1.0)
            if proc.is_alive():
                proc.kill()
                proc.join()
