"""Launching an exported ROS package in a test: a private network, no process left behind.

Shared by the ROS tests (``tests/ros/``). Every launch runs in a private network namespace
(``unshare -n``: roscpp listens on all interfaces) and every process it starts carries a
token in its environment, so a test can prove none is left behind (and end stragglers by
their id).
"""

from __future__ import annotations

import contextlib
import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import ros_prebuild
import sigint

#: s of wall time before a launch is declared hung (and killed): a deadline for a failure,
#: never a measured time, so set for a loaded machine (a launch there takes minutes)
LAUNCH_TIMEOUT = 600


def ros_missing() -> str | None:
    for tool in ("roslaunch", "catkin_make", "rosbag", "unshare", "nsenter", "ip"):
        if shutil.which(tool) is None:
            return f"{tool} is not installed (ROS 1 from Debian: see .ci/run)"
    if os.geteuid() != 0:
        return "unshare -n (a private network for roscpp) needs root"
    probe = subprocess.run(["unshare", "-n", "true"], capture_output=True)
    if probe.returncode != 0:
        return "unshare -n is not permitted here"
    return None


def _leftovers(token: str) -> list[int]:
    """Processes whose environment holds ``token`` (ours, whatever session they made)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            env = (entry / "environ").read_bytes()
        except OSError:
            continue
        if f"AMSA_ROS_TEST={token}".encode() in env.split(b"\0"):
            found.append(int(entry.name))
    return found


class Launch:
    """One roslaunch of the package in its own network namespace and process group."""

    def __init__(self, ws: Path, launch: str, *args: str) -> None:
        if not any(a.startswith("timeout:=") for a in args):
            # a node waits twice ``timeout:=`` (60 s by default) for its peers: on a loaded
            # machine a peer can take longer than that to start, and the launch failed for
            # it; a test that means a wait to run out says its own ``timeout:=``
            args = (*args, f"timeout:={LAUNCH_TIMEOUT}")
        self.token = uuid.uuid4().hex
        script = ws / "launch.sh"
        env = {k: v for k, v in os.environ.items() if not k.startswith("ROS") and k != "PYTHONPATH"}
        env["AMSA_ROS_TEST"] = self.token
        env["AMSA_PHYS_PYTHON"] = sys.executable  # the package names no Python of its own
        env["ROS_HOME"] = str(ws / "roshome")
        env["PWD"] = str(ws)
        self.proc = subprocess.Popen(
            ["unshare", "-n", "bash", str(script), launch, *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
            start_new_session=True,
            preexec_fn=sigint.at_default,
        )
        self.lines: list[str] = []
        self.hung = False  # the watchdog killed it
        self.watchdog = threading.Timer(LAUNCH_TIMEOUT, self._hung)
        self.watchdog.daemon = True
        self.watchdog.start()

    def _hung(self) -> None:
        self.hung = True
        self.kill()

    def kill(self) -> None:
        """End the launch and anything it started (by process id)."""
        for pid in [self.proc.pid, *_leftovers(self.token)]:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)

    def read_until(self, marker: str) -> bool:
        """Read output lines until one contains ``marker`` (False at the end of output)."""
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line)
            if marker in line:
                return True
        return False

    def finish(self) -> str:
        """Wait for the end; the whole output. Fails if a process outlived roslaunch."""
        assert self.proc.stdout is not None
        self.lines += self.proc.stdout.readlines()
        self.proc.wait()
        self.watchdog.cancel()
        if self.hung:  # say so: what follows (a missing bag, a cut output) is its consequence
            pytest.fail(f"the launch was killed after {LAUNCH_TIMEOUT} s: {self.lines[-30:]}")
        left = _leftovers(self.token)
        if left:
            names = [Path(f"/proc/{p}/cmdline").read_bytes()[:80] for p in left]
            self.kill()
            pytest.fail(f"processes left running after roslaunch exited: {names}")
        return "".join(self.lines)


@pytest.fixture
def launcher() -> Iterator[Callable[..., Launch]]:
    """Start launches; whatever a failing test leaves running is ended at teardown."""
    started: list[Launch] = []

    def start(ws: Path, launch: str, *args: str) -> Launch:
        started.append(Launch(ws, launch, *args))
        return started[-1]

    yield start
    for launch in started:
        launch.watchdog.cancel()
        launch.kill()
        launch.proc.wait()


def build_workspace(
    ws: Path, scenario: Path, pkg: str, install: bool = False, export_args: tuple[str, ...] = ()
) -> Path:
    """``scenario`` exported as package ``pkg`` in ``ws/src``, built with catkin; ``ws``
    gets ``launch.sh`` (``bash launch.sh NAME.launch ARGS``, run by :class:`Launch`), which
    sources the devel space. ``install``: also ``catkin_make install`` (``ws/install``, the
    space a workspace can be moved with). Where the session built the same in the background
    (tests/ros_prebuild.py) and ``ws`` is new and empty, ``ws`` becomes a link to that build
    (resolve it to reach the directory itself). ``export_args`` (``--duration 8``) are
    passed to the export: such a package is never the background build, always built here.
    (Not by patching ``ros_prebuild.build_commands``: the background builder calls it too,
    and a patch in force while it builds another package exports that one with them.)"""
    key = (scenario.resolve(), pkg, install)
    fresh = not ws.exists() or (ws.is_dir() and not any(ws.iterdir()))
    built = ros_prebuild.take(key) if fresh and not export_args else None
    t0 = time.perf_counter()
    if built is not None:
        assert built.error is None, built.error
        if ws.exists():
            ws.rmdir()
        ws.parent.mkdir(parents=True, exist_ok=True)
        ws.symlink_to(built.ws, target_is_directory=True)
        waited = time.perf_counter() - t0
        print(f"catkin_make: built in the background, waited {waited:.1f} s", file=sys.stderr)
    else:
        ws.mkdir(parents=True, exist_ok=True)
        for command, env in ros_prebuild.build_commands(ws, *key, export_args):
            done = subprocess.run(command, cwd=ws, capture_output=True, text=True, env=env)
            assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
        print(f"catkin_make: {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    (ws / "launch.sh").write_text(
        "set -e\n"
        "ip link set lo up\n"  # the namespace's loopback: the only interface ROS sees
        f"export ROS_LOG_DIR={ws}/roshome/log ROS_MASTER_URI=http://localhost:11311\n"
        "export ROS_HOSTNAME=localhost ROS_DISTRO=${ROS_DISTRO:-debian}\n"
        f"source {ws}/devel/setup.bash\n"
        f'exec roslaunch {pkg} "$@"\n'
    )
    return ws


@contextlib.contextmanager
def package_edit(path: Path, text: str) -> Iterator[Path]:
    """``path`` holds ``text`` inside the block; afterwards what it held before (or nothing,
    if it did not exist), whether the block passed or failed. Tests edit a workspace shared
    by the session (``ros_short_workspace`` in tests/ros/conftest.py) this way, so that the
    next test launches the package as it was built."""
    before = path.read_text() if path.exists() else None
    try:
        path.write_text(text)
        yield path
    finally:
        if before is None:
            path.unlink(missing_ok=True)
        else:
            path.write_text(before)


def run_lockstep_dir(ws: Path, pkg: str, dest: Path) -> Path:
    """``dest`` with a ``launch.sh`` that runs ``rosrun PKG run_lockstep`` on ``ws``'s build
    instead of roslaunch (as a CI would), from ``dest`` (a relative ``out:=`` and the default
    ``runs/`` land there, as from a user's shell)."""
    script = (ws / "launch.sh").read_text()
    assert f'exec roslaunch {pkg} "$@"' in script
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "launch.sh").write_text(
        f"cd {dest}\n"
        + script.replace(f'exec roslaunch {pkg} "$@"', f'exec rosrun {pkg} run_lockstep "$@"')
    )
    return dest


def metrics_without_wall(run_dir: Path) -> dict:
    """A run's ``metrics.json`` without the only fields a wall clock sets, to compare a ROS
    run with the in-process one."""
    data = json.loads((run_dir / "metrics.json").read_text())
    for key in ("wall_time_s", "real_time_factor"):
        data.pop(key)
    return data


def bag_topics(bag: Path) -> dict[str, list[float]]:
    """Every message of a ROS 1 bag, by topic, with rosbag's own reader (Debian's Python)."""
    code = (
        "import sys, json; sys.path.append('/usr/lib/python3/dist-packages'); import rosbag\n"
        "out = {}\n"
        f"for topic, msg, _ in rosbag.Bag({str(bag)!r}).read_messages():\n"
        "    out.setdefault(topic, []).append(msg.data)\n"
        "print(json.dumps(out))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def runs(values: list[float]) -> list[float]:
    """``values`` with consecutive repeats removed."""
    out: list[float] = []
    for v in values:
        if not out or out[-1] != v:
            out.append(v)
    return out


def assert_bag_holds_the_trace(bag: Path, trace_csv: Path, delayed: set[str]) -> dict[str, int]:
    """Every Data topic of ``bag`` carries the values ``trace_csv`` shows, in the same order
    (the trace samples faster than any Leaf publishes, so it sees each message that changes a
    value). A delayed Leaf's messages reach the trace later: its last ones, still in flight
    when the run ends, are in the bag only. Returns how many such extra values each delayed
    Leaf's columns have."""
    topics = bag_topics(bag)
    with trace_csv.open() as f:
        rows = list(csv.reader(f))
    extra: dict[str, int] = {}
    for i, column in enumerate(rows[0][1:], start=1):
        topic = "/" + column.replace(".", "/")
        assert topic in topics, topic
        trace = runs([float(r[i]) for r in rows[1:]])
        messages = runs([trace[0], *topics[topic]])
        if column.rpartition(".")[0] in delayed:
            assert messages[: len(trace)] == trace, column
            extra[column] = len(messages) - len(trace)
        else:
            assert messages == trace, column
    return extra
