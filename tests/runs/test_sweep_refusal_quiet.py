"""A sweep that is refused says only why: its warnings about the plan come once it runs.

A user who mistyped ``--out`` (an existing directory, no ``--force``) should read one line
naming the problem, not a warning about the timeline first and the refusal under it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"
# Kv is swept and the timeline sets it at 125 s: this sweep warns when it runs
ARGS = ["sweep", str(SCENARIO1), "--grid", "MyFollowerController.Kv=0.1,0.2"]
ARGS += ["--duration", "130", "-j", "1"]


def test_a_refused_out_directory_prints_one_line_and_no_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "s"
    out.mkdir()
    (out / "mine.txt").write_text("keep me")
    assert main([*ARGS, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "warning" not in err[0]
    assert str(out) in err[0]
    assert (out / "mine.txt").read_text() == "keep me"


def test_the_same_sweep_warns_when_it_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*ARGS, "--out", str(tmp_path / "s")]) == 0
    assert capsys.readouterr().err.count("warning: MyFollowerController.Kv is swept") == 1
