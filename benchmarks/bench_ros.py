"""The exported ROS 1 package against ``amsa-phys run``: speed, build and memory.

* scenario1 (500 s) in lockstep: the simulator's own run time (``simulated 500 s in X s``, its
  loop, without roscore and process start-up) against the in-process run's loop
  (``metrics.json`` ``wall_time_s``) measured just before it, launch to done (the difference
  is start-up and exit), and the CPU seconds of every process of the launch against the
  in-process run's (on a shared machine the run time follows the load; the CPU does much
  less); with a process per C++ Leaf asked in waves, with every C++ Leaf in the container
  asked in one message a wave and each instant's answers awaited (``pipeline:=false``), and
  pipelined (the default: many instants a message, each answer checked against the
  in-process template), alternated with the in-process run, in one sitting;
* lockstep's floor: the smallest world with scenario1's structure, one wait an instant;
* the build: ``catkin_make`` of the exported scenario1 package, its CPU (compilers included)
  against one roscpp compile unit compiled alone (``g++`` of a file including roscpp's and
  nodelet's headers: what every C++ Leaf's unit costs before its own code);
* the platoon world's launch: the peak of the summed resident memory of every process the
  launch started (sampled from ``/proc`` every 0.2 s), and its run time.

Needs ROS 1 (roslaunch, catkin_make), ``unshare -n`` and root, as tests/ros/test_ros.py does;
through ``perf.py`` a row says so where they are missing. Compare ratios only: the machine is
shared. Targets: pipelined lockstep within 3x the in-process loop; the platoon's launch under
1 GiB.
Run: ``python benchmarks/bench_ros.py [--duration 500] [--platoon-duration 20]`` or through
``python -m benchmarks.perf --only ros``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import re
import resource
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

import results  # noqa: E402

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
#: (wall s, CPU s of catkin_make and the compilers) of the last :func:`build`
LAST_BUILD = (0.0, 0.0)
#: One roscpp compile unit: what each C++ Leaf's unit costs before its own code
UNIT_CPP = """\
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_msgs/Float64.h>
int main() { return 0; }
"""


#: How the package's CMake compiles a unit (its flags; no build type, so no optimisation)
COMPILE = ["g++", "-std=c++14", "-ffp-contract=off"]


def _children_cpu() -> float:
    """CPU seconds (user + system) of this process's finished children and theirs."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def missing() -> str:
    """Why this machine cannot run the exported package ("" when it can)."""
    absent = [t for t in ("roslaunch", "catkin_make", "unshare", "g++") if not shutil.which(t)]
    if absent:
        return f"not measured: {', '.join(absent)} not installed (ROS 1 Noetic)"
    if os.geteuid() != 0:
        return "not measured: needs root for unshare -n (a private network)"
    return ""


def unit_cpu(tmp: Path) -> float:
    """CPU seconds of compiling :data:`UNIT_CPP` alone, as the package's CMake compiles."""
    src = tmp / "unit.cpp"
    src.write_text(UNIT_CPP)
    before = _children_cpu()
    subprocess.run(
        [*COMPILE, "-c", str(src), "-o", str(tmp / "unit.o")],
        check=True,
        capture_output=True,
    )
    return _children_cpu() - before


def _med(xs: list[float]) -> str:
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def build_cost(scenario: Path, root: Path, reps: int, report: results.Report, name: str) -> str:
    """Export and build ``scenario`` in ``root/ws_build``, reporting the build's CPU against a
    roscpp compile unit's and its wall time; the workspace's package name."""
    pkg = build(scenario, root / "ws_build")
    wall, cpu = LAST_BUILD
    units = [unit_cpu(root) for _ in range(max(1, reps))]
    ratio = [cpu / u for u in units]
    report(
        f"catkin_make of the exported {name}: CPU / one roscpp compile unit",
        f"{_med(ratio)}; build {cpu:.1f} s CPU, {wall:.1f} s wall; "
        f"unit {statistics.median(units):.2f} s CPU",
        "",
        None,
    )
    return pkg


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
    global LAST_BUILD
    cpu0, t0 = _children_cpu(), time.perf_counter()
    done = subprocess.run(
        ["catkin_make", "-C", str(ws), "-DPYTHON_EXECUTABLE=/usr/bin/python3"],
        capture_output=True,
        text=True,
        env={**{k: v for k, v in os.environ.items() if k != "PYTHONPATH"}, "PWD": str(ws)},
    )
    LAST_BUILD = (time.perf_counter() - t0, _children_cpu() - cpu0)
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


def floor(root: Path, duration: str, repeat: int, report: results.Report) -> None:
    """Lockstep's floor on this machine (:data:`FLOOR_WORLD`), against its in-process loop."""
    (root / "floor_world.yaml").write_text(FLOOR_WORLD)
    scenario = root / "floor.yaml"
    scenario.write_text(f"name: floor\nworld: floor_world.yaml\nduration: {duration}\nseed: 1\n")
    ws = root / "ws_floor"
    build(scenario, ws)
    beyond = []
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
        beyond.append((run - loop) / (4 * float(duration)) * 1e6)
    report(
        "ROS 1 lockstep floor (one wait an instant): µs an instant beyond the loop",
        _med(beyond),
        "",
        None,
    )


def perf(
    reps: int,
    report: results.Report = results.print_report,
    duration: str = "500",
    platoon_duration: str = "20",
) -> None:
    """Every figure of this file, each against its baseline of the same sitting."""
    why = missing()
    if why:
        for name in ("lockstep pipelined / in-process loop", "catkin_make", "platoon memory"):
            report(f"ROS 1 {name}", why, "", None, skipped=True)
        return
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        build_cost(SCENARIO1, root, reps, report, "scenario1 package")
        _lockstep(root, root / "ws_build", duration, reps, report)
        floor(root, duration, reps, report)
        ws = root / "ws2"
        build(PLATOON, ws, "--duration", platoon_duration)
        walls, rss_mib = [], []
        for rep in range(reps):  # a run directory each: out:= refuses one that is not empty
            out = ws / f"out{rep}"
            wall, _run, rss, _ = launch(ws, "platoon.launch", f"out:={out}", "plots:=false")
            walls.append(wall)
            rss_mib.append(rss / 1024)
        ok = statistics.median(rss_mib) < 1024
        report(
            f"ROS 1 platoon ({platoon_duration} s) launch: peak memory of its processes, MiB",
            f"{_med(rss_mib)}; launch to done {statistics.median(walls):.1f} s",
            "< 1024",
            ok,
        )


def _lockstep(root: Path, ws: Path, duration: str, reps: int, report: results.Report) -> None:
    """scenario1's three lockstep protocols, each rep alternated with the in-process run."""
    ref = root / "ref"
    argv = ["run", str(SCENARIO1), "--headless", "-q", "--no-plot", "--out", str(ref)]
    argv += ["--duration", duration, "--force"]
    ratios: dict[str, list[float]] = {label: [] for label, _ in PROTOCOLS}
    walls: dict[str, list[float]] = {label: [] for label, _ in PROTOCOLS}
    cpus: dict[str, list[float]] = {label: [] for label, _ in PROTOCOLS}
    same = True
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(argv) == 0  # warm: the first run imports the run command's modules
    for _ in range(reps):
        for label, extra in PROTOCOLS:
            cpu0 = time.process_time()
            with contextlib.redirect_stdout(io.StringIO()):
                assert main(argv) == 0
            ref_cpu = time.process_time() - cpu0
            loop = json.loads((ref / "metrics.json").read_text())["wall_time_s"]
            args = (f"out:={ws / 'out'}", "plots:=false", f"duration:={duration}", "force:=true")
            wall, run, _rss, _ = launch(ws, "scenario1.launch", *args, *extra)
            same &= (ws / "out" / "trace.csv").read_bytes() == (ref / "trace.csv").read_bytes()
            ratios[label].append(run / loop)
            walls[label].append(wall)
            cpus[label].append(LAST_CPU_S / ref_cpu)
    for label, _ in PROTOCOLS:
        pipelined = label.endswith("(default)")
        ok = statistics.median(ratios[label]) <= 3 and same if pipelined else None
        report(
            f"ROS 1 lockstep scenario1 {duration} s, {label} / in-process loop",
            f"{_med(ratios[label])}; launch to done {statistics.median(walls[label]):.1f} s; "
            f"CPU of the launch / in-process {statistics.median(cpus[label]):.3g}; "
            f"traces byte-identical {same}",
            "<= 3" if pipelined else "",
            ok,
        )


def main_bench() -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", default="500", help="scenario1's simulated seconds")
    parser.add_argument("--platoon-duration", default="20", help="the platoon's seconds")
    parser.add_argument("--repeat", type=int, default=2, help="launches of each protocol")
    args = parser.parse_args()
    why = missing()
    if why:
        sys.exit(why)
    perf(args.repeat, results.print_report, args.duration, args.platoon_duration)


if __name__ == "__main__":
    main_bench()
