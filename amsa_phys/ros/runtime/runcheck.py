"""``rosrun PKG run_lockstep SCENARIO.launch [arg:=value ...]``: a launch whose exit code a CI
can rely on.

``roslaunch`` exits 0 whatever its nodes' exit codes were: a run whose expectations failed, or
that faulted, ends the launch the same way a passing one does. This script (generated into
the package as ``nodes/run_lockstep``) runs ``roslaunch PKG SCENARIO.launch`` with the
arguments given (``mode:=lockstep`` unless ``mode:=`` is one of them, and ``out:=``
``runs/SCENARIO-STAMP`` in the current directory unless given), then judges the run directory
the simulator wrote, exactly as ``amsa-phys run`` judges its own: the expectations of the
run's ``scenario.yaml`` against its ``metrics.json`` and ``trace.csv``. Exit 0: every check
passed; 1: a check failed; 2: the run faulted, wrote nothing, or a required node died
(killed or crashed: the launch names it); 130: interrupted.

roslaunch's output passes through this script (``launchout``), which notes its ``error: ``
lines: when the run did not start, the last line names the first of them (the node that
refused to start and why), as the cause the user would otherwise look for among
roslaunch's screens.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import sys
from pathlib import Path

from ...errors import AmsaError, one_line
from ...model.scenario import load_scenario
from ...model.wording import plural
from ...runs.expect import check_expectations
from ...runs.rundir import default_run_dir
from ..names import RUN_LOCKSTEP as SCRIPT
from . import launchout

USAGE = f"usage: rosrun PKG {SCRIPT} SCENARIO.launch [arg:=value ...]"


def judge(out: Path, seen: launchout.Seen | None = None) -> tuple[int, list[str]]:
    """The exit code of the run in ``out`` and the lines that say why; ``seen``: what the
    launch printed, to say why a run did not start."""
    metrics_file = out / "metrics.json"
    if not metrics_file.is_file():
        why = f": {seen.cause()}" if seen is not None else ""
        return 2, [f"{SCRIPT}: no run in {out} (metrics.json missing): the run did not start{why}"]
    metrics = json.loads(metrics_file.read_text())
    status = str(metrics.get("status", ""))
    if status == "interrupted" and seen is not None and seen.died:
        # the launch ended because a required node died (killed, crashed): the run's
        # fault, not the user's Ctrl-C, which roslaunch's own shutdown looks like to the
        # simulator
        return 2, [
            one_line(
                f"{SCRIPT}: node {seen.died[0]} died mid-run and ended the launch; "
                f"outputs so far in {out}"
            )
        ]
    if status == "interrupted":
        return 130, [f"{SCRIPT}: the run was interrupted; outputs so far in {out}"]
    if status != "completed":
        return 2, [one_line(f"{SCRIPT}: the run did not complete ({status}); outputs in {out}")]
    try:
        scenario = load_scenario(out / "scenario.yaml")
        checks = check_expectations(scenario.expect, metrics, out / "trace.csv")
    except (AmsaError, OSError) as exc:
        return 2, [one_line(f"{SCRIPT}: cannot judge the run in {out}: {exc}")]
    lines = [one_line(f"expect {c.describe()}") for c in checks]
    failed = sum(not c.passed for c in checks)
    total = plural(len(checks), "expectation")
    if failed:
        lines.append(f"{SCRIPT}: FAIL: {failed} of {total} failed ({out})")
        return 1, lines
    lines.append(f"{SCRIPT}: pass: {total} passed{_left_out(out)} ({out})")
    return 0, lines


def _left_out(out: Path) -> str:
    """``, N skipped ...`` when the run was cut short (``duration:=``): its resolved
    ``scenario.yaml`` leaves out the checks it could not judge, naming them in its head
    comment (``runs/single.py``), which the simulator counted as skipped."""
    try:
        head = (out / "scenario.yaml").read_text().split("\n", 1)[0]
    except OSError:
        return ""
    marker = "these checks were not judged and are left out: "
    if marker not in head:
        return ""
    n = len(head.split(marker, 1)[1].split("; "))
    return f", {n} skipped (not judged by this run: see scenario.yaml)"


def launch_args(launch: str, args: list[str]) -> tuple[list[str], Path]:
    """``args`` completed with ``mode:=lockstep`` and ``out:=`` where missing; the run dir.

    A relative ``out:=`` is made absolute here, from the current directory: the simulator
    node runs in ``ROS_HOME``, where a relative path would land.
    """
    given = {a.partition(":=")[0]: a.partition(":=")[2] for a in args if ":=" in a}
    kept = [a for a in args if a.partition(":=")[0] != "out"]
    extra = [] if "mode" in given else ["mode:=lockstep"]
    if given.get("out"):
        out = Path(given["out"]).absolute()
    else:
        out = default_run_dir(Path(launch).stem, Path.cwd() / "runs").absolute()
    return [*kept, *extra, f"out:={out}"], out


def _stamp(path: Path) -> int | None:
    """``path``'s modification time (ns), None if it does not exist."""
    try:
        return path.stat().st_mtime_ns
    except OSError:
        return None


def main(pkg: str) -> None:
    """The script's entry point: launch, wait, judge, exit with the verdict."""
    argv = sys.argv[1:]
    if not argv or argv[0] in ("-h", "--help") or ":=" in argv[0]:
        print(USAGE, file=sys.stderr if not argv or ":=" in argv[0] else sys.stdout)
        sys.exit(0 if argv and argv[0] in ("-h", "--help") else 2)
    launch = argv[0] if argv[0].endswith(".launch") else f"{argv[0]}.launch"
    args, out = launch_args(launch, argv[1:])
    roslaunch = shutil.which("roslaunch")
    if roslaunch is None:
        sys.exit(f"error: {SCRIPT}: roslaunch is not on PATH (source the workspace's setup.bash)")
    # a terminal's Ctrl-C reaches roslaunch too, which stops the run; this process waits for
    # it and reports the interrupted run
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    before = _stamp(out / "metrics.json")  # a former run's (force:=true): not this run's
    # the nodes start afresh: this script's own re-execution (AMSA_PHYS_PYTHON) is not theirs
    env = {k: v for k, v in os.environ.items() if k != "AMSA_PHYS_REEXEC"}
    returncode, seen = launchout.run([roslaunch, pkg, launch, *args], env)
    if before is not None and _stamp(out / "metrics.json") == before:
        code, lines = 2, [f"{SCRIPT}: the run wrote no new metrics.json in {out}: {seen.cause()}"]
    else:
        code, lines = judge(out, seen)
    if code == 2 and returncode != 0:  # before the verdict: the last line says why
        lines.insert(-1, f"{SCRIPT}: roslaunch exited with {returncode}")
    for line in lines:
        print(line, file=sys.stdout if code == 0 else sys.stderr, flush=True)
    sys.exit(code)
