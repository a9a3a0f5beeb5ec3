"""A sweep axis's errors name the option that gave it (`--grid` or `--range`)."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
SCEN = ROOT / "tests" / "fixtures" / "mde_short.yaml"


@pytest.mark.parametrize(
    ("option", "axis", "message"),
    [
        ("--range", "MyFollowerControler.Kv=0.1:0.3:3", "unknown component 'MyFollowerControler'"),
        ("--range", "MyFollowerController.Kv=0.1:20:2", "20 is above the maximum 10"),
        ("--range", "physics.ground.frction=0.1:0.5:2", "unknown key (did you mean friction?)"),
        ("--grid", "MyFollowerController.Kv=0.1,20", "20 is above the maximum 10"),
    ],
)
def test_a_bad_axis_is_refused_naming_its_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, axis: str, message: str
) -> None:
    out = tmp_path / "sw"
    assert main(["sweep", str(SCEN), option, axis, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {option} {axis.partition('=')[0]}: {message}")
    assert not out.exists()
