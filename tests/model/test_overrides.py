"""What ``--set`` and ``amsa_phys.run(set=...)`` tell the user about their overrides.

A value the timeline replaces later is said before the run (a ``warning:`` line in the CLI,
an :class:`~amsa_phys.OverrideWarning` in Python, as the sweep warns for a swept one); a
parameter given twice with two values is refused, naming both, as a scenario file refuses
a key given twice.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import amsa_phys as ap
from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO2 = ROOT / "scenarios" / "scenario2.yaml"  # Kv 0.35, then 0.05 from t = 100 s
KV = "MyFollowerController.Kv"
LATER = (
    "MyFollowerController.Kv is given by {option}, but the scenario's timeline sets it again "
    "(at 100 s): the value given holds only until 100 s, so it shapes phase 0 only"
)


def cli(tmp_path: Path, *argv: str) -> int:
    out = tmp_path / "run"
    return main(["run", str(SCENARIO2), "--headless", "-q", "--no-plot", "--out", str(out), *argv])


def test_cli_warns_once_when_the_timeline_replaces_a_set_value(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert cli(tmp_path, "--duration", "110", "--set", f"{KV}=0.2", "--force") == 0
    err = capsys.readouterr().err.splitlines()
    assert err.count("warning: " + LATER.format(option="--set")) == 1
    # a run that stops before the timeline's entry: the value holds throughout, no warning
    assert cli(tmp_path, "--duration", "50", "--set", f"{KV}=0.2", "--force") == 0
    assert "warning" not in capsys.readouterr().err
    # a parameter the timeline never sets: no warning
    assert cli(tmp_path, "--duration", "110", "--set", "MyFollowerController.Kw=1", "--force") == 0
    assert "warning" not in capsys.readouterr().err


def test_api_warns_the_same_at_the_callers_line() -> None:
    with pytest.warns(ap.OverrideWarning) as caught:
        ap.run(SCENARIO2, duration=110, set={KV: 0.2})
    assert [str(w.message) for w in caught] == [LATER.format(option="set=")]
    assert caught[0].filename == __file__  # the user's call, not a line inside amsa_phys
    with warnings.catch_warnings():
        warnings.simplefilter("error", ap.OverrideWarning)
        ap.run(SCENARIO2, duration=50, set={KV: 0.2})
        ap.run(SCENARIO2, duration=110, set={"MyFollowerController.Kw": 1})


def test_a_parameter_set_twice_with_two_values_is_refused_naming_both(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert cli(tmp_path, "--duration", "1", "--set", f"{KV}=0.2", "--set", f"{KV}=0.3") == 2
    assert capsys.readouterr().err == (
        f"error: --set {KV}: set twice, '{KV}=0.2' and '{KV}=0.3': give one value\n"
    )
    assert not (tmp_path / "run").exists()
    # physics settings and frequencies too
    argv = ["--set", "physics.ground.friction=0.5", "--set", "physics.ground.friction=0.6"]
    assert cli(tmp_path, "--duration", "1", *argv) == 2
    assert "error: --set physics.ground.friction: set twice" in capsys.readouterr().err
    assert (
        cli(tmp_path, "--duration", "1", "--set", "Leader.freq=10", "--set", "Leader.freq=5") == 2
    )
    assert "error: --set Leader.freq: set twice" in capsys.readouterr().err
    # the same value twice is harmless
    assert cli(tmp_path, "--duration", "1", "--set", f"{KV}=0.2", "--set", f"{KV}=0.2") == 0


def test_a_parameter_and_its_alias_in_one_set_mapping_are_refused() -> None:
    with pytest.raises(ap.ConfigError) as err:
        ap.run(SCENARIO2, duration=1, set={"LeaderGPS.noise": 1, "LeaderGPS.stddev": 2})
    assert str(err.value) == (
        'set={"LeaderGPS.stddev": ...}: set twice, '
        "'LeaderGPS.noise=1' and 'LeaderGPS.stddev=2': give one value"
    )


def test_export_ros_warns_as_run_does(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The exported package runs the same timeline: the same note, before it is written."""
    argv = ["export", "ros", str(SCENARIO2), "-o", str(tmp_path / "pkg"), "--set", f"{KV}=0.2"]
    assert main(argv) == 0
    assert capsys.readouterr().err.splitlines() == ["warning: " + LATER.format(option="--set")]


def test_export_ros_of_a_bare_world_refuses_a_parameter_set_twice(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A bare world goes through the same --set path as a scenario: no silent last value,
    and a single --set reaches the package's parameters."""
    world = ROOT / "worlds" / "mde_challenge.yaml"
    argv = ["export", "ros", str(world), "-o", str(tmp_path / "twice")]
    assert main([*argv, "--set", f"{KV}=0.1", "--set", f"{KV}=0.2"]) == 2
    assert capsys.readouterr().err == (
        f"error: --set {KV}: set twice, '{KV}=0.1' and '{KV}=0.2': give one value\n"
    )
    assert not (tmp_path / "twice").exists()
    once = ["export", "ros", str(world), "-o", str(tmp_path / "once"), "--set", f"{KV}=0.125"]
    assert main(once) == 0
    params = (tmp_path / "once" / "config" / "mdeChallenge_params.yaml").read_text()
    assert "Kv: 0.125" in params
