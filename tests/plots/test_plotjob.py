"""A headless run's plots come from a child that imported matplotlib during the run."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from amsa_phys.runs.plotjob import PlotJob

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"

linux_only = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork is Linux-only")


def a_run(tmp_path: Path) -> tuple[Path, dict]:
    """A finished run directory without plots."""
    out = tmp_path / "run"
    argv = [sys.executable, "-m", "amsa_phys", "run", str(SCENARIO), "--headless", "-q"]
    argv += ["--duration", "10", "--out", str(out), "--no-plot"]
    subprocess.run(argv, check=True, capture_output=True)
    assert not (out / "distance.png").exists()
    return out, json.loads((out / "metrics.json").read_text())


def is_png(path: Path) -> bool:
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 5000


@linux_only
def test_the_cli_process_never_imports_matplotlib_itself(tmp_path: Path) -> None:
    script = (
        "import sys\n"
        "from amsa_phys.cli.main import main\n"
        f"code = main(['run', {str(SCENARIO)!r}, '--headless', '-q', '--duration', '10',"
        f" '--out', {str(tmp_path / 'run')!r}])\n"
        "print(code, 'matplotlib' in sys.modules)\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert proc.stdout.split() == ["0", "False"], proc.stderr
    assert is_png(tmp_path / "run" / "distance.png")
    assert is_png(tmp_path / "run" / "trajectory.png")


@linux_only
def test_child_draws_and_goes_away(tmp_path: Path) -> None:
    out, metrics = a_run(tmp_path)
    job = PlotJob.start()
    assert job.background
    proc = job._proc
    job.draw(out / "trace.csv", metrics, out / "d.png", out / "t.png")
    assert is_png(out / "d.png")
    assert is_png(out / "t.png")
    assert not job.background
    assert proc is not None
    assert not proc.is_alive()


@linux_only
def test_a_dead_child_means_plots_drawn_here(tmp_path: Path) -> None:
    out, metrics = a_run(tmp_path)
    job = PlotJob.start()
    assert job._proc is not None
    job._proc.kill()
    job._proc.join()
    job.draw(out / "trace.csv", metrics, out / "d.png", out / "t.png")
    assert is_png(out / "d.png")
    assert is_png(out / "t.png")


def test_a_plotting_error_surfaces_as_it_would_in_process(tmp_path: Path) -> None:
    out, metrics = a_run(tmp_path)
    job = PlotJob.start()
    with pytest.raises(FileNotFoundError):
        job.draw(out / "no-such-trace.csv", metrics, out / "d.png", out / "t.png")
    assert not (out / "d.png").exists()
    job.close()  # twice is fine
