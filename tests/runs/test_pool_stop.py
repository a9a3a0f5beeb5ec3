"""``sweep -j2`` and ``test -j2`` never leave a worker behind: workers die with a SIGKILLed
parent, and a second Ctrl-C or SIGTERM stops a pool whose jobs are stuck inside a
component's ``do_step`` at once (the first asks them to stop at their next instant, which a
stuck ``do_step`` never reaches)."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import sigint
from deadlines import HANG_S

TESTS = Path(__file__).resolve().parent.parent

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="uses /proc")


def children(pid: int) -> set[int]:
    """Direct children of ``pid`` (from /proc)."""
    found = set()
    for task in Path(f"/proc/{pid}/task").iterdir():
        text = (task / "children").read_text().split()
        found |= {int(c) for c in text}
    return found


def alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state != "Z"


def wait_for(what: str, check: object, timeout: float = HANG_S) -> None:
    deadline = time.monotonic() + timeout
    while not check():  # type: ignore[operator]
        assert time.monotonic() < deadline, f"timed out waiting until {what}"
        time.sleep(0.05)


def start_stuck(tmp_path: Path, command: str, grace: float) -> tuple[subprocess.Popen[str], Path]:
    """``command`` (sweep or test) at -j2, returned once both workers are stuck in do_step."""
    mark = tmp_path / "stuck"
    files = []
    for name in ("a", "b"):
        path = tmp_path / f"{name}.yaml"
        path.write_text(
            "world:\n  components:\n"
            "    R: {template: 'rogue:Rogue', freq: 4, params: {mode: stuck}}\n"
            "duration: 5\nexpect:\n  - {trace: R.u, below: 5}\n"
        )
        files.append(str(path))
    if command == "sweep":
        # one run per process: the pool's own stop (a batch steps Rogue's copies through
        # its step_many, which never gets stuck)
        argv = ["sweep", files[0], "--grid", "R.k=1,2,3", "--executor", "local"]
        argv += ["--out", str(tmp_path / "o")]
    else:
        argv = ["test", *files]
    env = {
        **os.environ,
        "PYTHONPATH": str(TESTS),
        "ROGUE_MARK": str(mark),
        "AMSA_PHYS_STOP_GRACE_S": str(grace),
    }
    proc = subprocess.Popen(
        [sys.executable, "-m", "amsa_phys", *argv, "-j", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,
        preexec_fn=sigint.at_default,
    )
    wait_for("two workers are stuck", lambda: len(list(tmp_path.glob("stuck.*"))) == 2)
    return proc, mark


def stuck_workers(tmp_path: Path) -> list[int]:
    return [int(p.suffix[1:]) for p in tmp_path.glob("stuck.*")]


@pytest.mark.parametrize("command", ["sweep", "test"])
def test_workers_die_with_a_sigkilled_parent(tmp_path: Path, command: str) -> None:
    proc, _ = start_stuck(tmp_path, command, grace=600)
    try:
        workers = stuck_workers(tmp_path)
        assert set(workers) <= children(proc.pid)
        proc.kill()
        proc.communicate(timeout=HANG_S)
        wait_for("the workers are gone", lambda: not any(alive(w) for w in workers))
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        for w in stuck_workers(tmp_path):
            if alive(w):
                os.kill(w, signal.SIGKILL)


@pytest.mark.parametrize(
    ("command", "sig"),
    [("sweep", signal.SIGINT), ("test", signal.SIGTERM)],
    ids=["sweep-ctrl-c", "test-sigterm"],
)
def test_a_second_signal_stops_a_stuck_pool_at_once(
    tmp_path: Path, command: str, sig: signal.Signals
) -> None:
    # the grace period is longer than the test's own timeout: only the second signal can
    # end the command in time
    proc, _ = start_stuck(tmp_path, command, grace=600)
    try:
        workers = stuck_workers(tmp_path)
        proc.send_signal(sig)
        with pytest.raises(subprocess.TimeoutExpired):  # the first only asks the jobs to stop
            proc.wait(timeout=1)
        # the second press; pressed again while it is not handled yet (two signals sent too
        # close together are delivered as one)
        deadline = time.monotonic() + HANG_S
        while proc.poll() is None and time.monotonic() < deadline:
            proc.send_signal(sig)
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(timeout=2)
        _, err = proc.communicate(timeout=HANG_S)
        assert proc.returncode == 130, err
        assert err.splitlines()[-1].startswith(f"error: {command} interrupted")
        assert not any(alive(w) for w in workers)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        for w in stuck_workers(tmp_path):
            if alive(w):
                os.kill(w, signal.SIGKILL)
