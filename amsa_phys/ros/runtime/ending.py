"""How the simulator node ends a launch: a last ``done:`` line, and a clean shutdown.

The simulator is a ``required`` node: when it exits, roslaunch stops the launch. But roslaunch
announces any required node's exit in red, "REQUIRED process [amsa_simulator-2] has died!",
even after a run that completed and passed every check, which reads as a crash. So after a
passing run the simulator asks roslaunch (its parent process) to shut the launch down as
Ctrl-C would, and waits to be stopped by it: the launch then ends with roslaunch's own
"shutting down processing monitor ... done" and exits 0. A run that failed a check or faulted
keeps the red message (it is one), and the simulator's last line says which.
"""

from __future__ import annotations

import os
import signal
import threading
from pathlib import Path
from typing import Any

from ...model.wording import plural
from .. import names

#: How long the simulator waits for roslaunch to stop it before exiting by itself (roslaunch
#: gives each node up to 15 s to end on SIGINT; it signals the nodes one after the other).
WAIT_S = 60.0


def done_line(checks: list[Any], out_dir: Path) -> str:
    """The simulator's last line: ``amsa_simulator: done: ...`` with the checks' verdict."""
    failed = [c for c in checks if not c.passed]
    skipped = sum(1 for c in checks if c.passed and c.skipped)  # a cut run judges fewer
    if not checks:
        verdict = "no expectations to check"
    elif failed:
        verdict = f"{len(failed)} of {plural(len(checks), 'expectation')} FAILED"
    else:
        verdict = f"{plural(len(checks) - skipped, 'expectation')} passed"
    if skipped:
        verdict += f", {skipped} skipped (not judged by this run)"
    return f"{names.SIMULATOR}: done: {verdict}; outputs in {out_dir}"


def launched_by_roslaunch() -> int | None:
    """The parent's process id if it is roslaunch (the simulator is one of its nodes)."""
    parent = os.getppid()
    try:
        argv = Path(f"/proc/{parent}/cmdline").read_bytes().split(b"\0")
    except OSError:
        return None
    return (
        parent
        if any(Path(a.decode(errors="replace")).name == "roslaunch" for a in argv[:2])
        else None
    )


def end_launch(code: int) -> None:
    """After a passing run (``code`` 0), shut the launch down through roslaunch, quietly.

    roslaunch's SIGINT (a terminal's Ctrl-C) stops every node and prints no alarm; it sends
    SIGINT to this process too, which then returns (the caller exits with ``code``). Does
    nothing for another code, or when the parent is not roslaunch (``rosrun`` by hand).
    """
    parent = launched_by_roslaunch() if code == 0 else None
    if parent is None:
        return
    stopped = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stopped.set())
    os.kill(parent, signal.SIGINT)
    stopped.wait(WAIT_S)  # roslaunch's SIGINT ends the wait (Python runs handlers here)
