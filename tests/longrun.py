"""Start a long headless run in a subprocess and wait until it is writing its trace."""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import sigint
from deadlines import HANG_S  # bounds a hang only: a run not writing rows by then is broken

FIXTURE = Path(__file__).resolve().parent / "fixtures" / "mde_short.yaml"

#: Every long run started, so that ``conftest.py`` can stop any a failed test left running.
STARTED: list[subprocess.Popen[str]] = []


def stop_leftovers() -> None:
    """Kill the long runs still alive (a test failed before it ended its run)."""
    while STARTED:
        proc = STARTED.pop()
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def wait_until(
    what: str, done: Callable[[], bool], proc: subprocess.Popen[str] | None = None
) -> None:
    """Poll ``done`` until true; fail naming ``what`` if ``proc`` exits or on a hang.

    A test waits for the event it needs, never for a fixed time: how long it takes depends
    on the machine and its load (issue 33, 11).
    """
    deadline = time.monotonic() + HANG_S
    while not done():
        if proc is not None and proc.poll() is not None:
            raise AssertionError(f"the process exited ({proc.returncode}) before {what}")
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {HANG_S:g} s waiting until {what}")
        time.sleep(0.05)


def has_rows(trace_tmp: Path) -> bool:
    """Whether a trace being written holds data rows: the header and the first chunk of
    rows reach the file together (``engine/tracefile.py`` writes rows 256 at a time)."""
    try:
        return trace_tmp.stat().st_size > 0
    except FileNotFoundError:
        return False


def start_long_run(out: Path, **popen: object) -> subprocess.Popen[str]:
    """A 100 000 s run into ``out``, returned once it has written rows to ``trace.csv.tmp``
    (so its stepping loop runs, and an interrupt then keeps at least 256 rows)."""
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "amsa_phys",
            "run",
            str(FIXTURE),
            "--headless",
            "--out",
            str(out),
            "--duration",
            "100000",
            "--no-plot",
            "-q",
        ],
        text=True,
        **{"preexec_fn": sigint.at_default, **popen},
    )  # type: ignore[call-overload]
    STARTED.append(proc)
    wait_until("the run wrote trace rows", lambda: has_rows(out / "trace.csv.tmp"), proc)
    return proc
