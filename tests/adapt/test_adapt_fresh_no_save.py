"""``benchmarks.adapt_fresh --no-save`` scores another draw and leaves the committed one alone.

The docs' table of the fresh draw is rendered from ``benchmarks/results/adapt_fresh.json``;
scoring a further draw (the docs' third) must not replace it, or the page would show a draw
its text does not describe.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

from benchmarks import adapt_fresh  # noqa: E402
from benchmarks import results as bench_results  # noqa: E402


@pytest.fixture(scope="module")
def sweepdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A short run of the shipped adaptive sweep (its rules need not be the committed ones)."""
    out = tmp_path_factory.mktemp("fresh") / "sweep"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "amsa_phys",
            "sweep",
            str(ROOT / "scenarios" / "adaptive_sweep.yaml"),
            "--out",
            str(out),
            "--duration",
            "20",
            "--executor",
            "batch",
        ],
        check=True,
        capture_output=True,
    )
    return out


@pytest.mark.parametrize("save", [False, True])
def test_no_save_prints_without_writing(
    sweepdir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys, save: bool
) -> None:
    out = tmp_path / "adapt_fresh.json"
    rewritten: list[str] = []
    monkeypatch.setattr(adapt_fresh, "OUT", out)
    monkeypatch.setattr(bench_results, "write_pages", lambda: rewritten.append("pages") or [])
    args = [str(sweepdir), "--sequences", "1", "--draw", "3000"]
    adapt_fresh.main(args if save else [*args, "--no-save"])
    printed = capsys.readouterr().out
    assert "| robust" in printed
    assert "the rules lose" in printed
    # the control case writes both, so the test sees a write when there is one
    assert out.exists() == save
    assert bool(rewritten) == save
