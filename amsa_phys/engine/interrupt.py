"""Ctrl-C and SIGTERM stop a run *between* two calls of ``Simulation.advance``, never inside one.

Why: Python raises KeyboardInterrupt wherever the main thread happens to be. Inside an
instant it can land between two statements that belong together -- CI caught one between
appending a quality sample's time and its value, and the metrics then failed with an
IndexError and a traceback instead of exit 130 -- or half-way through a component's
``doStep``, so the outputs finalised afterwards describe a state no instant ever had.

So while a run is going (:func:`deferred`), the signal handler only notes the request and
``Simulation.advance`` raises KeyboardInterrupt when it returns: every simulated second in a
headless run, every frame in the window and in a recording, which is well under a
wall-clock second for any world this project ships. A second signal raises at once: the user
insists. A component stuck in an endless loop never returns from ``advance``, so one signal
must do too: while a run steps (:func:`stepping`), a request not honoured within
:data:`GRACE_S` raises KeyboardInterrupt where the main thread is (a SIGALRM timer), as the
second signal would; the run then finalises its outputs the same way.

A KeyboardInterrupt a component raises *itself* is not the user's: :func:`users_interrupt`
tells them apart (the user's always went through :func:`request` first while a run defers),
and the engine makes the component's own a run fault naming it (``engine/tasks.py``).

Only the main thread can own signal handlers, and a SIGINT handler somebody else installed (a
sweep worker ignores SIGINT; a host application has its own; a shell script's ``cmd &`` starts
its job with SIGINT ignored) is left alone. The deferral itself holds whoever owns SIGINT: the
CLI's SIGTERM handler (:func:`sigterm_as_ctrl_c`) only ever requests a stop while a run
defers. It used to depend on SIGINT too, so ``amsa-phys run ... > log &`` from a script
(SIGINT ignored) was stopped by ``kill`` wherever it was, mid-second and even mid-instant,
while the same run in a terminal stopped on a whole second.

Sweeps and ``amsa-phys test -j`` defer interrupts in the main process too: Ctrl-C raised inside
``concurrent.futures`` (holding one of its locks) could hang the pool's shutdown. Their
loops wait with a timeout and call :func:`check` between completions.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import Any

_MAIN = threading.main_thread().ident

_installed = 0  # deferrals whose handler is in place (nested runs share one request)
_requested = False
_seen = False  # whether the pending request has been read (:func:`requested`) since it came
_external: Any = None  # a worker process's stop flag, set by its parent (multiprocessing.Event)
_stepping = 0  # main-thread runs inside ``advance`` (:func:`stepping`)
_alarm: Any = None  # the SIGALRM handler replaced while the grace timer is armed

#: how long (s) a stop request may wait for the run to reach a whole instant before it is
#: raised where the main thread is: a stuck component must not ignore the first Ctrl-C
GRACE_S = 0.5


def request(signum: int | None = None, frame: FrameType | None = None) -> None:
    """Signal handler: note a stop request, or raise at once.

    At once when no run defers interrupts, or when a request is already pending (the
    second Ctrl-C). Also the CLI's SIGTERM handler, so ``kill`` behaves like Ctrl-C.
    """
    global _requested
    if not _installed or _requested:
        raise KeyboardInterrupt
    _requested = True
    if _stepping:
        _arm()


def _arm() -> None:
    """Raise the request where the main thread is if ``advance`` has not returned by then."""
    global _alarm
    if _alarm is None:
        _alarm = signal.signal(signal.SIGALRM, _overdue)
    signal.setitimer(signal.ITIMER_REAL, GRACE_S)


def _disarm() -> None:
    global _alarm
    if _alarm is not None:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, _alarm)
        _alarm = None


def _overdue(signum: int, frame: FrameType | None) -> None:
    if _stepping and _requested:
        raise KeyboardInterrupt


def users_interrupt() -> bool:
    """Whether a KeyboardInterrupt now is the user's: a stop was requested (a signal noted,
    or this worker's parent's), or no run defers interrupts (nobody noted them: it may be)."""
    return requested() or (not _installed and _external is None)


@contextmanager
def stepping() -> Iterator[None]:
    """Around a run's ``advance`` in the main thread: a stop requested meanwhile is raised
    after :data:`GRACE_S` if the step does not return (a component stuck in a loop)."""
    global _stepping
    if threading.get_ident() != _MAIN:
        yield
        return
    _stepping += 1
    if _requested and _installed:  # asked between two steps: this one gets the grace too
        _arm()
    try:
        yield
    finally:
        _stepping -= 1
        if not _stepping:
            _disarm()


def requested() -> bool:
    """Whether a stop was requested during the current run (or by this worker's parent)."""
    global _seen
    if _requested:
        _seen = True  # somebody now knows: the deferral's end need not raise it (deferred)
        return True
    return _external is not None and _external.is_set()


def follow(stop: Any) -> None:
    """In a worker process: forget the parent's deferral state, and stop when ``stop`` is set.

    Workers ignore SIGINT themselves (one idle between two jobs would die of it); their
    parent owns Ctrl-C and sets ``stop`` (a ``multiprocessing.Event``), which
    :func:`requested` reads, so a running job ends at its next whole instant however the
    parent was told (a terminal's Ctrl-C, ``kill -INT`` or SIGTERM to the parent alone).
    """
    global _installed, _requested, _external
    _installed = 0
    _requested = False
    _external = stop


def check() -> None:
    """Raise KeyboardInterrupt if a stop was requested: call where the state is whole."""
    if requested():
        raise KeyboardInterrupt


@contextmanager
def deferred() -> Iterator[None]:
    """While active, SIGINT (if Python's default handler has it) and the CLI's SIGTERM
    (:func:`sigterm_as_ctrl_c`, whoever owns SIGINT) only request a stop.

    A request nobody read (:func:`requested`) by the time the outermost deferral ends, and
    the block ended without an exception, is raised then, as KeyboardInterrupt: it came
    after the block's last look (a Ctrl-C while a progress bar closed, say), and dropping it
    would ignore the user's Ctrl-C, as a falsify run once did, finishing its search and
    exiting 1 instead of 130. A request that was read is the reader's to act on.
    """
    global _installed, _requested, _seen
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    take_sigint = signal.getsignal(signal.SIGINT) in (signal.default_int_handler, request)
    previous = signal.signal(signal.SIGINT, request) if take_sigint else None
    if not _installed:
        _requested = _seen = False
    _installed += 1
    failed = False
    try:
        yield
    except BaseException:
        failed = True
        raise
    finally:
        _installed -= 1
        if take_sigint:
            signal.signal(signal.SIGINT, previous)
        if not _installed:
            unread = _requested and not _seen
            _requested = _seen = False
            if unread and not failed:
                raise KeyboardInterrupt


@contextmanager
def sigterm_as_ctrl_c() -> Iterator[None]:
    """While a command runs, ``kill`` (SIGTERM) is handled like Ctrl-C (:func:`request`)."""
    previous = signal.signal(signal.SIGTERM, request)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
