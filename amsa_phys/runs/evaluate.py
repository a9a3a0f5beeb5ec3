"""Evaluate arbitrary points of a scenario's parameter space as result rows.

A sweep expands a grid into jobs itself; a search (``amsa-phys falsify``) or a rule learner
chooses its points one generation at a time, then wants each point's row as a sweep would
have written it. :func:`evaluate` is that: points in, rows out, through the sweep's own
machinery (``Job``, ``prepare_job``, the batched executor, the process pool, Dask), so a
point gives the same row, byte for byte, whichever of them ran it.

Ctrl-C and SIGTERM behave as in a sweep: the executors call ``interrupt.check()`` between
completions, so a caller inside ``interrupt.deferred()`` gets every row finished before the
KeyboardInterrupt.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from .batched import iter_batched, iter_dask_batched, plan_units
from .sweep import Job, iter_local

#: One point: the settings (``("Comp.param", value)`` pairs, applied at t = 0 like a sweep's
#: grid values) and the run's seed.
Point = tuple[tuple[tuple[str, Any], ...], int]

EXECUTORS = ("batch", "local", "dask")


def point_jobs(
    scenario_path: str | Path, points: Sequence[Point], duration: float | None = None
) -> list[Job]:
    """The sweep jobs of ``points``: job ``i`` is point ``i`` (its ``run`` column too).

    ``seed_index`` is 0 for every job: the seed is the point's own, not one of a sweep's
    derived seeds, and its column stays so that ``results.csv`` reads as a sweep's.
    """
    path = str(Path(scenario_path).resolve())
    return [
        Job(i, path, tuple(settings), 0, int(seed), (), duration)
        for i, (settings, seed) in enumerate(points)
    ]


def evaluate(
    scenario_path: str | Path,
    points: Sequence[Point],
    *,
    duration: float | None = None,
    executor: str = "batch",
    workers: int | None = None,
    batch_size: int | None = None,
    scheduler: str | None = None,
) -> Iterator[dict[str, Any]]:
    """One result row per point, in completion order, each with ``index`` = its position.

    The row has a sweep's columns (``run``, every setting, ``seed_index``, ``seed``,
    ``error``, every overall and per-phase metric) plus ``index``. ``executor`` is
    ``batch`` (runs as columns of one simulation per batch, on ``workers`` processes),
    ``local`` (one run per process) or ``dask`` (batches on the cluster at ``scheduler``).
    """
    if executor not in EXECUTORS:
        raise ConfigError(
            f"expected one of {', '.join(EXECUTORS)}, got {executor!r}", key="--executor"
        )
    if executor == "dask" and not scheduler:
        raise ConfigError("the Dask executor needs --scheduler ADDR", key="--executor")
    n = workers if workers is not None else (os.cpu_count() or 1)
    if n < 1:
        raise ConfigError("must be at least 1", key="--jobs")
    if batch_size is not None and batch_size < 1:
        raise ConfigError("must be at least 1", key="--batch-size")
    jobs = point_jobs(scenario_path, points, duration)
    return _rows(jobs, executor, n, batch_size, scheduler)


def _rows(
    jobs: list[Job], executor: str, n: int, batch_size: int | None, scheduler: str | None
) -> Iterator[dict[str, Any]]:
    """The rows of ``jobs`` from the executor (a generator: nothing runs until asked)."""
    if not jobs:
        return
    if executor == "local":
        rows = iter_local(jobs, min(n, len(jobs)))
    else:
        units, _notes = plan_units(jobs, n, batch_size)
        if executor == "dask":
            rows = iter_dask_batched(units, str(scheduler))
        else:
            rows = iter_batched(units, min(n, len(units)), iter_local)
    for row in rows:
        row["index"] = row["run"]
        yield row
