"""``test --out DIR``: a root that cannot hold the scenarios' directories is one line, exit 2,
before any scenario runs (it was an ERROR row per scenario, exit 1, each after its worker
had started: a suite of fifty said the same thing fifty times)."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

WORLD = Path(__file__).resolve().parents[2] / "worlds" / "mde_challenge.yaml"


def _scenario(folder: Path) -> Path:
    path = folder / "s.yaml"
    path.write_text(
        f"world: {WORLD}\nduration: 1\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "expect:\n  - {metric: collisions, below: 1}\n"
    )
    return path


def test_a_root_that_is_a_file_is_refused_before_any_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = _scenario(tmp_path)
    root = tmp_path / "notes.txt"
    root.write_text("mine\n")
    assert main(["test", str(scen), str(scen), "--out", str(root), "-j", "1"]) == 2
    out, err = capsys.readouterr()
    assert err == f"error: {root}: --out: exists and is not a directory\n"
    assert out == ""  # no table: nothing ran
    assert root.read_text() == "mine\n"


def test_a_root_that_does_not_exist_is_made(tmp_path: Path) -> None:
    scen = _scenario(tmp_path)
    root = tmp_path / "a" / "b"
    assert main(["test", str(scen), "--out", str(root), "-j", "1"]) == 0
    assert (root / "s" / "trace.csv").is_file()
