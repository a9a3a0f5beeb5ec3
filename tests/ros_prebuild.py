"""Building the session's catkin workspaces in the background, while the tests before them run.

A catkin build of an exported package costs 15-60 s of compiler time, and the ROS test files
come in the middle of the suite: while the tests before them run in pytest's one process, a
2-core machine has a core to spare. The session fixture below starts a :class:`Prebuilder`
for the packages the collected tests will build, one after the other, at the lowest CPU
priority (the tests running meanwhile keep theirs); :func:`ros_launch.build_workspace` then
takes the one it was about to build: finished, it is used at once; under way, it is put back
to normal priority and waited for (its end is the event, no time is guessed); not started,
it is dropped from the queue and built as before, in the foreground. A build that failed
fails the test that takes it, with catkin's output. Nothing in a build depends on when it
ran: it is the same commands (:func:`build_commands`) in the same kind of fresh directory.
"""

from __future__ import annotations

import contextlib
import os
import resource
import signal
import subprocess
import sys
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest

Key = tuple[Path, str, bool]  # (scenario, package name, catkin_make install as well)

#: ``ros_short_workspace``'s build (tests/ros/conftest.py): tests/fixtures/ros_short.yaml as
#: package mdeChallenge, installed too
ROS_SHORT: Key = (
    Path(__file__).resolve().parent / "fixtures" / "ros_short.yaml",
    "mdeChallenge",
    True,
)


def build_commands(
    ws: Path, scenario: Path, pkg: str, install: bool, export_args: tuple[str, ...] = ()
) -> list[tuple[list[str], dict[str, str]]]:
    """The commands (and their environments) that make ``ws``: ``amsa-phys export ros`` of
    ``scenario`` (with ``export_args``) as ``pkg`` into ``ws/src``, then catkin_make (and
    install). Every core for make and no load limit: catkin's default ``-jN -lN`` makes the
    build serial as soon as the machine's load average reaches its core count, on a loaded
    CI machine all along."""
    export = [sys.executable, "-m", "amsa_phys", "export", "ros", str(scenario), *export_args]
    catkin = ["catkin_make", *(["install"] if install else []), "-C", str(ws)]
    # Debian's python3 for catkin's own scripts (a venv's lacks catkin_pkg)
    catkin += [f"-j{os.cpu_count() or 1}", "-DPYTHON_EXECUTABLE=/usr/bin/python3"]
    no_pythonpath = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    return [
        ([*export, "-o", str(ws / "src" / pkg)], {**os.environ, "PWD": str(ws)}),
        (catkin, {**no_pythonpath, "PWD": str(ws)}),
    ]


@dataclass
class _Build:
    key: Key
    ws: Path
    log: Path  # the commands' output, beside ws
    done: threading.Event = field(default_factory=threading.Event)
    urgent: bool = False  # a test waits for it: no lowered priority from now on
    error: str | None = None


class Prebuilder:
    """One thread building ``wanted`` in order, each in a fresh directory under ``root``."""

    def __init__(self, root: Path, wanted: list[Key]) -> None:
        self._lock = threading.Lock()
        self._queue = [
            _Build(key, root / f"ws{i}", root / f"ws{i}.log") for i, key in enumerate(wanted)
        ]
        self._current: _Build | None = None
        self._finished: dict[Key, _Build] = {}
        self._proc: subprocess.Popen[bytes] | None = None
        self._stopped = False
        self.cpu = 0.0  # seconds of CPU its finished commands spent
        self._halt = threading.Event()
        self._thread = threading.Thread(target=self._run, name="ros-prebuild", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def _next(self) -> _Build | None:
        with self._lock:
            if self._stopped or not self._queue:
                self._current = None
                return None
            self._current = self._queue.pop(0)
            return self._current

    def _run(self) -> None:
        while (build := self._next()) is not None:
            try:
                build.ws.mkdir(parents=True)
                for command, env in build_commands(build.ws, *build.key):
                    if self._execute(build, command, env):
                        break
            except Exception as exc:  # said by the test that takes it, not lost in a thread
                build.error = f"background build in {build.ws}: {exc!r}"
            finally:
                with self._lock:
                    self._finished[build.key] = build
                build.done.set()
        # alive until the session ends, all builds done or not: a test that counts the
        # process's threads around its work (test_gym_episode.py) must see the same number
        self._halt.wait()

    def _execute(self, build: _Build, command: list[str], env: dict[str, str]) -> bool:
        """Run one command of ``build``; True when it failed (``build.error`` says how)."""
        with self._lock:
            if self._stopped:
                build.error = "stopped before the end of the session's tests"
                return True
            nice = [] if build.urgent else ["nice", "-n", "19"]
            # output to a file, not a pipe: a process the tests fork meanwhile (a pool's
            # worker) would inherit a pipe's open end and hold back its end of file
            with build.log.open("a") as log:
                self._proc = subprocess.Popen(
                    [*nice, *command],
                    cwd=build.ws,
                    stdout=log,
                    stderr=subprocess.STDOUT,
                    env=env,
                    start_new_session=True,  # its own process group: reniced or ended whole
                )
        # os.wait4: the command's CPU (with its waited-for descendants'), which is no test's
        # (tests/tiers.py takes it off the CPU budget of the test running meanwhile). Waited
        # for first without reaping it (WNOWAIT), then reaped and counted in one step under
        # _REAP, so a reading of the children's CPU never sees the one without the other
        try:
            os.waitid(os.P_PID, self._proc.pid, os.WEXITED | os.WNOWAIT)
            with _REAP:
                _, status, usage = os.wait4(self._proc.pid, 0)
                with self._lock:
                    self.cpu += usage.ru_utime + usage.ru_stime
        except ChildProcessError:  # reaped by a poll() of take() or stop() (a ROS test's)
            self._proc.wait()
        else:
            self._proc.returncode = os.waitstatus_to_exitcode(status)
        if self._proc.returncode != 0:
            output = build.log.read_text(errors="replace")[-3000:]
            build.error = f"{' '.join(command)} failed ({self._proc.returncode}):\n{output}"
            return True
        return False

    def take(self, key: Key) -> _Build | None:
        """The build of ``key``, finished (waited for at normal priority if under way); None
        when none was queued or it had not started (it is not built in the background then)."""
        with self._lock:
            if key in self._finished:
                return self._finished.pop(key)
            for build in self._queue:
                if build.key == key:
                    self._queue.remove(build)
                    return None
            build = self._current
            if build is None or build.key != key:
                return None
            build.urgent = True
            if self._proc is not None and self._proc.poll() is None:
                with contextlib.suppress(OSError):  # lowering niceness needs root, as ROS tests do
                    os.setpriority(os.PRIO_PGRP, self._proc.pid, 0)
        build.done.wait()
        return build

    def stop(self) -> None:
        """End the build under way (its process group, by id) and drop the rest."""
        with self._lock:
            self._stopped = True
            self._halt.set()
            self._queue.clear()
            if self._proc is not None and self._proc.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(self._proc.pid, signal.SIGKILL)
        if self._thread.is_alive():
            self._thread.join()


_active: Prebuilder | None = None
_spent = 0.0  # the CPU of the builders stopped so far
#: held while a build is reaped and its CPU added to :func:`cpu_spent`, and while
#: :func:`tests_children_cpu` reads the two: the kernel counts a reaped child in
#: ``RUSAGE_CHILDREN`` at once, so without it a test measuring in between was charged the
#: whole build (a 32 s "unknown-param" error test in CI)
_REAP = threading.Lock()


def start(root: Path, wanted: list[Key]) -> Prebuilder:
    """Start building ``wanted`` in the background; :func:`take` hands them out."""
    global _active
    _active = Prebuilder(root, wanted)
    _active.start()
    return _active


def take(key: Key) -> _Build | None:
    """The background build of ``key`` (see :meth:`Prebuilder.take`), or None."""
    return None if _active is None else _active.take(key)


def cpu_spent() -> float:
    """CPU seconds the session's background builds have spent so far (finished commands)."""
    return _spent + (0.0 if _active is None else _active.cpu)


def tests_children_cpu() -> float:
    """CPU seconds of this process's waited-for children less the background builds': what
    the tests' own children spent. One consistent reading (:data:`_REAP`)."""
    with _REAP:
        kids = resource.getrusage(resource.RUSAGE_CHILDREN)
        return kids.ru_utime + kids.ru_stime - cpu_spent()


def stop() -> None:
    global _active, _spent
    if _active is not None:
        _active.stop()
        _spent += _active.cpu
        _active = None


# -- the pytest side: registered by tests/conftest.py (``pytest_plugins``), so that the builds
# start at the session's first test, whatever folder it is in


def _skipped(item: pytest.Item) -> bool:
    """Marked to be skipped whatever happens (a skipif whose condition is already True)."""
    for mark in item.iter_markers():
        if mark.name == "skip" or (mark.name == "skipif" and mark.args and mark.args[0] is True):
            return True
    return False


def _builds_wanted(items: list[pytest.Item]) -> list[tuple[Path, str, bool]]:
    """The catkin builds the collected tests will ask for, in the order they will: the
    session's ros_short, and the ``SCENARIO`` as ``PKG`` of every module that imports
    ``build_workspace`` (a module building something else builds it in the foreground)."""
    wanted: list[tuple[Path, str, bool]] = []
    for item in items:
        module = getattr(item, "module", None)
        if module is None or _skipped(item):
            continue
        if "ros_short_workspace" in getattr(item, "fixturenames", ()):
            key = (ROS_SHORT[0].resolve(), *ROS_SHORT[1:])
        elif getattr(getattr(module, "build_workspace", None), "__module__", "") == "ros_launch":
            scenario, pkg = getattr(module, "SCENARIO", None), getattr(module, "PKG", None)
            if not isinstance(scenario, Path) or not isinstance(pkg, str):
                continue
            key = (scenario.resolve(), pkg, False)
        else:
            continue
        if key not in wanted:
            wanted.append(key)
    return wanted


@pytest.fixture(scope="session", autouse=True)
def _ros_prebuild(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[None]:
    """The session's catkin builds start in the background at the session's first test, at
    the lowest CPU priority, while the tests before the ROS files run; whatever is still
    building when the session ends is ended."""
    wanted = _builds_wanted(request.session.items)
    if wanted:
        from ros_launch import ros_missing

        if ros_missing() is not None:
            wanted = []
    if not wanted:
        yield
        return
    start(tmp_path_factory.mktemp("ros_prebuild"), wanted)
    try:
        yield
    finally:
        stop()
