"""Many independent jobs on local worker processes, in a way one dying worker cannot stop.

A worker process that dies (killed, out of memory, a crash in native code) breaks a
``ProcessPoolExecutor`` and fails every job it held. :func:`imap_resilient` hands out only a
few jobs at a time; after a break, the jobs the pool held run again one at a time, each in a
fresh process, so the job that kills its process a second time is found and reported through
``lost(item)``, the others give their results, and the rest go on in a new pool. Sweeps and
``amsa-phys test -j`` both run on it.
"""

from __future__ import annotations

import functools
import multiprocessing
import signal
from collections import deque
from collections.abc import Callable, Generator, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

from ..engine import interrupt

T = TypeVar("T")
R = TypeVar("R")

WORKER_LOST = "a worker process died (killed, out of memory, or a crash in native code)"


def imap_resilient(
    fn: Callable[[T], R],
    items: Sequence[T],
    workers: int,
    lost: Callable[[T], R],
    *,
    in_flight: int,
) -> Iterator[tuple[int, R]]:
    """``(index, fn(item))`` as jobs complete; ``(index, lost(item))`` for a job that kills
    its worker process twice.

    At most ``in_flight`` jobs are submitted at a time: what was submitted may run even after
    Ctrl-C (the pool moves it to its workers' queue at once), and it is what a break costs.
    On any other exception (Ctrl-C included) the jobs not started are cancelled and it
    propagates. Ctrl-C noted by :func:`interrupt.deferred` is raised between completions
    (checked every 0.2 s). Workers ignore SIGINT; on the way out the parent sets their stop
    flag (:func:`interrupt.follow`), so running jobs end at their next whole instant.
    """
    stop = multiprocessing.get_context().Event()
    initializer = functools.partial(_worker_init, stop)
    todo = deque(enumerate(items))
    try:
        while todo:
            suspects = yield from _pass(fn, todo, workers, in_flight, initializer, stop)
            for index, item in suspects:
                yield index, _alone(fn, item, lost, initializer)
    finally:
        stop.set()  # also when the caller stops consuming: nothing keeps running for nobody


def _pass(
    fn: Callable[[T], R],
    todo: deque[tuple[int, T]],
    workers: int,
    in_flight: int,
    initializer: Callable[[], None],
    stop: Any,
) -> Generator[tuple[int, R], None, list[tuple[int, T]]]:
    """Run jobs from ``todo`` until it is empty or the pool breaks; the jobs the break took."""
    with ProcessPoolExecutor(max_workers=workers, initializer=initializer) as pool:
        running: dict[Future[R], tuple[int, T]] = {}
        try:
            while todo or running:
                while todo and len(running) < in_flight:
                    job = todo.popleft()
                    running[pool.submit(fn, job[1])] = job
                finished, _ = wait(running, timeout=0.2, return_when=FIRST_COMPLETED)
                interrupt.check()
                results, broken = [], False
                for fut in sorted(finished, key=lambda f: running[f][0]):
                    try:
                        results.append((running[fut][0], fut.result()))
                        del running[fut]
                    except BrokenProcessPool:
                        broken = True
                yield from results
                if broken:  # what the pool still held, finished or not, went with it
                    return sorted(running.values(), key=lambda job: job[0])
        except BaseException:
            stop.set()  # before the pool's shutdown waits for the jobs still running
            for fut in running:
                fut.cancel()
            raise
    return []


def _worker_init(stop: Any) -> None:
    """A forked worker inherits the parent's handlers and deferral state: start clean.

    SIGINT is ignored (the terminal sends it to the workers too; an idle one would die of
    it and break the pool); the parent stops running jobs through ``stop`` instead.
    """
    interrupt.follow(stop)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _alone(
    fn: Callable[[T], R],
    item: T,
    lost: Callable[[T], R],
    initializer: Callable[[], None],
) -> R:
    """``fn(item)`` in a process of its own, or ``lost(item)`` if it kills that one too."""
    with ProcessPoolExecutor(max_workers=1, initializer=initializer) as pool:
        try:
            return pool.submit(fn, item).result()
        except BrokenProcessPool:
            return lost(item)
