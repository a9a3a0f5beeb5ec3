"""Run every scenario with expectations; print pass/fail against the bounds."""

from __future__ import annotations

import argparse
import functools
import sys
from pathlib import Path

from ..engine import interrupt
from ..errors import ConfigError, Interrupted, one_line
from ..model.wording import plural
from ..runs.junit import write_junit
from ..runs.outfile import check_output_file, junit_by_us
from ..runs.pool import WORKER_LOST, imap_resilient
from ..runs.rundir import prepare_out_root
from ..runs.suite import ScenarioResult, find_scenarios, run_dir_names, run_scenario_job
from .options import add_jobs, add_ros2

#: What ``test`` searches without a path (a project's own scenarios, as in this repository).
DEFAULT_FOLDER = "scenarios"


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys test``."""
    p.add_argument(
        "paths",
        nargs="*",
        default=[],
        help="scenario files or folders (default: scenarios)",
    )
    p.add_argument("--junit", metavar="FILE", help="also write JUnit XML")
    add_jobs(p)
    p.add_argument("--out", metavar="DIR", help="keep each run's directory under DIR")
    add_ros2(p)


def run(args: argparse.Namespace) -> int:
    """Exit 0 if every check passes, 1 if any fails or errors."""
    skipped: list[Path] = []
    if not args.paths and not Path(DEFAULT_FOLDER).is_dir():
        # the default, not a name the user typed: say where it was looked for and what to give
        raise ConfigError(
            "no scenarios folder in the current directory (the default): give scenario files "
            "or folders, e.g. amsa-phys test my_scenarios/",
            file=Path(DEFAULT_FOLDER).resolve(),
        )
    paths = args.paths or [DEFAULT_FOLDER]
    files = find_scenarios(paths, skipped)
    if skipped:
        print(
            f"skipped {plural(len(skipped), 'resolved scenario')} in run directories "
            f"(e.g. {skipped[0]}); name a file to run it",
            file=sys.stderr,
        )
    for f in files:
        if not f.exists():
            raise ConfigError("file not found", file=f)
    if not files:
        raise ConfigError("no scenario with an expect: section found", key=" ".join(paths))
    if args.jobs < 1:
        raise ConfigError("must be at least 1", key="--jobs")
    if args.out:  # its scenarios' directories are judged one by one; a bad root is one line
        prepare_out_root(Path(args.out))
    if args.junit:  # before the suite runs, not after (its folder is made, as pytest does)
        # a file there is replaced only if it is an earlier report; never a scenario or a
        # world the suite reads (``--junit scenarios/a.yaml`` wrote XML over the scenario)
        check_output_file(
            Path(args.junit), "--junit", None, files, ours=junit_by_us, make_parent=True
        )
    with interrupt.sigterm_as_ctrl_c():
        # a ROS 2 node answers one run at a time: the scenarios run one after another
        jobs = 1 if args.ros2 else min(args.jobs, len(files))
        results = _run_all(files, jobs, args.out, args.ros2, args.ros2_timeout)
    print_table(results)
    if args.junit:
        write_junit(results, Path(args.junit))
    return 0 if all(r.passed for r in results) else 1


def _run_all(
    files: list[Path],
    jobs: int,
    out: str | None,
    ros2: str | None = None,
    ros2_timeout: float | None = None,
) -> list[ScenarioResult]:
    """Every scenario's result, in the order given; Ctrl-C stops the whole suite.

    A suite cut short reports nothing (a partial table would read as a smaller suite that
    passed): scenarios not started never start, running ones stop at their next simulated
    second (the pool sets its workers' stop flag), and :class:`Interrupted` says how far it
    got. A scenario that kills its worker process twice is an ERROR row (``runs/pool.py``).
    """
    done: dict[int, ScenarioResult] = {}
    paths = [str(f) for f in files]
    names: list[str | None] = list(run_dir_names(paths)) if out else [None] * len(paths)
    job_list = list(zip(paths, names, strict=True))
    try:
        with interrupt.deferred():  # Ctrl-C raised between completions, not in a pool's locks
            _run_each(job_list, jobs, out, done, ros2, ros2_timeout)
            interrupt.check()  # a Ctrl-C noted after the last completion still stops it
    except KeyboardInterrupt:
        raise Interrupted(
            f"test interrupted after {len(done)} of {len(files)} scenarios; nothing reported"
        ) from None
    return [done[i] for i in range(len(files))]


def _run_each(
    job_list: list[tuple[str, str | None]],
    jobs: int,
    out: str | None,
    done: dict[int, ScenarioResult],
    ros2: str | None = None,
    ros2_timeout: float | None = None,
) -> None:
    run = functools.partial(run_scenario_job, out_root=out, ros2=ros2, ros2_timeout=ros2_timeout)
    if jobs == 1:
        for i, job in enumerate(job_list):
            done[i] = run(job)
            interrupt.check()
        return
    # at most ``jobs`` handed out: anything queued would still run after Ctrl-C
    # (measured before: six 3 s scenarios on two workers went on for 5.4 s)
    for i, result in imap_resilient(run, job_list, jobs, _lost, in_flight=jobs):
        done[i] = result


def _lost(job: tuple[str, str | None]) -> ScenarioResult:
    path = job[0]
    return ScenarioResult(path=path, name=Path(path).stem, error=f"{WORKER_LOST}, twice")


def print_table(results: list[ScenarioResult]) -> None:
    """One row per check: scenario, check, measured value, bound, verdict."""
    rows = [("scenario", "check", "measured", "bound", "result")]
    for r in results:
        if r.error is not None:
            rows.append((r.name, "load and run", "-", "-", "ERROR"))
            continue
        for c in r.checks:
            value = "-" if c.value is None else c.measured
            rows.append((r.name, c.what, value, c.bound, c.verdict))
    # cells escaped before they are measured: a name with a control character is wider shown
    # (``a\x01b``) than its length, and the columns after it slid out of line
    rows = [tuple(one_line(v) for v in row) for row in rows]
    widths = [max(len(row[i]) for row in rows) for i in range(5)]
    for row in rows:
        print("  ".join(v.ljust(w) for v, w in zip(row, widths, strict=True)).rstrip())
    for r in results:
        if r.error is not None:
            print(one_line(f"error: {r.name}: {r.error}"), file=sys.stderr)
    n_checks = sum(len(r.checks) for r in results)
    n_fail = sum(1 for r in results for c in r.checks if not c.passed)
    n_err = sum(1 for r in results if r.error is not None)
    n_skip = sum(1 for r in results for c in r.checks if c.skipped)
    print(
        f"{plural(len(results), 'scenario')}, {plural(n_checks, 'check')}: "
        f"{n_checks - n_fail - n_skip} passed, {n_fail} failed"
        + (f", {n_skip} skipped" if n_skip else "")
        + (f", {plural(n_err, 'error')}" if n_err else "")
    )
