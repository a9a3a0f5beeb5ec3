"""``amsa-phys test`` with no path searches ./scenarios; where there is none it says that it
looked there by default and what to give, not "scenarios: file not found"."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent


def test_no_scenarios_folder_here_names_the_default_and_what_to_give(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["test"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err
    assert err.startswith(f"error: {tmp_path / 'scenarios'}: no scenarios folder in the current")
    assert "give scenario files or folders" in err


def test_a_path_the_user_typed_is_still_just_not_found(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["test", "scenarios"]) == 2
    assert capsys.readouterr().err.strip() == "error: scenarios: file not found"


def test_the_default_folder_is_searched_when_it_exists(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "scenarios").mkdir()
    text = (ROOT / "scenarios" / "paper_fig5_kv005.yaml").read_text()
    world = ROOT / "worlds" / "mde_challenge.yaml"
    (tmp_path / "scenarios" / "kv.yaml").write_text(
        text.replace("../worlds/mde_challenge.yaml", str(world))
    )
    monkeypatch.chdir(tmp_path)
    assert main(["test"]) == 0
    assert "1 scenario, 3 checks: 3 passed, 0 failed" in capsys.readouterr().out
