"""Every size estimate survives any duration the schema accepts (issue 33, 12).

The schema takes any positive finite duration, up to ~1.8e308 s. ``--duration 1e308`` made
the trace-size note overflow (``OverflowError: cannot convert float infinity to integer``,
a traceback and exit 1) before the run began. A duration that large is legal — the run
simply goes on until it is stopped or faults — so the estimate, not the duration, was wrong.
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
NOTE = (
    "amsa-phys: note: trace.csv will be over 1e+299 GB (1 columns at 20 Hz for 1e+308 s); "
    "--trace-columns or --log-rate make it smaller\n"
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


def test_the_note_is_one_line_at_1e308(capsys: pytest.CaptureFixture[str]) -> None:
    warn_if_trace_is_large(load_scenario(SHORT, duration=1e308))
    assert capsys.readouterr().err == (
        "amsa-phys: note: trace.csv will be over 1e+299 GB (25 columns at 20 Hz for 1e+308 s); "
        "--trace-columns or --log-rate make it smaller\n"
    )


def _toy(tmp_path: Path, duration: str) -> Path:
    """A world whose only component faults at t = 1 s: the run ends at once, however long."""
    path = tmp_path / "s.yaml"
    path.write_text(
        f"world:\n  components:\n    B: {{template: 'toys:Bad', freq: 4}}\nduration: {duration}\n"
    )
    return path


@pytest.mark.parametrize(
    ("file_duration", "option"),
    [("5", ["--duration", "1e308"]), ("1.0e+308", [])],
    ids=["option", "file"],
)
def test_cli_run_of_1e308_seconds_has_no_traceback(
    tmp_path: Path, file_duration: str, option: list[str]
) -> None:
    scen = _toy(tmp_path, file_duration)
    argv = ["run", str(scen), "--headless", "-q", "--out", str(tmp_path / "o"), *option]
    proc = subprocess.run(
        [sys.executable, "-m", "amsa_phys", *argv],
        capture_output=True,
        text=True,
        env=ENV,
        check=False,
    )
    assert proc.stderr == NOTE + "error: run fault at t=1.000 s in B (Bad): output u is nan\n"
    assert proc.returncode == 3
    assert (tmp_path / "o" / "metrics.json").is_file()


@pytest.mark.parametrize("executor", ["local", "batch"])
def test_sweep_of_1e308_seconds_has_no_traceback(tmp_path: Path, executor: str) -> None:
    argv = ["sweep", str(_toy(tmp_path, "5")), "--grid", "B.boom=false", "--duration", "1e308"]
    argv += ["--out", str(tmp_path / "sw"), "-j", "1", "--executor", executor]
    proc = subprocess.run(
        [sys.executable, "-m", "amsa_phys", *argv],
        capture_output=True,
        text=True,
        env=ENV,
        check=False,
    )
    assert "Traceback" not in proc.stderr
    assert "run 0: run fault at t=1.000 s in B (Bad): output u is nan" in proc.stderr
    assert (tmp_path / "sw" / "results.csv").is_file()
