"""Batched sweeps: a sweep's runs as columns of one simulation per batch (``--executor batch``).

The sweep's jobs are split into *batches* of runs that one :class:`engine.multirun.MultiRun`
can hold: same scenario, duration and physics settings (a ``physics.*`` axis splits them),
built-in templates or user templates with ``step_many``, no random loop timing (jitter or
free-running timers: each run's timer phases would put its instants elsewhere). A batch is
the unit of work of the process pool and of Dask, so batches are split across cores and
workers; the runs that no batch can hold go one per process as before, said once.

A run that faults inside a batch (a component raising, a rover leaving the world) is run
again alone, which gives its error row and its metrics up to the fault exactly as the
process pool does; the batch then goes on without it (started again from t = 0). A batch
whose worker dies twice has its runs run one per process, so the run that kills its process
is found and reported as before, and the others give their rows.

A run whose shapes are within reach at t = 0 (``ColumnPhysics.within_reach_at_start``: the
paper's Fig. 5 starts the follower 1 m behind the leader) would be marked at the batch's
first step and made alone afterwards: it is made alone at once instead, never computed twice.
"""

from __future__ import annotations

import dataclasses
import gc
import json
import math
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from ..engine import interrupt
from ..engine.multirun import MultiRun
from ..errors import AmsaError, RunFault
from ..model.scenario import Scenario
from ..model.timing import RANDOM
from .pool import WORKER_LOST, imap_resilient
from .single import compute_metrics
from .sweep import Job, fill_metrics, job_row, prepare_job, run_job

#: Most runs in one batch: a batch's worker holds ~0.3 MB a run-minute (world, components,
#: quality samples: peak RSS 125 MiB at 250 runs of 60 s, 204 MiB at 500), and a batch is
#: what a Ctrl-C or a dying worker costs.
MAX_BATCH = 250
#: Batches per worker when the size is automatic: two, so the pool balances and a Ctrl-C
#: keeps the rows of the batches finished so far, while each batch stays wide (numpy's
#: fixed cost per call is shared by every run of a batch: 21 ms a run-minute at 63 runs
#: a batch, 16 ms at 250, measured on scenario1).
BATCHES_PER_WORKER = 2
#: Most work in one automatic batch, in Leaf-seconds (runs x simulated seconds x Leaves):
#: about a second of CPU, so a Ctrl-C, which cannot keep a batch's unfinished runs (they
#: all end together), costs at most that much work a worker. 250 runs of scenario1 (8
#: Leaves) at 60 s; 30 at 500 s.
BATCH_WORK = 120_000
#: On Ctrl-C the batches running get this long to finish (their rows kept) before their
#: workers are killed: the sweep stops within it.
FINISH_S = 1.0
#: Allocations between two collections of the garbage collector's youngest generation while
#: a batch runs (:func:`fewer_collections`; Python's default is 700).
YOUNG_GC = 20_000


@dataclass(frozen=True)
class Unit:
    """What one pool task (or Dask task) runs: a batch, or runs one by one."""

    jobs: tuple[Job, ...]
    batched: bool = True


def unbatchable(scenario: Scenario) -> str | None:
    """Why a batch cannot hold runs of ``scenario`` (None if it can), from what each
    template declares (``Template.batchable``, ``shares_physics``, ``batch_params_at_start``)."""
    world = scenario.world
    if scenario.adapt:
        return "adapt: rules (each run switches its parameters at its own instants)"
    if world.free_running:
        return "free-running timers (each run draws its own phases)"
    for path, leaf in world.leaves.items():
        template = leaf.template
        if not _batchable(template):
            return f"{path} is a user template ({template.name()}) without step_many"
        if leaf.timing.jitter or leaf.timing.phase == RANDOM:
            return f"{path} has random loop timing (jitter or a random phase)"
        if template.has_arrays():
            return f"{path} has array ports (a lidar casts rays in its run's space every scan)"
        if not _shares_physics(template):
            return f"{path} is a terrain zone (the batch's physics has one ground)"
    fixed = {p for p, leaf in world.leaves.items() if _params_at_start(leaf.template)}
    for point in scenario.timeline.points():
        for c in point.changes:
            if c.leaf in fixed:
                return f"the timeline changes {c.key} during the run"
    return None


def _batchable(template: type) -> bool:
    """What the template declares; undeclared, only a template with ``step_many`` (a user's
    template without it may keep state a batch cannot see: it runs alone). Never inferred
    from where the template lives: built-in ones declare it like any other."""
    declared = getattr(template, "batchable", None)
    if declared is not None:
        return bool(declared)
    return hasattr(template, "step_many")


def _shares_physics(template: Any) -> bool:
    return bool(template.shares_physics)


def _params_at_start(template: Any) -> bool:
    return bool(template.batch_params_at_start)


def batch_key(scenario: Scenario) -> str:
    """What runs of one batch share, as text: duration, log rate, physics settings."""
    return json.dumps(
        [str(scenario.duration), str(scenario.log_rate), scenario.world.physics],
        sort_keys=True,
        default=str,
    )


def auto_size(runs: int, workers: int) -> int:
    """Runs per batch: :data:`BATCHES_PER_WORKER` batches per worker, at most MAX_BATCH."""
    return max(1, min(MAX_BATCH, math.ceil(runs / (BATCHES_PER_WORKER * max(1, workers)))))


def plan_units(
    jobs: Sequence[Job], workers: int, size: int | None = None
) -> tuple[list[Unit], list[str]]:
    """Jobs as batches (in job order within each batch key), then the jobs no batch can hold;
    and the notes to say once (why some runs go one per process)."""
    keys: dict[tuple[tuple[str, Any], ...], str | None] = {}
    reasons: dict[str, int] = {}
    groups: dict[str, list[Job]] = {}
    cost: dict[str, float] = {}  # batch key -> Leaf-seconds of one run
    alone: list[Job] = []
    for job in jobs:
        if job.point not in keys:
            try:
                scenario = prepare_job(job)
            except (AmsaError, ValueError):
                keys[job.point] = None  # its row says why; run_job gives it
            else:
                why = unbatchable(scenario)
                if why is not None:
                    reasons[why] = 0
                    keys[job.point] = None
                else:
                    keys[job.point] = key = batch_key(scenario)
                    leaf_s = float(scenario.duration) * max(1, len(scenario.world.leaves))
                    cost[key] = max(cost.get(key, 0.0), leaf_s)
        key = keys[job.point]
        if job.keep_dir is not None or key is None:
            alone.append(job)
        else:
            groups.setdefault(key, []).append(job)
    units = []
    n = size or auto_size(sum(len(g) for g in groups.values()), workers)
    for key, members in groups.items():
        # automatic: also at most BATCH_WORK of work, so a Ctrl-C costs about a second
        size_k = n if size else max(1, min(n, int(BATCH_WORK // cost.get(key, 1.0))))
        for start in range(0, len(members), size_k):
            units.append(Unit(tuple(members[start : start + size_k])))
    units += [Unit((job,), batched=False) for job in alone]
    notes = []
    kept = sum(1 for j in alone if j.keep_dir is not None)
    if kept:
        notes.append(
            f"--keep-runs writes every run's directory (its plots cost ~20x the run): "
            f"{kept} runs go one per process"
        )
    for why in reasons:
        notes.append(f"runs that a batch cannot hold go one per process: {why}")
    return units, notes


def _columns() -> Any:
    """The batch's column physics: every run's rovers in one force pass and integration."""
    from ..physics.columns import ColumnPhysics

    return ColumnPhysics()


@contextmanager
def built_uncollected() -> Iterator[None]:
    """A batch built with the cyclic collector off, what it built then kept out of the
    collector's generations (``gc.freeze``) until the batch ends (:func:`fewer_collections`
    lets them back).

    The set-up makes ~100 objects a run that live as long as the batch: the collector
    traversed them at each young collection while they were made, ~2 % of a batched run's
    CPU. Nothing is frozen where the process froze objects of its own (one ``unfreeze``
    would let them go too), or where the collector was off already.
    """
    if not gc.isenabled() or gc.get_freeze_count():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        gc.enable()


@contextmanager
def fewer_collections(young: int = YOUNG_GC) -> Iterator[None]:
    """The garbage collector's youngest generation collected every ``young`` allocations
    (at least; the other thresholds kept), the process's settings restored after.

    A batch builds ~100,000 objects that live as long as it does (components, tasks, their
    contexts and state); with Python's default (700) the collector traverses them again and
    again while they are made and while the loop allocates its small dicts: ~6 % of a
    batch's CPU. Cyclic garbage is still found, by the same older-generation rules.
    """
    old = gc.get_threshold()
    frozen = gc.get_freeze_count()
    gc.set_threshold(max(old[0], young), *old[1:])
    try:
        yield
    finally:
        gc.set_threshold(*old)
        if gc.get_freeze_count() and not frozen:  # what the batch froze (built_uncollected)
            gc.unfreeze()


def run_batch(jobs: Sequence[Job], stats: dict[str, int] | None = None) -> list[dict[str, Any]]:
    """The result rows of ``jobs`` run as one batch (in job order).

    ``stats`` (if given) counts the runs made alone: ``faults`` (a run that faulted in the
    batch) and ``contacts`` (shapes within reach), of which ``at_start`` were within reach
    at t = 0 and so were never computed in the batch.
    """
    from ..engine import publish

    # the environment's switch for the compiled publishing read once for the whole batch
    with fewer_collections(), publish.pinned():
        return _run_batch(jobs, stats)


def _run_batch(jobs: Sequence[Job], stats: dict[str, int] | None) -> list[dict[str, Any]]:
    counts = stats if stats is not None else {}
    counts.setdefault("faults", 0)
    counts.setdefault("contacts", 0)
    counts.setdefault("at_start", 0)
    rows: dict[int, dict[str, Any]] = {}
    todo: list[tuple[Job, Scenario]] = []
    for job, prepared in zip(jobs, prepare_jobs(jobs), strict=True):
        if isinstance(prepared, str):
            rows[job.index] = job_row(job, prepared)
        else:
            todo.append((job, prepared))
    sim: MultiRun | None = None
    while todo:
        if sim is not None:  # a batch given up (a fault, runs alone): freed at once
            sim.release()
        t0 = time.perf_counter()
        fault: RunFault | None = None
        with built_uncollected():
            sim = MultiRun([sc for _, sc in todo], columns=_columns())
            try:
                sim.initialize()
            except RunFault as exc:  # handled below, as a fault of the loop is
                fault = exc
        try:
            if fault is not None:
                raise fault
            near = sim.column_physics.within_reach_at_start()
            if near:  # their first step would mark them: alone at once, not computed twice
                for k in sorted(near, reverse=True):
                    job = todo.pop(k)[0]
                    rows[job.index] = run_job(job)
                    counts["contacts"] += 1
                    counts["at_start"] += 1
                continue  # the rest as a batch of their own, built again without them
            _run_whole(sim)
        except RunFault as exc:
            k = sim.run_of(exc)
            if k is None:  # not any one run's: each alone says what it is
                rows.update((job.index, run_job(job)) for job, _ in todo)
                break
            job = todo.pop(k)[0]
            rows[job.index] = run_job(job)  # its error row and metrics, as alone
            counts["faults"] += 1
            continue
        wall = (time.perf_counter() - t0) / len(todo)
        touched = sim.column_physics.touched
        for k, ((job, scenario), outcome) in enumerate(zip(todo, sim.outcomes(), strict=True)):
            if k in touched:  # shapes within reach: contacts are made by the run alone
                rows[job.index] = run_job(job)
                counts["contacts"] += 1
                continue
            metrics = compute_metrics(scenario, outcome, outcome.result, wall, "completed")
            rows[job.index] = fill_metrics(job_row(job), metrics)
        break
    if sim is not None:  # by reference counting, not left to the cyclic collector
        sim.release()
    return [rows[job.index] for job in jobs]


def prepare_jobs(jobs: Sequence[Job]) -> list[Scenario | str]:
    """Each job's scenario (``sweep.prepare_job``), or why it cannot run.

    A batch's jobs are a few grid points times many seeds, and a job's scenario differs from
    its point's only in the seed: each point is prepared once (its settings applied and
    checked: ~75 us a run of scenario1), then given each job's seed.
    """
    points: dict[tuple[Any, ...], Scenario | str] = {}
    out: list[Scenario | str] = []
    for job in jobs:
        key = (job.scenario, job.duration, job.point, job.contexts)
        base = points.get(key)
        if base is None:
            try:
                base = points[key] = prepare_job(job)
            except (AmsaError, ValueError) as exc:
                base = points[key] = str(exc)
            out.append(base)
        elif isinstance(base, str):
            out.append(base)
        else:
            out.append(dataclasses.replace(base, seed=job.seed))
    return out


def _run_whole(sim: MultiRun) -> None:
    """Run the batch to its end. A Ctrl-C noted meanwhile is raised by the engine once the
    last instant has run: the batch is then whole, so its rows are kept and the caller
    (``iter_batched``, between units) raises the Ctrl-C after them."""
    try:
        sim.run()
    except KeyboardInterrupt:
        if not sim.finished:
            raise


def run_unit(unit: Unit) -> list[dict[str, Any]]:
    """Run one unit: a batch, or its jobs one by one."""
    if unit.batched and len(unit.jobs) > 0:
        return run_batch(unit.jobs)
    return [run_job(job) for job in unit.jobs]


def iter_batched(
    units: Sequence[Unit],
    workers: int,
    alone: Callable[[list[Job], int], Iterator[dict[str, Any]]],
) -> Iterator[dict[str, Any]]:
    """Rows as units complete, from local worker processes (in-process for 1 worker).

    ``alone`` runs jobs one per process (``sweep.iter_local``): the runs of a batch whose
    worker died twice go there, so the run that kills its process is found as before.
    """
    if workers <= 1:
        for unit in units:
            yield from run_unit(unit)
            interrupt.check()
        return
    lost: list[Job] = []

    def note_lost(unit: Unit) -> list[dict[str, Any]]:
        if len(unit.jobs) == 1:
            return [job_row(unit.jobs[0], f"{WORKER_LOST}, twice, running this job")]
        lost.extend(unit.jobs)
        return []

    for _, rows in imap_resilient(
        run_unit,
        units,
        min(workers, len(units)),
        note_lost,
        in_flight=2 * workers,
        finish_s=FINISH_S,
    ):
        yield from rows
    if lost:
        yield from alone(lost, workers)


def lost_rows(unit: Unit) -> list[dict[str, Any]]:
    """The rows of a unit Dask could not run on any worker."""
    return [job_row(job, f"{WORKER_LOST}, on every worker that ran it") for job in unit.jobs]


def iter_dask_batched(units: Sequence[Unit], scheduler: str) -> Iterator[dict[str, Any]]:
    """Rows as units complete on a Dask cluster (a task is a batch). The runs of a batch
    that killed every worker it met go again one per task, so the run that kills is found
    and the others give their rows, as on local workers."""
    from .sweep import dask_map

    lost: list[Job] = []

    def note_lost(unit: Unit) -> list[dict[str, Any]]:
        if len(unit.jobs) == 1:
            return lost_rows(unit)
        lost.extend(unit.jobs)
        return []

    for rows in dask_map(run_unit, units, scheduler, note_lost):
        yield from rows
    if lost:
        singles = [Unit((job,), batched=False) for job in lost]
        for rows in dask_map(run_unit, singles, scheduler, lost_rows):
            yield from rows
