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
    """A 100 000 s run into ``out``, returned once ``trace.csv.tmp`` exists (plus 0.3 s)."""
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
    deadline = time.monotonic() + 30
    while not (out / "trace.csv.tmp").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.3)
    return proc
