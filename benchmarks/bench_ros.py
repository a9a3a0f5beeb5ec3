"""The exported ROS package against ``amsa-phys run`` (issue 26 item 5): speed and memory.

* scenario1 (500 s) in lockstep: the simulator's own run time (``simulated 500 s in X s``, its
  loop, without roscore and process start-up) against the in-process run's loop
  (``metrics.json`` ``wall_time_s``), launch to done (the difference is start-up and exit),
  and the CPU seconds of every process of the launch (on a shared machine the run time
  follows the load; the CPU does much less); with a process per C++ Leaf asked in waves,
  with every C++ Leaf in the container asked in one message a wave and each instant's
  answers awaited (``pipeline:=false``), and pipelined (the default: many instants a
  message, each answer checked against the in-process template), alternated with the
  in-process run, in one sitting;
* the platoon world's launch: the peak of the summed resident memory of every process the
  launch started (sampled from ``/proc`` every 0.2 s), and its run time.

Needs ROS 1 (roslaunch, catkin_make), ``unshare -n`` and root, as tests/ros/test_ros.py does.
Compare ratios only: the machine is shared. Targets (issue 26): lockstep within 3x the
in-process loop; the platoon's launch under 1 GB.
Run: ``python benchmarks/bench_ros.py [--duration 500] [--platoon-duration 20]``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"
PLATOON = ROOT / "worlds" / "platoon.yaml"
#: scenario1's lockstep protocols compared: (label, launch arguments)
PROTOCOLS = (
    ("a process per Leaf, waves", ("cpp_container:=false",)),
    ("container, one message a wave", ("pipeline:=false",)),
    ("container, pipelined (default)", ()),
)
#: CPU seconds of the last :func:`launch`'s processes
LAST_CPU_S = 0.0


def _env(token: str, ws: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROS") and k != "PYTHONPATH"}
    env.update(AMSA_ROS_BENCH=token, ROS_HOME=str(ws / "roshome"), PWD=str(ws))
    env["AMSA_PHYS_PYTHON"] = sys.executable
    return env


def _ours(token: str) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            with contextlib.suppress(OSError):
                env = (entry / "environ").read_bytes().split(b"\0")
                if f"AMSA_ROS_BENCH={token}".encode() in env:
                    found.append(int(entry.name))
    return found


def _cpu_s(pids: list[int], seen: dict[int, float]) -> None:
    """Note each process's CPU seconds so far (user + system) into ``seen``."""
    tck = os.sysconf("SC_CLK_TCK")
    for pid in pids:
        with contextlib.suppress(OSError, IndexError, ValueError):
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
            seen[pid] = (int(fields[11]) + int(fields[12])) / tck


def _rss_kib(pids: list[int]) -> int:
    total = 0
    for pid in pids:
        with contextlib.suppress(OSError):
            for line in Path(f"/proc/{pid}/status").read_text().splitlines():
                if line.startswith("VmRSS:"):
                    total += int(line.split()[1])
    return total


def build(scenario: Path, ws: Path, *extra: str) -> str:
    """Export into ``ws/src`` and build; the package's name."""
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["export", "ros", str(scenario), "-o", str(ws / "src" / "pkg"), *extra]) == 0
    pkg = re.search(r"<name>(\w+)</name>", (ws / "src" / "pkg" / "package.xml").read_text())
    assert pkg is not None
    done = subprocess.run(
        ["catkin_make", "-C", str(ws), "-DPYTHON_EXECUTABLE=/usr/bin/python3"],
        capture_output=True,
        text=True,
        env={**{k: v for k, v in os.environ.items() if k != "PYTHONPATH"}, "PWD": str(ws)},
    )
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    (ws / "launch.sh").write_text(
        "set -e\nip link set lo up\n"
        f"export ROS_LOG_DIR={ws}/roshome/log ROS_MASTER_URI=http://localhost:11311\n"
        "export ROS_HOSTNAME=localhost ROS_DISTRO=${ROS_DISTRO:-debian}\n"
        f"source {ws}/devel/setup.bash\n"
        f'exec roslaunch {pkg.group(1)} "$@"\n'
    )
    return pkg.group(1)


def launch(ws: Path, launch_file: str, *args: str) -> tuple[float, float, int, str]:
    """Launch to done: wall seconds, the simulator's run seconds, peak summed RSS (KiB).

    ``LAST_CPU_S`` is then the CPU seconds every process of the launch used (sampled: a
    process's last 0.2 s may be missed).
    """
    global LAST_CPU_S
    token = uuid.uuid4().hex
    peak = [0]
    cpu: dict[int, float] = {}
    stop = threading.Event()

    def sample() -> None:
        while not stop.is_set():
            pids = _ours(token)
            peak[0] = max(peak[0], _rss_kib(pids))
            _cpu_s(pids, cpu)
            stop.wait(0.2)

    sampler = threading.Thread(target=sample, daemon=True)
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        ["unshare", "-n", "bash", str(ws / "launch.sh"), launch_file, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=_env(token, ws),
        start_new_session=True,
    )
    sampler.start()
    try:
        text, _ = proc.communicate(timeout=1800)
    finally:
        stop.set()
        sampler.join()
        for pid in _ours(token):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
    wall = time.perf_counter() - t0
    LAST_CPU_S = sum(cpu.values())
    m = re.search(r"simulated [\d.]+ s in ([\d.]+) s", text)
    assert m is not None, text[-3000:]
    return wall, float(m.group(1)), peak[0], text


#: The floor of lockstep: a rover driven by two C++ Leaves of the container (a constant power
#: and an actuator chained on it) at scenario1's 4 Hz, so one wait an instant as scenario1
#: has at best, and next to nothing else: what a lockstep instant that waits for its answers
#: (``pipeline:=false``) costs on this machine
#: beyond the in-process loop (a request, the container's steps and the answer, through
#: rospy and roscpp over loopback TCP)
FLOOR_WORLD = """\
name: rosFloor
physics: {rate: 100, ground: {friction: 0.8, rolling_resistance: 0.0017}, obstacles: []}
components:
  Cart:
    template: controlledRobot
    freq: 4
    inputs: {powerL: Act.normalizedPowerL, powerR: Act.normalizedPowerR}
  Act:
    template: NormalizePower
    freq: 4
    inputs: {powerL: Drive.LeftPower, powerR: Drive.RightPower}
  Drive:
    template: ConstantPower
    freq: 4
    params: {left: 9.0, right: 7.0}
"""


def floor(root: Path, duration: str, repeat: int) -> None:
    """Lockstep's floor on this machine (:data:`FLOOR_WORLD`), against its in-process loop."""
    (root / "floor_world.yaml").write_text(FLOOR_WORLD)
    scenario = root / "floor.yaml"
    scenario.write_text(f"name: floor\nworld: floor_world.yaml\nduration: {duration}\nseed: 1\n")
    ws = root / "ws_floor"
    build(scenario, ws)
    for _ in range(repeat):
        ref = root / "floor_ref"
        with contextlib.redirect_stdout(io.StringIO()):
            argv = ["run", str(scenario), "--headless", "-q", "--no-plot", "--out", str(ref)]
            assert main([*argv, "--force"]) == 0
        loop = json.loads((ref / "metrics.json").read_text())["wall_time_s"]
        _, run, _, _ = launch(
            # the exact protocol: pipelined (the default here, every Leaf in the container)
            # waits for no instant, so it would measure no round trip
            ws,
            "floor.launch",
            f"out:={ws / 'out'}",
            "plots:=false",
            "force:=true",
            "pipeline:=false",
        )
        instants = 4 * float(duration)
        print(
            f"floor (one wait an instant, 4 Hz) {duration} s: in-process loop {loop:.3f} s, "
            f"lockstep {run:.3f} s: {(run - loop) / instants * 1e6:.0f} us an instant beyond "
            f"the loop; scenario1's floor {instants:.0f} instants x that"
        )


def main_bench() -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", default="500", help="scenario1's simulated seconds")
    parser.add_argument("--platoon-duration", default="20", help="the platoon's seconds")
    parser.add_argument("--repeat", type=int, default=2, help="launches of each protocol")
    args = parser.parse_args()
    missing = [t for t in ("roslaunch", "catkin_make", "unshare") if shutil.which(t) is None]
    if missing or os.geteuid() != 0:
        sys.exit(f"needs ROS 1, unshare and root (missing: {missing or 'root'})")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        ref = root / "ref"
        with contextlib.redirect_stdout(io.StringIO()):
            argv = ["run", str(SCENARIO1), "--headless", "-q", "--no-plot", "--out", str(ref)]
            assert main([*argv, "--duration", args.duration]) == 0
        loop = json.loads((ref / "metrics.json").read_text())["wall_time_s"]
        ws = root / "ws1"
        build(SCENARIO1, ws)
        cpu0 = time.process_time()
        with contextlib.redirect_stdout(io.StringIO()):
            assert main([*argv, "--duration", args.duration, "--out", str(root / "ref2")]) == 0
        ref_cpu = time.process_time() - cpu0
        print(f"scenario1 {args.duration} s, in-process loop        {loop:.3f} s")
        print(f"scenario1 in-process: CPU of the whole run         {ref_cpu:.2f} s")
        # the protocols, alternated with the in-process loop, --repeat times each (the
        # machine is shared): each ratio is against the loop measured just before it
        for _ in range(args.repeat):
            for label, extra in PROTOCOLS:
                with contextlib.redirect_stdout(io.StringIO()):
                    assert main([*argv, "--duration", args.duration, "--force"]) == 0
                loop = json.loads((ref / "metrics.json").read_text())["wall_time_s"]
                wall, run, rss, _ = launch(
                    ws,
                    "scenario1.launch",
                    f"out:={ws / 'out'}",
                    "plots:=false",
                    f"duration:={args.duration}",
                    "force:=true",
                    *extra,
                )
                same = (ws / "out" / "trace.csv").read_bytes() == (ref / "trace.csv").read_bytes()
                print(
                    f"scenario1 lockstep, {label:34}: run {run:.3f} s ({run / loop:.1f}x the "
                    f"loop's {loop:.3f} s), "
                    f"launch to done {wall:.1f} s (start-up and exit {wall - run:.1f} s), "
                    f"CPU of the launch {LAST_CPU_S:.1f} s, peak memory {rss / 1024:.0f} MiB, "
                    f"trace byte-identical {same}"
                )
        floor(root, args.duration, args.repeat)
        ws = root / "ws2"
        build(PLATOON, ws, "--duration", args.platoon_duration)
        wall, run, rss, _ = launch(ws, "platoon.launch", f"out:={ws / 'out'}", "plots:=false")
        print(f"platoon {args.platoon_duration} s lockstep: simulator's run         {run:.3f} s")
        print(f"platoon lockstep: launch to done                   {wall:.1f} s")
        print(f"platoon lockstep: peak memory of the launch        {rss / 1024:.0f} MiB")


if __name__ == "__main__":
    main_bench()
