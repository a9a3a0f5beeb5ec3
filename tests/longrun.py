"""Start a long headless run in a subprocess and wait until it is writing its trace."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

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


def start_long_run(out: Path, **popen: object) -> subprocess.Popen[str]:
    """A 100 000 s run into ``out``, returned once it is running its loop: ``trace.csv.tmp``
    exists and has grown since it was first seen (rows are being written, so the signal
    handlers are installed and the run is past its start). Raises if it never gets there."""
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
        **popen,
    )  # type: ignore[call-overload]
    STARTED.append(proc)
    trace = out / "trace.csv.tmp"
    first: int | None = None
    deadline = time.monotonic() + 120  # a bound for a stuck run, not a wait for a fast one
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise AssertionError(f"the long run ended early with code {proc.returncode}")
        size = trace.stat().st_size if trace.exists() else None
        if size is not None and first is None:
            first = size
        elif size is not None and first is not None and size > first:
            return proc
        time.sleep(0.02)  # polling an event, not waiting a fixed time
    raise AssertionError(f"the long run wrote no trace rows into {trace} within 120 s")
