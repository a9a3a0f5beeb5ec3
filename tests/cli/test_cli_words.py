"""The command line's own words: a mistyped command and an abbreviated option."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

SCENARIO = Path(__file__).resolve().parents[2] / "tests" / "fixtures" / "mde_short.yaml"


def test_a_mistyped_command_gets_a_did_you_mean(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as done:
        main(["rnu", str(SCENARIO)])
    assert done.value.code == 2
    assert capsys.readouterr().err == (
        "error: amsa-phys: unknown command 'rnu' (did you mean run?) (see amsa-phys --help)\n"
    )


def test_an_abbreviated_option_is_refused_not_guessed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--hea`` is a typo, not ``--headless``: refused in one line, nothing written."""
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as done:
        main(["run", str(SCENARIO), "--hea", "--out", str(out)])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "unrecognized arguments: --hea (did you mean --headless?)" in err
    assert not out.exists()


def test_a_mistyped_option_names_the_nearest_option_of_its_command(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Python 3.11's argparse suggests nothing for an unknown option; the names of the
    command given are searched, not just the top parser's."""
    with pytest.raises(SystemExit) as done:
        main(["run", str(SCENARIO), "--seeed", "3", "--outt=x"])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert "--seeed (did you mean --seed?) 3 --outt=x (did you mean --out?)" in err
