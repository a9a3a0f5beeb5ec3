"""Exhaustive exploration: the Cartesian product of parameter grids × seeds, in parallel.

Each run is a pure function of (scenario file, grid point, seed index), so a result never
depends on ``-j``, the completion order or the executor. Seed index ``i`` runs with the seed
derived from (scenario seed, i) — the same for every grid point (common random numbers), so
two grid points differ by their parameters, not by their noise. Workers load each scenario
file once per process and copy it per run (no re-parsing per run).
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import itertools
import json
import math
import os
import re
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from ..engine import interrupt
from ..errors import AmsaError, ConfigError
from ..model.scenario import (
    PHYSICS_PREFIX,
    Scenario,
    check_phases,
    load_scenario,
    physics_setting,
    resolve_change,
    shortened,
    with_physics,
)
from ..model.yamlio import parse_value
from ..requirements.objective import column
from .pool import WORKER_LOST, imap_resilient

# results.csv's columns and reader live in results.py; importers of sweep still find them
from .results import METRIC_KEYS as METRIC_KEYS
from .results import metric_names as metric_names
from .results import read_results as read_results
from .results import unknown_metric as unknown_metric
from .results import unknown_sweep_metric as unknown_sweep_metric
from .rundir import prepare_run_dir
from .single import compute_metrics, default_simulation, run_scenario

T = TypeVar("T")
R = TypeVar("R")

#: Most runs in one sweep (grid points × seeds): about 14 hours of 50 ms runs on 2 cores.
#: A larger grid is refused before anything is allocated.
MAX_RUNS = 1_000_000


@dataclass(frozen=True)
class Axis:
    """One dimension of the grid: a parameter (or ``context``) and its values.

    ``option`` is the command-line option that gave it (``--grid``, ``--range``), which its
    errors name: a bad ``--range`` value is reported as the ``--range`` the user typed.
    """

    key: str
    values: tuple[Any, ...]
    option: str = field(default="--grid", compare=False)


@dataclass(frozen=True)
class Job:
    """One run of a sweep (picklable: it travels to worker processes and Dask workers)."""

    index: int
    scenario: str
    point: tuple[tuple[str, Any], ...]
    seed_index: int
    seed: int
    contexts: tuple[tuple[str, tuple[tuple[str, Any], ...]], ...] = ()
    duration: float | None = None
    keep_dir: str | None = None


@dataclass
class SweepPlan:
    """Axes, seeds and the jobs they expand to."""

    scenario: Path
    axes: list[Axis]
    seeds: int
    base_seed: int
    contexts: dict[str, dict[str, Any]] = field(default_factory=dict)
    metric: str = "rms_error"
    duration: float | None = None
    keep_dir: str | None = None
    inputs: tuple[Path, ...] = ()  # files the sweep reads: its --out must not hold them
    warnings: tuple[str, ...] = ()  # said once before the sweep starts

    @property
    def size(self) -> int:
        """How many runs: grid points × seeds (computed without building them)."""
        return math.prod(len(a.values) for a in self.axes) * self.seeds

    def jobs(self) -> list[Job]:
        """The Cartesian product of the axes, then seeds, in a fixed order."""
        ctx = tuple((name, tuple(sets.items())) for name, sets in self.contexts.items())
        out = []
        values = [a.values for a in self.axes]
        for n, (combo, s) in enumerate(
            itertools.product(itertools.product(*values), range(self.seeds))
        ):
            point = tuple((a.key, v) for a, v in zip(self.axes, combo, strict=True))
            out.append(
                Job(
                    n,
                    str(self.scenario),
                    point,
                    s,
                    derive_seed(self.base_seed, s),
                    ctx,
                    self.duration,
                    self.keep_dir,
                )
            )
        return out


def deterministic_points(plan: SweepPlan, scenario: Scenario) -> list[tuple[tuple[str, Any], ...]]:
    """The grid points at which nothing random runs, so every seed gives the same run.

    A leaf is random if its template says so for its values (``Template.is_random``: sensor
    noise, losses, a random leader; user templates are assumed random) in any phase: the
    world's values, the scenario's ``set`` and the point's, then each timeline entry.
    """
    world = scenario.world
    out = []
    for combo in itertools.product(*[a.values for a in plan.axes]):
        point = tuple((a.key, v) for a, v in zip(plan.axes, combo, strict=True))
        changes = list(scenario.timeline.initial)
        for key, value in point:
            sets = plan.contexts[value].items() if key == "context" else [(key, value)]
            changes += [resolve_change(k, v, world) for k, v in sets]
        values = {path: dict(leaf.params) for path, leaf in world.leaves.items()}
        random = False
        later = [p.changes for p in scenario.timeline.points()]
        for phase_changes in [changes, *later]:
            for c in phase_changes:
                values[c.leaf][c.param] = c.value
            if any(world.leaves[path].template.is_random(v) for path, v in values.items()):
                random = True
                break
        if not random:
            out.append(point)
    return out


def derive_seed(base: int, index: int) -> int:
    """The seed of seed index ``index`` under scenario seed ``base``."""
    if index == 0:
        return base
    state = np.random.SeedSequence(entropy=base, spawn_key=(index,)).generate_state(1)
    return int(state[0])


def parse_values(text: str, what: str = "--grid") -> tuple[Any, ...]:
    """``0.05,0.1,true,circle`` -> values read as YAML scalars."""
    out = []
    for raw in text.split(","):
        raw = raw.strip()
        if not raw:
            raise ValueError("empty value")
        out.append(parse_value(raw, what))
    return tuple(out)


def parse_grid(text: str) -> Axis:
    """``Comp.param=v1,v2,...``."""
    key, sep, values = text.partition("=")
    if not sep or not key.strip():
        raise ConfigError(f"expected Comp.param=v1,v2,..., got {text!r}", key="--grid")
    if values.count(",") >= MAX_RUNS:
        raise ConfigError(f"more than {MAX_RUNS:,} values", key=f"--grid {key.strip()}")
    try:
        return Axis(key.strip(), parse_values(values, f"--grid {key.strip()}"))
    except ValueError as exc:
        raise ConfigError(f"{exc} in {text!r}", key="--grid") from None


def parse_range(text: str) -> Axis:
    """``Comp.param=start:stop:n`` -> n evenly spaced values, both ends included."""
    key, sep, spec = text.partition("=")
    parts = spec.split(":")
    try:
        if not sep or len(parts) != 3:
            raise ValueError
        start, stop, n = float(parts[0]), float(parts[1]), int(parts[2])
        if n < 1 or not (math.isfinite(start) and math.isfinite(stop)):
            raise ValueError
    except ValueError:
        raise ConfigError(
            f"expected Comp.param=start:stop:n, got {text!r}", key="--range"
        ) from None
    if n > MAX_RUNS:
        raise ConfigError(f"{n:,} values: at most {MAX_RUNS:,}", key=f"--range {key.strip()}")
    values = np.linspace(start, stop, n) if n > 1 else np.array([start])
    return Axis(key.strip(), tuple(float(round(v, 12)) for v in values), option="--range")


def check_size(axes: list[Axis], seeds: int) -> None:
    """Refuse a sweep of more than :data:`MAX_RUNS` runs before anything is allocated."""
    runs = math.prod(len(a.values) for a in axes) * seeds
    if runs > MAX_RUNS:
        shape = " × ".join(str(len(a.values)) for a in axes)
        raise ConfigError(
            f"{shape} grid points × {seeds} seed{'s' if seeds != 1 else ''} = {runs:,} runs; "
            f"a sweep has at most {MAX_RUNS:,}",
            key="sweep",
        )


def check_axes(axes: list[Axis], scenario: Scenario, ranges: str = "start:stop:n") -> None:
    """Judge every grid value up front, so a typo fails before any run starts; ``ranges``:
    how the command's ``--range`` is written (``falsify``'s is ``lo:hi``), for the hint a
    range given to ``--grid`` gets."""
    seen = set()
    for axis in axes:
        if axis.key in seen:
            raise ConfigError(f"{axis.key} appears twice", key=axis.option)
        seen.add(axis.key)
        for value in axis.values:
            if axis.key.startswith(PHYSICS_PREFIX):
                physics_setting(axis.key, value, option=f"{axis.option} {axis.key}")
                continue
            try:
                resolve_change(axis.key, value, scenario.world)
            except ValueError as exc:
                hint = range_hint(axis, value, ranges)
                raise ConfigError(f"{exc}{hint}", key=f"{axis.option} {axis.key}") from None


#: ``0.1:0.3`` or ``0.1:0.3:5``: a range written where ``--grid`` wants a list.
_NUM = r"\s*[-+]?[\d.]+(?:e[-+]?\d+)?\s*"
_RANGE_LIKE = re.compile(rf"{_NUM}:{_NUM}(?::\s*\d+)?\s*")


def range_hint(axis: Axis, value: Any, ranges: str = "start:stop:n") -> str:
    """`` (a range start:stop:n is --range ...)`` when a ``--grid`` value looks like one: the
    user meant the other option, and "expected a number" alone does not say so. ``ranges``
    is the form the command's ``--range`` takes (``lo:hi`` for ``falsify``)."""
    if axis.option != "--grid" or not isinstance(value, str) or not _RANGE_LIKE.fullmatch(value):
        return ""
    parts = [x.strip() for x in value.split(":")]
    if ranges == "lo:hi":
        spec = f"{parts[0]}:{parts[1]}"
    else:
        spec = ":".join(parts) if len(parts) == 3 else f"{parts[0]}:{parts[1]}:5"
    return f" (a range {ranges} is given by --range: --range {axis.key}={spec})"


def apply_setting(scenario: Scenario, key: str, value: Any) -> Scenario:
    """``scenario`` with one grid value: a parameter at t = 0, or a physics setting (a new
    Scenario; the given one, cached and shared by the process's runs, is untouched)."""
    if key.startswith(PHYSICS_PREFIX):
        nested = physics_setting(key, value, option=f"--grid {key}")
        return dataclasses.replace(scenario, world=with_physics(scenario.world, nested))
    change = resolve_change(key, value, scenario.world)
    return dataclasses.replace(scenario, timeline=scenario.timeline.with_initial([change]))


def timeline_overlaps(keys: list[str], scenario: Scenario, end: Fraction) -> list[str]:
    """A warning for each swept parameter the scenario's timeline also changes before ``end``.

    The grid sets its value at t = 0; a timeline entry then overrides it, so the axis only
    shapes the run until that entry (often phase 0 alone) and the overall metrics mix in
    phases where every run has the same value.
    """
    out = []
    for key in dict.fromkeys(keys):  # once per key, in order
        times = list(scenario.timeline.changes_of(key, before=end))
        if times:
            when = ", ".join(f"{float(t):g}" for t in sorted(times))
            first = min(times)
            starts = list(scenario.timeline.starts)
            reach = (
                (
                    "phase 0 only"
                    if starts.index(first) == 1
                    else f"phases 0-{starts.index(first) - 1}"
                )
                if first in starts
                else f"the first {float(first):g} s only"
            )
            out.append(
                f"{key} is swept, but the timeline also sets it (at {when} s): each run's "
                f"value holds only until {float(first):g} s, so the axis affects {reach}; "
                "compare phase-0 metrics (--metric phase0.rms_error) or drop those entries"
            )
    return out


@functools.lru_cache(maxsize=8)
def _cached(path: str) -> Scenario:
    return load_scenario(path)


@functools.lru_cache(maxsize=8)
def _shortened(path: str, duration: float | None) -> Scenario:
    """The scenario file's scenario cut to the sweep's ``--duration`` (once per process)."""
    scenario = copy.deepcopy(_cached(path))
    if duration is not None:
        scenario = shortened(scenario, Fraction(str(duration)))
    return scenario


def job_row(job: Job, error: str = "") -> dict[str, Any]:
    """A result row's leading columns: run number, grid point, seed; no metrics yet."""
    row: dict[str, Any] = {"run": job.index}
    for key, value in job.point:
        row[key] = value
    row["seed_index"] = job.seed_index
    row["seed"] = job.seed
    row["error"] = error
    return row


def prepare_job(job: Job) -> Scenario:
    """The scenario of one job: the file's, cut to the sweep's duration, with the job's seed,
    its context's and grid point's values (ValueError or AmsaError if they break a rule)."""
    # the world and later phases are shared (a run changes neither); each setting makes a
    # new Scenario with its own phase 0 (a deep copy per run costs ~2 ms: a batch of 250
    # runs would spend half a second on it)
    scenario = dataclasses.replace(_shortened(job.scenario, job.duration), seed=job.seed)
    contexts = dict(job.contexts)
    for key, value in job.point:
        if key == "context":
            for k, v in contexts[value]:
                scenario = apply_setting(scenario, k, v)
        else:
            scenario = apply_setting(scenario, key, value)
    check_phases(scenario, None)  # this point's combination may break a template's rule
    return scenario


def fill_metrics(row: dict[str, Any], metrics: dict[str, Any]) -> dict[str, Any]:
    """Put a run's ``metrics.json`` document into its result row (overall, then phases,
    then each STL requirement's robustness as ``robustness.NAME``)."""
    for k in METRIC_KEYS:
        row[k] = metrics["overall"].get(k)
    for i, phase in enumerate(metrics["phases"]):
        for k in METRIC_KEYS:
            row[f"phase{i}.{k}"] = phase.get(k)
    for name, entry in (metrics.get("requirements") or {}).items():
        row[column(name)] = entry.get("robustness")
    return row


def run_job(job: Job) -> dict[str, Any]:
    """Run one job and return its result row (errors are reported in the row)."""
    row = job_row(job)
    try:
        scenario = prepare_job(job)
        if job.keep_dir is not None:
            out = prepare_run_dir(Path(job.keep_dir) / f"run-{job.index:05d}", force=True)
            try:
                metrics = run_scenario(scenario, out, progress=False).metrics
            except AmsaError as exc:
                row["error"] = str(exc)
                metrics = json.loads((out / "metrics.json").read_text())
        else:
            # the engine's; with ros2: Leaves, the ROS 2 bridge's (left when the run ends)
            sim = default_simulation(scenario, None)  # type: ignore[arg-type]
            try:
                sim.run()
                status = "completed"
            except AmsaError as exc:
                status = f"fault: {exc}"
                row["error"] = str(exc)
            finally:
                sim.close()  # a ros2: run leaves its graph
            metrics = compute_metrics(scenario, sim, sim.result(), 1.0, status)
    except (AmsaError, ValueError) as exc:
        row["error"] = str(exc)
        return row
    return fill_metrics(row, metrics)


def iter_local(jobs: list[Job], workers: int) -> Iterator[dict[str, Any]]:
    """Rows as they complete, from local worker processes (or in-process for 1 worker).

    Workers ignore Ctrl-C: the main process handles it, cancels what has not started, stops
    what is running and keeps every row finished so far. A worker that dies costs one row,
    not the sweep (``runs/pool.py``): a job that kills its process twice becomes a row error.
    """
    if workers <= 1:
        for job in jobs:
            yield run_job(job)
            interrupt.check()
        return
    lost = functools.partial(job_row, error=f"{WORKER_LOST}, twice, running this job")
    for _, row in imap_resilient(run_job, jobs, workers, lost, in_flight=2 * workers):
        yield row


def run_lane(lane: tuple[int, list[Job]]) -> list[dict[str, Any]]:
    """The runs of one ROS 2 domain, one after another: a user's node in that domain answers
    one run at a time (``ros2:`` Leaves)."""
    domain, jobs = lane
    os.environ["ROS_DOMAIN_ID"] = str(domain)  # read when each run's bridge starts
    return [run_job(job) for job in jobs]


def iter_ros2_lanes(jobs: list[Job], lanes: int) -> Iterator[dict[str, Any]]:
    """Rows of a sweep whose scenario has ``ros2:`` Leaves: ``lanes`` ROS 2 domains in
    parallel (``ROS_DOMAIN_ID`` and the ``lanes - 1`` after it, a copy of the user's node in
    each), every ``lanes``-th job in the same domain, a domain's runs in turn."""
    if lanes <= 1:
        yield from iter_local(jobs, 1)
        return
    base = int(os.environ.get("ROS_DOMAIN_ID") or 0)  # checked by the command before
    groups = [(base + k, jobs[k::lanes]) for k in range(lanes)]

    def lost(lane: tuple[int, list[Job]]) -> list[dict[str, Any]]:
        return [job_row(j, error=f"{WORKER_LOST}, twice, running this job") for j in lane[1]]

    for _, rows in imap_resilient(run_lane, groups, lanes, lost, in_flight=lanes):
        yield from rows


def iter_dask(jobs: list[Job], scheduler: str) -> Iterator[dict[str, Any]]:
    """Rows as they complete, from an existing Dask distributed cluster."""
    return dask_map(
        run_job,
        jobs,
        scheduler,
        functools.partial(job_row, error=f"{WORKER_LOST}, on every worker that ran it"),
    )


def dask_map(
    fn: Callable[[T], R], items: Sequence[T], scheduler: str, lost: Callable[[T], R]
) -> Iterator[R]:
    """``fn(item)`` as they complete on an existing Dask cluster; ``lost(item)`` for an item
    whose workers all died (a batched sweep's items are batches: ``runs/batched.py``)."""
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise ConfigError(
            "the Dask executor needs the cluster extra: pip install 'amsa-phys[cluster]'",
            key="--executor",
        ) from None
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise ConfigError(f"cannot reach the Dask scheduler: {exc}", key="--scheduler") from None
    from distributed import KilledWorker

    try:
        futures = client.map(fn, items, pure=False)
        item_of = dict(zip(futures, items, strict=True))
        pending = as_completed(futures)
        while not pending.is_empty():
            batch = pending.next_batch(block=False)
            if not batch:  # poll, so that a noted Ctrl-C is raised here, not in Dask's locks
                interrupt.check()
                time.sleep(0.05)
            for fut in batch:
                try:
                    yield fut.result()
                except KilledWorker:  # Dask retried it on other workers and they died too
                    yield lost(item_of[fut])
    finally:
        client.close()
