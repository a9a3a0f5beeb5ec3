"""Absurd durations: refused in one line, and no size estimate overflows (issue 33, 12).

``--duration 1e308`` made the trace-size note overflow (``OverflowError: cannot convert float
infinity to integer``, a traceback and exit 1) before the run began; once that was fixed the
run went on "forever" (until stopped or faulting). Hostile input must be bounded in time: a
run is at most ``schema.MAX_DURATION_S`` (10^6 s) long, in a file and on every command line,
refused before anything is built. The estimates still take any float (the API's memory check
and the note share them), so they are tested up to the float range.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from amsa_phys.cli.run import warn_if_trace_is_large
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.tracecols import estimate_trace_bytes, size_text

ROOT = Path(__file__).resolve().parent.parent.parent
SHORT = ROOT / "tests" / "fixtures" / "mde_short.yaml"
ENV = {**os.environ, "PYTHONPATH": str(ROOT / "tests")}
LIMIT = (
    "must be at most 1,000,000 s of simulated time (11.6 days, the limit on a run's length), "
    "got 1e+308"
)


@pytest.mark.parametrize("duration", [1e308, sys.float_info.max])
@pytest.mark.parametrize("rate", [1e-9, 20.0, 1e6])
def test_estimate_never_raises(duration: float, rate: float) -> None:
    size = estimate_trace_bytes(3_600, rate, duration)
    assert size > 1e299  # inf past the float range: still a size that compares
    assert size_text(size) in {"over 1e+299 GB", f"about {size / 1e9:.2g} GB"}


def test_estimate_is_the_rows_times_the_row() -> None:
    """The float arithmetic keeps the value the note has always printed."""
    assert estimate_trace_bytes(25, 20, 400_000) == (400_000 * 20 + 1) * 26 * 18
    assert size_text(estimate_trace_bytes(25, 20, 400_000)) == "about 3.7 GB"
    assert size_text(2.5e17) == "about 2.5e+08 GB"


def test_the_note_is_one_line_at_the_longest_run(capsys: pytest.CaptureFixture[str]) -> None:
    warn_if_trace_is_large(load_scenario(SHORT, duration=1e6, log_rate=10_000))
    assert capsys.readouterr().err == (
        "amsa-phys: note: trace.csv will be about 4680.0 GB (25 columns at 10000 Hz for "
        "1e+06 s); --trace-columns or --log-rate make it smaller\n"
    )


def _toy(tmp_path: Path, duration: str) -> Path:
    """A world whose only component faults at t = 1 s: the run ends at once, however long."""
    path = tmp_path / "s.yaml"
    path.write_text(
        f"world:\n  components:\n    B: {{template: 'toys:Bad', freq: 4}}\nduration: {duration}\n"
    )
    return path


def _cli(argv: list[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "amsa_phys", *argv],
        capture_output=True,
        text=True,
        env=ENV,
        check=False,
    )


@pytest.mark.parametrize(
    ("file_duration", "option", "message"),
    [
        ("5", ["--duration", "1e308"], f"--duration: {LIMIT}"),
        ("1.0e+308", [], f"{{path}}:4: duration: {LIMIT}"),
        ("1000000", ["--duration", "1000000.5"], f"--duration: {LIMIT[:-6]}1e+06"),
    ],
    ids=["option", "file", "just-over"],
)
def test_cli_run_longer_than_the_limit_is_refused_in_one_line(
    tmp_path: Path, file_duration: str, option: list[str], message: str
) -> None:
    """exit 2, one line naming the option (or the file's line and key), nothing written."""
    scen = _toy(tmp_path, file_duration)
    out = tmp_path / "o"
    proc = _cli(["run", str(scen), "--headless", "-q", "--out", str(out), *option])
    assert proc.stderr == "error: " + message.format(path=scen) + "\n"
    assert proc.returncode == 2
    assert not out.exists()


def test_the_longest_run_is_accepted(tmp_path: Path) -> None:
    """The limit itself runs (here until the toy faults at t = 1 s): exit 3, not 2."""
    scen = _toy(tmp_path, "5")
    argv = ["run", str(scen), "--headless", "-q", "--out", str(tmp_path / "o")]
    proc = _cli([*argv, "--duration", "1000000"])
    assert proc.stderr == "error: run fault at t=1.000 s in B (Bad): output u is nan\n"
    assert proc.returncode == 3


@pytest.mark.parametrize("command", ["sweep", "falsify"])
def test_sweep_and_falsify_refuse_it_before_any_run(tmp_path: Path, command: str) -> None:
    axis = (
        ["--grid", "B.boom=false"]
        if command == "sweep"
        else ["--range", "B.boom=0:1", "--budget", "2"]
    )
    argv = [command, str(_toy(tmp_path, "5")), *axis, "--duration", "1e308"]
    proc = _cli([*argv, "--out", str(tmp_path / "sw")])
    assert proc.stderr == f"error: --duration: {LIMIT}\n"
    assert proc.returncode == 2
    assert not (tmp_path / "sw").exists()
