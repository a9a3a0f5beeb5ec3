"""Scenario tests: run every scenario that has ``expect`` and collect the checks.

Used by ``amsa-phys test`` (in parallel, across processes) and by the pytest plugin. Each
scenario runs into a temporary directory unless an output root is given; a scenario that
cannot load or faults is an error result, not a crash of the whole suite.
"""

from __future__ import annotations

import re
import stat
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import AmsaError
from ..model.configure import with_ros2
from ..model.scenario import Scenario, load_scenario
from ..model.yamlio import MAX_FILE_BYTES, load_yaml, read_regular_file
from .expect import Check, check_expectations
from .rundir import MARKER, prepare_run_dir, unique_names
from .single import run_scenario

_EXPECT = re.compile(r"^expect\s*:", re.MULTILINE)


@dataclass
class ScenarioResult:
    """The outcome of one scenario file."""

    path: str
    name: str
    checks: list[Check] = field(default_factory=list)
    error: str | None = None
    wall_s: float = 0.0

    @property
    def passed(self) -> bool:
        """No error and every check passed (or was skipped)."""
        return self.error is None and all(c.passed for c in self.checks)


def has_expectations(path: Path) -> bool:
    """Cheap test: a YAML file with a top-level ``expect:`` key (it is loaded properly later,
    so a broken scenario surfaces as an error rather than being skipped).

    Read as the loader reads (``read_regular_file``): a FIFO named ``x.yaml`` in the folder
    hung the search, a link to ``/dev/zero`` filled the memory. A file the loader refuses
    (not a regular file, over its size) is kept, so it surfaces as that one-line error too.
    """
    try:
        st = path.stat()
    except OSError:
        return False
    if stat.S_ISDIR(st.st_mode):
        return False
    if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_FILE_BYTES:
        return True
    try:
        text = read_regular_file(path, MAX_FILE_BYTES, "a YAML file")
    except AmsaError:
        return False
    return bool(_EXPECT.search(text.decode("utf-8", errors="replace")))


def in_run_directory(path: Path) -> bool:
    """Whether ``path`` is an output of amsa-phys (a run directory's resolved
    ``scenario.yaml``, a falsify trial's ``worst.yaml``, anything else in an output folder).

    A folder search skips those: ``test runs/`` would otherwise rerun every old run as a
    test, and an output folder is data someone may have handed over, whose files may name a
    plugin template to import. Every folder above ``path`` is looked at, not only its own:
    ``falsify --trials`` writes each trial's ``worst.yaml`` one folder below the marker. An
    output folder holds amsa-phys's marker file, or (a run made before the marker) a
    ``metrics.json`` beside its ``scenario.yaml``.
    """
    parent = path.parent
    if path.name == "scenario.yaml" and (parent / "metrics.json").is_file():
        return True
    return any((folder / MARKER).is_file() for folder in path.absolute().parents)


def find_scenarios(paths: list[str], skipped: list[Path] | None = None) -> list[Path]:
    """Scenario files with expectations: files as given, folders searched recursively.

    A folder's run directories are skipped (see :func:`in_run_directory`) and listed in
    ``skipped``; a file given by name always runs (that is how a run is replayed as a test).
    """
    found: list[Path] = []
    for raw in paths:
        p = Path(raw)
        if p.is_dir():
            for f in sorted(p.rglob("*.y*ml")):
                if not has_expectations(f):
                    continue
                if in_run_directory(f):
                    if skipped is not None:
                        skipped.append(f)
                    continue
                found.append(f)
        else:
            found.append(p)
    return found


def run_dir_names(paths: list[str]) -> list[str]:
    """One distinct, safe directory name per scenario file for ``test --out``.

    Named after each scenario's ``name:`` (the file's stem where it has none or cannot be
    read; loading reports that later), made safe and unique *before* any run starts, so two
    scenarios with the same name in parallel workers never share or delete one directory.
    """
    names = []
    for path in paths:
        name = Path(path).stem
        try:
            data = load_yaml(path).data
            if isinstance(data, dict) and isinstance(data.get("name"), str):
                name = data["name"]
        except (AmsaError, OSError):
            pass
        names.append(name)
    return unique_names(names)


def input_files(scenario: Scenario) -> list[Path]:
    """The files a run of ``scenario`` reads: its output directory must not hold them."""
    return [scenario.path, scenario.world.source.path]


def run_scenario_file(
    path: str,
    out_root: str | None = None,
    dir_name: str | None = None,
    ros2: str | None = None,
    ros2_timeout: float | None = None,
) -> ScenarioResult:
    """Load, run and check one scenario (safe to call in a worker process).

    With ``out_root`` the run goes to ``out_root/dir_name`` (``dir_name`` from
    :func:`run_dir_names`); nothing outside ``out_root`` is created or removed.
    """
    t0 = time.perf_counter()
    result = ScenarioResult(path=path, name=Path(path).stem)
    try:
        scenario = with_ros2(load_scenario(path), ros2, ros2_timeout)
        result.name = scenario.name
        if not scenario.expect:
            result.error = "no expect: section"
            return result
        with tempfile.TemporaryDirectory(prefix="amsa-test-") as tmp:
            if out_root:
                sub = dir_name or run_dir_names([path])[0]
                out = Path(out_root) / sub
            else:
                out = Path(tmp) / "run"
            prepare_run_dir(out, force=True, inputs=input_files(scenario))
            outcome = run_scenario(scenario, out, plot=out_root is not None, progress=False)
            result.checks = check_expectations(scenario.expect, outcome.metrics, out / "trace.csv")
    except AmsaError as exc:
        result.error = str(exc)
    result.wall_s = time.perf_counter() - t0
    return result


def run_scenario_job(
    job: tuple[str, str | None],
    out_root: str | None,
    ros2: str | None = None,
    ros2_timeout: float | None = None,
) -> ScenarioResult:
    """:func:`run_scenario_file` for a ``(path, dir_name)`` pair (a pool maps one argument)."""
    return run_scenario_file(job[0], out_root, job[1], ros2, ros2_timeout)
