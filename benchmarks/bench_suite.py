"""The test suite's duration and memory, and the build of the exported MDE package.

What a contributor waits for, measured the way the README states it: the quick tier (``pytest
-n auto -m "not (ros or ros2 or build or docs or slow)"``) and the full suite (``pytest -n 2
--dist loadgroup``, what CI runs), each in a child process: its wall time, the CPU of pytest
and everything it started (compilers, ROS launches), the peak resident memory of the largest of
those processes, and the counts from the run's JUnit XML (a run with failures still gives its
time; the row says how many failed). Then ``catkin_make`` of the exported MDE package
(scenario1), against one roscpp compile unit compiled alone in the same sitting
(``bench_ros.build_cost``).

One repetition (the full suite takes long); the machine's load before and after is recorded
with each row. Measure on a quiet machine, and compare the CPU figures, which the load moves
less than the wall time.

Run: ``python -m benchmarks.perf --save --only suite`` (both tiers and the build), or some
parts: ``--suite quick build``, or a subset of the tests to check the measurement itself:
``--suite quick --suite-tests tests/docs/test_user_text.py`` (rows then name the subset).
A tier already run (CI's, or the lead's after a merge) need not run again:
``--suite-junit full=report.xml`` reads its time and counts from ``pytest --junitxml``'s
report (its CPU and memory rows then say they were not measured).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import results

ROOT = Path(__file__).resolve().parent.parent
#: The tiers as the README names them: the arguments each adds to ``pytest``
TIERS = {
    "quick": ["-n", "auto", "-m", "not (ros or ros2 or build or docs or slow)"],
    "full": ["-n", "2", "--dist", "loadgroup"],
}
#: What the suite target measures: the tiers and the MDE package's build
PARTS = (*TIERS, "build")
#: Runs the measured command and prints its wall seconds, CPU seconds (itself and every
#: descendant it waited for) and peak RSS (KiB, the largest of those processes), as the kernel
#: accounts them; a small launcher, so the benchmark's own pages are never counted.
_LAUNCH = (
    "import os, subprocess, sys, time\n"
    "t0 = time.perf_counter()\n"
    "p = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n"
    "_, status, ru = os.wait4(p.pid, 0)\n"
    "print(time.perf_counter() - t0, ru.ru_utime + ru.ru_stime, ru.ru_maxrss,\n"
    "      os.waitstatus_to_exitcode(status))\n"
)


def measure(argv: list[str]) -> tuple[float, float, float, int]:
    """(wall s, CPU s, peak RSS MiB, exit code) of a command and its descendants."""
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    out = subprocess.run(
        [sys.executable, "-c", _LAUNCH, *argv],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
        env=env,
    )
    wall, cpu, rss, code = out.stdout.split()
    return float(wall), float(cpu), int(rss) / 1024, int(code)


def counts(junit: Path) -> dict[str, int]:
    """tests, failures, errors and skipped of a JUnit XML report (zeros when it is missing)."""
    keys = ("tests", "failures", "errors", "skipped")
    total = dict.fromkeys(keys, 0)
    if not junit.exists():
        return total
    root = ET.parse(junit).getroot()
    suites = [root] if root.tag == "testsuite" else root.findall("testsuite")
    for suite in suites:
        for k in keys:
            total[k] += int(suite.get(k, 0))
    return total


def junit_time(junit: Path) -> tuple[float, str]:
    """(seconds, start) of a JUnit XML report: pytest's own session time summed over its
    suites, and the first suite's timestamp. Raises ``ValueError`` naming the file when it is
    not a JUnit report."""
    try:
        root = ET.parse(junit).getroot()
    except (OSError, ET.ParseError) as exc:
        raise ValueError(f"{junit}: not a JUnit XML report ({exc})") from None
    suites = [root] if root.tag == "testsuite" else root.findall("testsuite")
    if not suites or any(x.get("time") is None for x in suites):
        raise ValueError(f"{junit}: no <testsuite time=...> (not pytest's --junitxml output)")
    try:
        return sum(float(x.get("time", "")) for x in suites), suites[0].get("timestamp", "")
    except ValueError:
        raise ValueError(f"{junit}: a <testsuite> time that is not a number") from None


def _what(name: str, paths: list[str]) -> str:
    what = "the quick tier" if name == "quick" else "the full suite"
    return what + (f" (only {' '.join(paths)})" if paths else "")


def _tally(n: dict[str, int]) -> str:
    return f"{n['tests']} tests, {n['skipped']} skipped, {n['failures'] + n['errors']} failed"


def from_junit(name: str, junit: Path, report: results.Report) -> float:
    """Report a tier from the JUnit XML of a run the user already made (``pytest
    --junitxml=FILE``): its time and counts; the CPU and memory rows say they were not
    measured. The wall seconds."""
    seconds, start = junit_time(junit)
    what = _what(name, [])
    detail = f"{_tally(counts(junit))}; pytest's own time, from {junit.name} of {start}"
    report(f"pytest, {what}: wall, minutes", f"{seconds / 60:.3g}; {detail}", "", None)
    why = f"not measured: read from {junit.name} (a JUnit report has no CPU or memory)"
    report(f"pytest, {what}: CPU of pytest and its children, minutes", why, "", None, skipped=True)
    report(f"pytest, {what}: peak RSS of its largest process, MiB", why, "", None, skipped=True)
    return seconds


def tier(name: str, paths: list[str], tmp: Path, report: results.Report) -> tuple[float, float]:
    """Run one tier (or ``paths`` of it) and report its rows; (wall, CPU) seconds."""
    junit = tmp / f"{name}.xml"
    argv = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *TIERS[name]]
    argv += [f"--junitxml={junit}", *paths]
    wall, cpu, rss, code = measure(argv)
    what = _what(name, paths)
    tally = f"{_tally(counts(junit))}; pytest exit {code}; {os.cpu_count()} cores"
    ok = None if code in (0, 1) else False  # 1: tests failed; anything else: it did not run
    report(f"pytest, {what}: wall, minutes", f"{wall / 60:.3g}; {tally}", "", ok)
    report(f"pytest, {what}: CPU of pytest and its children, minutes", f"{cpu / 60:.3g}", "", ok)
    report(f"pytest, {what}: peak RSS of its largest process, MiB", f"{rss:.0f}", "", ok)
    return wall, cpu


def perf(
    reps: int,
    report: results.Report = results.print_report,
    parts: tuple[str, ...] = PARTS,
    paths: tuple[str, ...] = (),
    junits: dict[str, Path] | None = None,
) -> None:
    """The parts asked for: the tiers (each run here, or read from the JUnit XML given for
    it in ``junits``), then the MDE package's build (``reps`` compile units of baseline)."""
    import bench_ros

    junits = junits or {}
    with tempfile.TemporaryDirectory(prefix="bench-suite-") as tmp_s:
        tmp = Path(tmp_s)
        took: dict[str, tuple[float, float | None]] = {}
        for name in TIERS:
            if name in junits:
                took[name] = (from_junit(name, junits[name], report), None)
            elif name in parts:
                took[name] = tier(name, list(paths), tmp, report)
        if "quick" in took and "full" in took:
            (qw, qc), (fw, fc) = took["quick"], took["full"]
            cpu = f"; CPU {fc / qc:.3g}x" if qc and fc else ""
            report("pytest, the full suite / the quick tier, wall", f"{fw / qw:.3g}{cpu}", "", None)
        if "build" not in parts:
            return
        why = bench_ros.missing()
        if why:
            report("catkin_make of the exported MDE package", why, "", None, skipped=True)
            return
        t0 = time.perf_counter()
        bench_ros.build_cost(
            ROOT / "scenarios" / "scenario1.yaml", tmp, reps, report, "MDE package (scenario1)"
        )
        print(f"info  build measured in {time.perf_counter() - t0:.0f} s", flush=True)
