"""``falsify --force`` over an earlier search: the earlier one stays whole until the new one
ends (it is written beside it and renamed into place), its messages name ``--out``, and an
interrupted forced search is the search's own outputs, resumable where ``--out`` says."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from amsa_phys.cli import falsify as cli_falsify
from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
RESONANCE = ROOT / "scenarios" / "falsify_resonance.yaml"
ARGV = ["falsify", str(RESONANCE), "--range", "Leader.changePeriod=2:40", "--duration", "10"]
ARGV += ["--budget", "4", "--executor", "local", "-j", "1"]


def _beside(tmp_path: Path) -> list[str]:
    return [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize("trials", [1, 2])
def test_force_keeps_the_earlier_search_whole_until_the_new_one_ends(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    trials: int,
) -> None:
    out = tmp_path / "f"
    argv = [*ARGV, "--trials", str(trials), "--out", str(out)]
    assert main(argv) in (0, 1)
    earlier = out / "results.csv" if trials == 1 else out / "trial-001" / "results.csv"
    earlier.write_text("the earlier search\n")
    seen: list[str] = []
    real = cli_falsify.search

    def watching(*args: Any, **kwargs: Any) -> Any:
        for row in real(*args, **kwargs):
            seen.append(earlier.read_text())
            yield row

    monkeypatch.setattr(cli_falsify, "search", watching)
    capsys.readouterr()
    assert main([*argv, "--force"]) in (0, 1)
    assert seen == ["the earlier search\n"] * (4 * trials)
    assert earlier.read_text().startswith("run,")
    assert _beside(tmp_path) == []
    said = capsys.readouterr().out
    assert f"results in {out if trials == 1 else out / 'trial-002'}" in said
    assert "amsa-tmp" not in said


def test_an_interrupted_forced_search_is_put_in_place_and_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "f"
    argv = [*ARGV, "--out", str(out)]
    assert main(argv) in (0, 1)
    real = cli_falsify.search

    def interrupted(*args: Any, **kwargs: Any) -> Any:
        for k, row in enumerate(real(*args, **kwargs)):
            if k == 2:
                raise KeyboardInterrupt
            yield row

    monkeypatch.setattr(cli_falsify, "search", interrupted)
    capsys.readouterr()
    assert main([*argv, "--force"]) == 130
    err = capsys.readouterr().err
    assert f"finished rows kept in {out} (--resume continues)" in err
    assert "amsa-tmp" not in err
    assert _beside(tmp_path) == []
    kept = (out / "results.csv").read_text().count("\n") - 1
    assert 2 <= kept < 4  # the interrupted search's rows, not the earlier search's four
    monkeypatch.setattr(cli_falsify, "search", real)
    assert main([*argv, "--resume"]) in (0, 1)
    assert f"resumed: {kept} finished runs taken from results.csv" in capsys.readouterr().err
