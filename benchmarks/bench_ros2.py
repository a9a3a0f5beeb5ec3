"""The cost of a ROS 2 node in the loop: ``run --ros2`` against the same run in process.

scenario1 with the test suite's hand-written rclpy follower node (``tests/ros2/follower_node.py``)
as ``--ros2 MyFollowerController`` (4 Hz: 2001 round trips over 500 s), against the in-process
run, alternated round by round in one sitting; and ``ros2 lockstep`` of the exported package
(six nodes) once per round. Each time is the run's own loop (``metrics.json``
``wall_time_s``: no process start-up, no node start-up), and the load average is recorded
before each round: compare ratios only, the machine is shared.

Needs ``.venv-ros2`` (``pip install -e '.[ros2]'``), ``unshare -n`` and root, as
``tests/ros2`` do. Run: ``python benchmarks/bench_ros2.py [--rounds 3] [--out FILE]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "bench_ros2.json"))
    args = ap.parse_args()
    if not PY.exists():
        sys.exit(f"{PY} is missing: python3 -m venv .venv-ros2; pip install -e '.[ros2]'")
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-ros2-") as tmp_s:
        tmp = Path(tmp_s)
        pkg = tmp / "pkg"
        subprocess.run(
            [PY, "-m", "amsa_phys", "export", "ros2", SCENARIO, "-o", pkg],
            env=ENV,
            check=True,
            capture_output=True,
        )
        for i in range(args.rounds):
            load = os.getloadavg()[0]
            a = in_process(tmp)
            b = with_node(tmp)
            c = lockstep(tmp, pkg)
            rows.append(
                {
                    "round": i,
                    "load1": load,
                    "in_process_s": a,
                    "ros2_node_s": b,
                    "ros2_lockstep_s": c,
                }
            )
            print(
                f"round {i}: load {load:.1f}; in process {a:.2f} s, one ROS 2 node "
                f"{b:.2f} s ({b / a:.1f}x), exported package {c:.2f} s ({c / a:.1f}x)",
                flush=True,
            )
    med = {k: statistics.median(r[k] for r in rows) for k in rows[0] if k.endswith("_s")}
    result = {
        "scenario": "scenario1 (500 s)",
        "cpus": os.cpu_count(),
        "rounds": rows,
        "median_s": med,
        "ratio_node": med["ros2_node_s"] / med["in_process_s"],
        "ratio_lockstep": med["ros2_lockstep_s"] / med["in_process_s"],
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n")
    print(
        f"median: one node {result['ratio_node']:.1f}x, exported package "
        f"{result['ratio_lockstep']:.1f}x the in-process loop; written to {args.out}"
    )


if __name__ == "__main__":
    main()
