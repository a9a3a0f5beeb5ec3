"""Many independent jobs on local worker processes, in a way one dying worker cannot stop.

A worker process that dies (killed, out of memory, a crash in native code) breaks a
``ProcessPoolExecutor`` and fails every job it held. :func:`imap_resilient` hands out only a
few jobs at a time; after a break, the jobs the pool held run again one at a time, each in a
fresh process, so the job that kills its process a second time is found and reported through
``lost(item)``, the others give their results, and the rest go on in a new pool. Sweeps and
``amsa-phys test -j`` both run on it.

Workers never outlive the command. They die with their parent, even a SIGKILLed one
(:func:`die_with_parent`: ``PR_SET_PDEATHSIG`` on Linux, a thread watching the parent
elsewhere), so nothing keeps spinning on a core or holding the terminal's output open. When
the command stops early (Ctrl-C, SIGTERM, an error), running jobs are asked to stop at their
next whole instant and given :data:`STOP_GRACE_S`; a job stuck inside a component's
``do_step`` never gets there, so after that -- or at once on a second Ctrl-C or SIGTERM --
the workers are killed.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Generator, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, TypeVar

from ..engine import interrupt

T = TypeVar("T")
R = TypeVar("R")

WORKER_LOST = "a worker process died (killed, out of memory, or a crash in native code)"
#: How long running jobs get to stop at their next instant before their workers are killed
#: (``AMSA_PHYS_STOP_GRACE_S`` overrides it: a machine where a simulated second takes long).
STOP_GRACE_S = 10.0
_PR_SET_PDEATHSIG = 1  # linux/prctl.h


def imap_resilient(
    fn: Callable[[T], R],
    items: Sequence[T],
    workers: int,
    lost: Callable[[T], R],
    *,
    in_flight: int,
    finish_s: float = 0.0,
) -> Iterator[tuple[int, R]]:
    """``(index, fn(item))`` as jobs complete; ``(index, lost(item))`` for a job that kills
    its worker process twice.

    At most ``in_flight`` jobs are submitted at a time: what was submitted may run even after
    Ctrl-C (the pool moves it to its workers' queue at once), and it is what a break costs.
    On any other exception (Ctrl-C included) the jobs not started are cancelled and it
    propagates. Ctrl-C noted by :func:`interrupt.deferred` is raised between completions
    (checked every 0.2 s). Workers ignore SIGINT; on the way out the parent sets their stop
    flag (:func:`interrupt.follow`), so running jobs end at their next whole instant.

    ``finish_s`` > 0 (short jobs whose partial work is worth nothing, a sweep's batches):
    on Ctrl-C the running jobs get that long to finish, their results are yielded before
    the Ctrl-C propagates, and the workers of the rest are killed at once.
    """
    stop = multiprocessing.get_context().Event()
    initializer = functools.partial(_worker_init, stop, os.getpid())
    todo = deque(enumerate(items))
    try:
        while todo:
            suspects = yield from _pass(fn, todo, workers, in_flight, initializer, stop, finish_s)
            for index, item in suspects:
                yield index, _alone(fn, item, lost, initializer, stop)
    finally:
        stop.set()  # also when the caller stops consuming: nothing keeps running for nobody


def _pass(
    fn: Callable[[T], R],
    todo: deque[tuple[int, T]],
    workers: int,
    in_flight: int,
    initializer: Callable[[], None],
    stop: Any,
    finish_s: float = 0.0,
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
        except KeyboardInterrupt:
            if finish_s <= 0:
                _stop(pool, running, stop)
                raise
            finished = _finished_within(running, finish_s)
            stop.set()
            for fut in running:
                fut.cancel()
            _kill_workers(pool)  # what is left is lost either way: at once, not after a grace
            yield from finished
            raise
        except BaseException:
            _stop(pool, running, stop)
            raise
    return []


def _stop(pool: ProcessPoolExecutor, running: dict[Future[Any], Any], stop: Any) -> None:
    """The stop flag, then no job not started, then the running ones stopped or killed."""
    stop.set()  # before the pool's shutdown waits for the jobs still running
    for fut in running:
        fut.cancel()
    _stop_running(pool, list(running))


def _finished_within(
    running: dict[Future[R], tuple[int, Any]], seconds: float
) -> list[tuple[int, R]]:
    """``(index, result)`` of the running jobs that finish within ``seconds`` (none if a
    second Ctrl-C comes meanwhile: the user wants out now), in index order."""
    try:
        done, _ = wait(running, timeout=seconds)
    except BaseException:  # a second Ctrl-C or SIGTERM, raised at once by interrupt.request
        return []
    out = []
    for fut in sorted(done, key=lambda f: running[f][0]):
        with contextlib.suppress(BaseException):  # a job that failed or was cancelled
            out.append((running[fut][0], fut.result()))
    return out


def _stop_running(pool: ProcessPoolExecutor, running: list[Future[Any]]) -> None:
    """Let running jobs stop at their next instant, or kill their workers.

    They get :data:`STOP_GRACE_S`; a second Ctrl-C or SIGTERM meanwhile (raised here at once
    by ``interrupt.request``) kills them at once -- the README's promise -- and propagates.
    """
    try:
        _, late = wait(running, timeout=_grace_s())
    except BaseException:
        _kill_workers(pool)
        raise
    if late:
        _kill_workers(pool)


def _grace_s() -> float:
    try:
        return max(0.0, float(os.environ.get("AMSA_PHYS_STOP_GRACE_S", STOP_GRACE_S)))
    except ValueError:
        return STOP_GRACE_S


def _kill_workers(pool: ProcessPoolExecutor) -> None:
    """SIGKILL every worker of ``pool`` (a stuck ``do_step`` never returns to check)."""
    processes = getattr(pool, "_processes", None) or {}  # concurrent.futures' own table
    for proc in list(processes.values()):
        with contextlib.suppress(OSError, ValueError, AttributeError):  # already gone
            proc.kill()


def die_with_parent(parent_pid: int) -> None:
    """Make this process die when ``parent_pid``, its parent, does (even of SIGKILL).

    Linux: ``prctl(PR_SET_PDEATHSIG, SIGKILL)``; if the parent died before the call, this
    process is already an orphan and exits now. Elsewhere a daemon thread notices that the
    parent changed (it became an orphan) within half a second.
    """
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0:
                if os.getppid() != parent_pid:
                    os._exit(1)
                return
        except (OSError, AttributeError):
            pass
    threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True).start()


def _watch_parent(parent_pid: int) -> None:
    """The fallback of :func:`die_with_parent`: poll for being orphaned."""
    while os.getppid() == parent_pid:
        time.sleep(0.5)
    os._exit(1)


def _worker_init(stop: Any, parent_pid: int) -> None:
    """A forked worker inherits the parent's handlers and deferral state: start clean.

    SIGINT is ignored (the terminal sends it to the workers too; an idle one would die of
    it and break the pool); the parent stops running jobs through ``stop`` instead. The
    worker dies with its parent (:func:`die_with_parent`).
    """
    die_with_parent(parent_pid)
    interrupt.follow(stop)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _alone(
    fn: Callable[[T], R],
    item: T,
    lost: Callable[[T], R],
    initializer: Callable[[], None],
    stop: Any,
) -> R:
    """``fn(item)`` in a process of its own, or ``lost(item)`` if it kills that one too."""
    with ProcessPoolExecutor(max_workers=1, initializer=initializer) as pool:
        fut = pool.submit(fn, item)
        try:
            while True:  # polled, so that a noted Ctrl-C is raised here
                done, _ = wait([fut], timeout=0.2)
                interrupt.check()
                if done:
                    return fut.result()
        except BrokenProcessPool:
            return lost(item)
        except BaseException:
            stop.set()
            _stop_running(pool, [fut])
            raise
