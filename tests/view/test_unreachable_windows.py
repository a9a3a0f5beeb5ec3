"""An expectation whose window starts after the scenario's end is refused (issue 33, 13).

It could never be evaluated, and an expectation never evaluated passes: ``after: 1000000``
in a 5 s scenario printed "checked no sample" and exited 0. When the scenario's *own*
duration puts the window past the end, that is a mistake in the file: one line naming file,
line and key, exit 2, before anything runs. When only ``--duration`` cuts the window off,
the file is fine and the check is skipped, visibly, as before.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import amsa_phys as ap
from amsa_phys.cli.main import main
from amsa_phys.errors import ConfigError

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def scenario(tmp_path: Path, duration: str, after: str) -> Path:
    path = tmp_path / "late.yaml"
    path.write_text(
        f"world: {WORLD}\n"
        f"duration: {duration}\n"
        "expect:\n"
        "  - {trace: Leader.posX, below: 1000}\n"
        f"  - {{trace: Leader.posX, after: {after}, below: -1}}\n"
    )
    return path


MESSAGE = "expect[1].after: 1e+06 s is after the end of the scenario (duration 5 s): "
MESSAGE += "the window would never hold a sample"


@pytest.mark.parametrize("command", ["validate", "run"])
def test_window_after_the_end_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    path = scenario(tmp_path, "5", "1000000")
    argv = [command, str(path)]
    if command == "run":
        argv += ["--headless", "-q", "--no-plot", "--out", str(tmp_path / "o")]
    assert main(argv) == 2
    assert capsys.readouterr().err == f"error: {path}:5: {MESSAGE}\n"
    assert not (tmp_path / "o").exists()  # refused before anything ran


def test_suite_reports_it_as_an_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``amsa-phys test`` goes on with the other scenarios and counts this one an error."""
    path = scenario(tmp_path, "5", "1000000")
    assert main(["test", str(path)]) == 1
    captured = capsys.readouterr()
    assert captured.err == f"error: late: {path}:5: {MESSAGE}\n"
    assert "0 passed, 0 failed, 1 error" in captured.out


def test_api_mapping_is_refused_with_its_key() -> None:
    source = {
        "world": str(WORLD),
        "duration": 5,
        "expect": [{"trace": "Leader.posX", "after": 1_000_000, "below": -1}],
    }
    with pytest.raises(ConfigError) as info:
        ap.run(source)
    assert str(info.value) == "<mapping>: " + MESSAGE.replace("expect[1]", "expect[0]")
    with pytest.raises(ConfigError):
        ap.validate(source)


def test_a_window_starting_at_the_end_is_judged(tmp_path: Path) -> None:
    """``after`` equal to the duration holds the final instant: accepted, and it fails."""
    run = ap.run(scenario(tmp_path, "5", "5"))
    late = run.checks[1]
    assert late.verdict == "FAIL"
    assert late.value is not None
    assert late.value > -1


def test_cut_off_by_duration_only_is_skipped_as_before(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # reachable in the file's own run (1e6 s: the longest a scenario may be)
    path = scenario(tmp_path, "1000000", "500000")
    argv = ["run", str(path), "--headless", "-q", "--no-plot", "--duration", "2"]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        "expect Leader.posX in [500000, end] s: skipped "
        "(no sample: the window starts after the run's end at t=2 s)"
    )
