"""``--force`` replaces only outputs of the same kind: a run's ``--force`` never wipes a sweep's
or a falsification search's results (the marker file says which command made a directory).

A user who points ``run --out`` at last night's sweep by mistake keeps the sweep; a directory
marked before kinds existed is replaced as before.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.runs.rundir import MARKER, kind_of

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def _scenario(path: Path) -> Path:
    path.write_text(
        f"world: {WORLD}\nduration: 2\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "sweep:\n  grid: {MyFollowerController.Kv: [0.2, 0.3]}\n  metric: rms_error\n",
        encoding="utf-8",
    )
    return path


def _sweep(tmp_path: Path) -> tuple[Path, Path]:
    scen = _scenario(tmp_path / "s.yaml")
    out = tmp_path / "sweep"
    assert main(["sweep", str(scen), "--out", str(out), "-j", "1"]) == 0
    return scen, out


def test_a_runs_force_keeps_a_sweeps_results(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen, out = _sweep(tmp_path)
    results = (out / "results.csv").read_bytes()
    capsys.readouterr()
    code = main(["run", str(scen), "--headless", "--no-plot", "--out", str(out), "--force", "-q"])
    assert code == 2
    (err,) = capsys.readouterr().err.splitlines()
    assert err == (
        f"error: {out}: --out: holds a sweep's outputs (amsa-phys sweep); --force replaces "
        "only a run's: choose a new directory, or remove this one yourself"
    )
    assert (out / "results.csv").read_bytes() == results  # nothing touched
    # the same command's --force still replaces its own kind
    assert main(["sweep", str(scen), "--out", str(out), "-j", "1", "--force"]) == 0
    assert kind_of(out) == "sweep"


def test_a_run_directory_says_it_is_a_runs_and_an_old_marker_is_replaced_as_before(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = _scenario(tmp_path / "s.yaml")
    out = tmp_path / "run"
    args = ["run", str(scen), "--headless", "--no-plot", "--out", str(out), "-q"]
    assert main(args) == 0
    assert kind_of(out) == "run"
    # a directory marked before kinds existed (no kind: line) is anyone's to replace
    (out / MARKER).write_text("amsa-phys output directory; --force may replace it\n")
    assert kind_of(out) is None
    assert main(["sweep", str(scen), "--out", str(out), "-j", "1", "--force"]) == 0
    assert kind_of(out) == "sweep"
    capsys.readouterr()
