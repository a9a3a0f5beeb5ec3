"""The cost of a ROS 2 node in the loop: ``run --ros2`` against the same run in process.

scenario1 with the test suite's hand-written rclpy follower node (``tests/ros2/follower_node.py``)
as ``--ros2 MyFollowerController`` (4 Hz: 2001 round trips over 500 s), against the in-process
run, alternated round by round in one sitting; and ``ros2 lockstep`` of the exported package
(six nodes) once per round. Each time is the run's own loop (``metrics.json``
``wall_time_s``: no process start-up, no node start-up), and the load average is recorded
before each round: compare ratios only, the machine is shared.

Needs ``.venv-ros2`` (``pip install -e '.[ros2]'``), ``unshare -n`` and root, as
``tests/ros2`` do; through ``perf.py`` a row says so where they are missing.
Run: ``python benchmarks/bench_ros2.py [--rounds 3]`` or through
``python -m benchmarks.perf --only ros2`` (which writes the figures to the results file).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

import results  # noqa: E402

PY = ROOT / ".venv-ros2" / "bin" / "python"
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"
NODE = ROOT / "tests" / "ros2" / "follower_node.py"
ENV = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "ROS_DOMAIN_ID": "77"}


def _loop_s(out: Path) -> float:
    return float(json.loads((out / "metrics.json").read_text())["wall_time_s"])


def in_process(tmp: Path) -> float:
    out = tmp / f"inproc-{time.monotonic_ns()}"
    subprocess.run(
        [PY, "-m", "amsa_phys", "run", SCENARIO, "--headless", "--no-plot", "-q", "--out", out],
        env=ENV,
        check=True,
        capture_output=True,
    )
    return _loop_s(out)


def _netns(script: str) -> None:
    subprocess.run(
        ["unshare", "-n", "bash", "-c", f"ip link set lo up\n{script}"],
        env=ENV,
        check=True,
        capture_output=True,
    )


def with_node(tmp: Path) -> float:
    out = tmp / f"ros2-{time.monotonic_ns()}"
    _netns(
        f"{PY} {NODE} & N=$!\n"
        f"{PY} -m amsa_phys run {SCENARIO} --headless --no-plot -q --out {out} "
        f"--ros2 MyFollowerController; rc=$?\nkill $N; wait $N\nexit $rc"
    )
    return _loop_s(out)


def lockstep(tmp: Path, pkg: Path) -> float:
    out = tmp / f"lock-{time.monotonic_ns()}"
    _netns(f"{PY} -m amsa_phys ros2 lockstep {pkg} --out {out} --no-plot -q")
    return _loop_s(out)


def missing() -> str:
    """Why this machine cannot run ROS 2 nodes here ("" when it can)."""
    if not PY.exists():
        return f"not measured: {PY.relative_to(ROOT)} is missing (pip install -e '.[ros2]' there)"
    if shutil.which("unshare") is None or os.geteuid() != 0:
        return "not measured: needs unshare and root (a private network)"
    return ""


def _med(xs: list[float]) -> str:
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def perf(reps: int, report: results.Report = results.print_report) -> None:
    """A node in the loop and the exported package over the in-process run, round by round."""
    names = (
        "ROS 2 node in the loop (run --ros2) / in-process loop",
        "ros2 lockstep of the exported package / in-process loop",
    )
    why = missing()
    if why:
        for name in names:
            report(name, why, "", None, skipped=True)
        return
    node, lock, base = [], [], []
    with tempfile.TemporaryDirectory(prefix="bench-ros2-") as tmp_s:
        tmp = Path(tmp_s)
        pkg = tmp / "pkg"
        subprocess.run(
            [PY, "-m", "amsa_phys", "export", "ros2", SCENARIO, "-o", pkg],
            env=ENV,
            check=True,
            capture_output=True,
        )
        for _ in range(reps):
            a = in_process(tmp)
            base.append(a)
            node.append(with_node(tmp) / a)
            lock.append(lockstep(tmp, pkg) / a)
    loop = f"in-process loop {statistics.median(base):.3f} s"
    report(names[0], f"{_med(node)}; {loop}", "", None)
    report(names[1], f"{_med(lock)}; {loop}", "", None)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    why = missing()
    if why:
        sys.exit(why)
    perf(args.rounds)


if __name__ == "__main__":
    main()
