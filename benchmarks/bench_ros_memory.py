"""The platoon's launch in memory (under 1 GB), by kind of process.

Exports ``worlds/platoon.yaml`` (10 cars: each a GPS, a GPS on the car ahead, a compass, a
distance monitor, a controller and a drive), builds it with catkin (timed) and launches it
in lockstep three times in one sitting: with every C++ Leaf in one process (the container,
the default), with each C++ Leaf in a process of its own (``cpp_container:=false``, as
before the container) and with ``cpp:=false`` (every Leaf a Python node). While each runs,
the resident memory of every process the launch started is sampled from ``/proc`` every
0.2 s, summed: RSS (the issue's measure) and PSS (which shares a library's pages out among
the processes that map them instead of counting them in each). At the RSS peak the sum is
split into: the simulator node (Python: pymunk, numpy and the engine), the other Python
nodes (scenario, boundary, Leaves), the C++ Leaves (the container, or a nodelet process
each), and ROS itself (roslaunch, rosmaster, rosout). It also says whether the three traces
are byte-identical.

Needs ROS 1 (roslaunch, catkin_make), ``unshare -n`` and root, as tests/ros/test_ros.py.
Run: ``python benchmarks/bench_ros_memory.py [--duration 20]``.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

from bench_ros import PLATOON, _env, _ours, build

#: the C++ Leaves in one process (the default), one process each, and the Python twins
CONFIGS = ("cpp_container:=true", "cpp_container:=false", "cpp:=false")
KINDS = ("simulator", "python nodes", "C++ nodes", "ROS (roslaunch, master, rosout)")


def _kind(pid: int) -> str | None:
    """Which of :data:`KINDS` process ``pid`` is (None: gone, or the launch's shell)."""
    try:
        argv = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except OSError:
        return None
    text = b" ".join(argv).decode(errors="replace")
    if "amsa_simulator" in text:
        return KINDS[0]
    # the C++ Leaves: the container (every one in one process) or a nodelet standalone each
    if any(a.endswith((b"_cpp", b"/amsa_leaves", b"/nodelet")) for a in argv[:1]):
        return KINDS[2]
    if "roslaunch" in text or "rosmaster" in text or "rosout" in text:
        return KINDS[3]
    if "python" in text:
        return KINDS[1]
    return None


def _mem(pid: int) -> tuple[int, int]:
    """Resident and proportional set size (KiB): RSS counts a shared library's pages in
    every process that maps it, PSS shares them out (the memory the launch really uses)."""
    rss = pss = 0
    with contextlib.suppress(OSError):
        for line in Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines():
            if line.startswith("Rss:"):
                rss = int(line.split()[1])
            elif line.startswith("Pss:"):
                pss = int(line.split()[1])
    return rss, pss


Split = dict[str, tuple[int, int, int]]


def measure(ws: Path, *args: str) -> tuple[int, int, Split, float]:
    """Launch to done: peak summed RSS and PSS (KiB), the split at the RSS peak {kind: (RSS,
    PSS, processes)}, wall seconds."""
    token = uuid.uuid4().hex
    best: list = [0, 0, {}]
    stop = threading.Event()

    def sample() -> None:
        while not stop.is_set():
            split: Split = {}
            for pid in _ours(token):
                kind = _kind(pid)
                if kind is None:
                    continue
                rss, pss = _mem(pid)
                r, q, n = split.get(kind, (0, 0, 0))
                split[kind] = (r + rss, q + pss, n + 1)
            total = sum(r for r, _, _ in split.values())
            best[1] = max(best[1], sum(q for _, q, _ in split.values()))
            if total > best[0]:
                best[0], best[2] = total, split
            stop.wait(0.2)

    t0 = time.perf_counter()
    proc = subprocess.Popen(
        ["unshare", "-n", "bash", str(ws / "launch.sh"), "platoon.launch", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=_env(token, ws),
        start_new_session=True,
    )
    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    try:
        text, _ = proc.communicate(timeout=3600)
    finally:
        stop.set()
        sampler.join()
        for pid in _ours(token):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
    assert "completed" in text, text[-3000:]
    return best[0], best[1], best[2], time.perf_counter() - t0


def main_bench() -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", default="20", help="the platoon's simulated seconds")
    parser.add_argument(
        "--workspace", type=Path, help="a workspace this script built before (skips the build)"
    )
    args = parser.parse_args()
    missing = [t for t in ("roslaunch", "catkin_make", "unshare") if shutil.which(t) is None]
    if missing or os.geteuid() != 0:
        sys.exit(f"needs ROS 1, unshare and root (missing: {missing or 'root'})")
    with tempfile.TemporaryDirectory() as tmp:
        ws = args.workspace or Path(tmp) / "ws"
        if args.workspace is None:
            t0 = time.perf_counter()
            build(PLATOON, ws, "--duration", args.duration)
            print(f"platoon: export and catkin_make             {time.perf_counter() - t0:.0f} s")
        traces = []
        for how in CONFIGS:
            out = ws / f"out_{how.replace(':=', '_')}"
            rss, pss, split, wall = measure(ws, f"out:={out}", "plots:=false", "force:=true", how)
            traces.append((out / "trace.csv").read_bytes())
            print(f"platoon {args.duration} s lockstep, {how}: peak memory (summed)")
            print(f"  RSS {rss / 1024:6.0f} MiB, PSS {pss / 1024:6.0f} MiB; at the RSS peak:")
            for kind in KINDS:
                r, q, n = split.get(kind, (0, 0, 0))
                print(f"  {kind:34s} RSS {r / 1024:5.0f} MiB, PSS {q / 1024:5.0f} MiB, {n:2d} proc")
            print(f"  launch to done                     {wall:6.1f} s")
        same = all(t == traces[0] for t in traces)
        print(f"platoon: traces byte-identical ({', '.join(CONFIGS)})  {same}")


if __name__ == "__main__":
    main_bench()
