"""Running amsa-phys and a user's rclpy node together, in a private network, for a test.

The ROS 2 wheels live in ``.venv-ros2`` (never the test suite's own venv: ROS 1's message
packages share their names), so everything ROS 2 runs as that venv's python, in ``unshare -n``
with only loopback up and a ROS_DOMAIN_ID of the test's own. Every process carries a token in
its environment: a test proves none is left behind.
"""

from __future__ import annotations

import contextlib
import os
import random
import re
import shlex
import shutil
import subprocess
import sys
import uuid
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PY = ROOT / ".venv-ros2" / "bin" / "python"
NODE = Path(__file__).resolve().parent / "follower_node.py"
WALL_LIMIT_S = 600  # a hung run is killed (and fails the test), never waited for forever


#: What Python prints when a stop signal lands while rclpy frees one of its executor's Tasks:
#: the KeyboardInterrupt rclpy's signal handler raises cannot leave ``Task.__del__`` (rclpy's
#: own code), so Python reports it as ignored and the node ends as it should. Not ours to
#: print, and not a fault: the tests that look for tracebacks look past it.
_RCLPY_TASK_DEL = re.compile(
    r"Exception ignored in: <function Task\.__del__ at 0x[0-9a-f]+>\n"
    r"Traceback \(most recent call last\):\n(?:  .*\n)*?[A-Za-z_][\w.]*(?::[^\n]*)?(?:\n|$)"
)


def without_rclpy_task_noise(text: str) -> str:
    """``text`` (a process's stderr) without :data:`_RCLPY_TASK_DEL`'s reports."""
    return _RCLPY_TASK_DEL.sub("", text)


#: the environment of an export test's commands: headless, no ROS on PATH
EXPORT_ENV = {"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"}


def amsa(*args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
    """amsa-phys of the test suite's own venv (no ROS), in :data:`EXPORT_ENV`."""
    return subprocess.run(
        [sys.executable, "-m", "amsa_phys", *args],
        capture_output=True,
        text=True,
        env=EXPORT_ENV,
        check=check,
    )


def ros2_missing() -> str | None:
    """Why the ROS 2 tests cannot run here, or None."""
    if not PY.exists():
        return f"{PY} is missing (.ci/run makes it: pip install -e '.[ros2]' in .venv-ros2)"
    probe = subprocess.run([PY, "-c", "import rclpy, amsa_phys"], capture_output=True)
    if probe.returncode != 0:
        return f"rclpy or amsa_phys is not importable in {PY}"
    for tool in ("unshare", "ip"):
        if shutil.which(tool) is None:
            return f"{tool} is not installed"
    if os.geteuid() != 0:
        return "unshare -n (a private network for DDS) needs root"
    if subprocess.run(["unshare", "-n", "true"], capture_output=True).returncode != 0:
        return "unshare -n is not permitted here"
    return None


@dataclass
class Outcome:
    """What the amsa-phys command did, and what was left running after it."""

    rc: int
    stdout: str
    stderr: str
    node_log: str
    leftovers: list[int]


def leftovers(token: str) -> list[int]:
    """Processes whose environment holds ``token``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            env = (entry / "environ").read_bytes()
        except OSError:
            continue
        if f"AMSA_ROS2_TEST={token}".encode() in env.split(b"\0"):
            found.append(int(entry.name))
    return found


def in_private_network(
    script: Path, extra_env: dict[str, str], log: Path | None = None, cwd: Path | None = None
) -> tuple[int, list[int]]:
    """Run the bash ``script`` in ``unshare -n`` with ``extra_env``, a ROS_DOMAIN_ID and a
    token of its own; its output to ``log`` (a file, not a pipe: a straggler holding it cannot
    hang us) or inherited. Returns its exit code (-1: killed at ``WALL_LIMIT_S``) and the
    processes it left behind, which are killed (a straggler fails the test, and is not left
    running after it)."""
    token = uuid.uuid4().hex
    env = {
        **os.environ,
        **extra_env,
        "AMSA_ROS2_TEST": token,
        "ROS_DOMAIN_ID": str(random.randint(1, 100)),
    }
    env.pop("VIRTUAL_ENV", None)
    argv = ["unshare", "-n", "bash", str(script)]
    try:
        with log.open("w") if log is not None else contextlib.nullcontext() as out:
            err = subprocess.STDOUT if out is not None else None
            proc = subprocess.run(
                argv, env=env, cwd=cwd, stdout=out, stderr=err, timeout=WALL_LIMIT_S
            )
        rc = proc.returncode
    except subprocess.TimeoutExpired:
        rc = -1
    left = leftovers(token)
    for pid in left:
        with contextlib.suppress(OSError):
            os.kill(pid, 9)
    return rc, left


def run_with_nodes(
    tmp: Path, amsa_args: list[str], nodes: list[list[str]], domains: list[int] | None = None
) -> Outcome:
    """Start each node (``nodes``: argument lists of ``follower_node.py``; ``domains``: each
    one's ROS_DOMAIN_ID after the test's own, default 0), then ``amsa-phys AMSA_ARGS`` with
    the ROS 2 venv's python; stop the nodes; report."""
    out, err, log = tmp / "amsa.out", tmp / "amsa.err", tmp / "node.log"
    lines = ["set -u", "ip link set lo up", "pids=()"]
    for i, args in enumerate(nodes):
        shift = domains[i] if domains else 0
        cmd = f"ROS_DOMAIN_ID=$((ROS_DOMAIN_ID + {shift})) " + " ".join(
            shlex.quote(str(a)) for a in [PY, NODE, *args]
        )
        lines.append(f"{cmd} >>{shlex.quote(str(log))} 2>&1 & pids+=($!)")
    amsa = " ".join(shlex.quote(str(a)) for a in [PY, "-m", "amsa_phys", *amsa_args])
    lines.append(f"{amsa} >{shlex.quote(str(out))} 2>{shlex.quote(str(err))}; rc=$?")
    # each node stopped by SIGTERM, then (a failure deadline, a node that does not stop) SIGKILL
    stop = (
        'kill "$p" 2>/dev/null; for _ in $(seq 600); do kill -0 "$p" 2>/dev/null || break;'
        ' sleep 0.1; done; kill -9 "$p" 2>/dev/null; wait "$p" 2>/dev/null'
    )
    lines.append(f'for p in "${{pids[@]}}"; do {stop}; done')
    lines.append("exit $rc")
    script = tmp / "run.sh"
    script.write_text("\n".join(lines) + "\n")
    extra = {"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PYTHONUNBUFFERED": "1"}
    rc, left = in_private_network(script, extra, cwd=tmp)
    return Outcome(
        rc,
        out.read_text() if out.exists() else "",
        err.read_text() if err.exists() else "",
        log.read_text() if log.exists() else "",
        left,
    )
