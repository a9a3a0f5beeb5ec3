"""``ap.falsify``: the command's search from Python, with the same rows, and a user's cost."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import pytest

import amsa_phys as ap
from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
DIST = "MyDistanceMonitor.distanceFollowerToLeader"
BOX = {"Leader.changePeriod": (2.0, 40.0), "Leader.cruisePower": (3.0, 12.0)}


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    path = tmp_path / "res.yaml"
    path.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 60\nseed: 1\nlog_rate: 4\n"
        "set: {Leader.behavior: 3, MyFollowerController.Kv: 0.35}\nexpect:\n"
        f'  - {{stl: "always[20:60](abs({DIST} - 15) <= 4.5)", name: band}}\n'
    )
    return path


def test_same_rows_as_the_command_and_a_trial_table(scenario: Path, tmp_path: Path) -> None:
    found = ap.falsify(scenario, BOX, budget=60, requirement="band", seed=2, trials=2)
    out = tmp_path / "cli"
    args = ["falsify", str(scenario), "--range", "Leader.changePeriod=2.0:40.0"]
    args += ["--range", "Leader.cruisePower=3.0:12.0", "--budget", "60", "--requirement"]
    main([*args, "band", "--seed", "2", "-j", "1", "--out", str(out)])
    cli = list(csv.DictReader(io.StringIO((out / "results.csv").read_text())))
    ours = found.rows[0]
    assert len(ours) == len(cli)
    for a, b in zip(ours, cli, strict=True):
        assert repr(a["robustness.band"]) == b["robustness.band"]
        assert str(a["Leader.changePeriod"]) == b["Leader.changePeriod"]
    assert found.summary["trials"] == 2
    assert [t.seed for t in found.trials] == [2, 3]
    assert found.summary["falsified"] == sum(t.falsified for t in found.trials)


def test_a_users_cost_is_minimised_and_below_zero_falsifies(scenario: Path) -> None:
    def cost(row: dict) -> float:  # a stricter band: 1 m more margin than the requirement's
        return row["robustness.band"] - 1.0

    found = ap.falsify(scenario, BOX, budget=30, cost=cost, search_on=True)
    values = [cost(r) for r in found.rows[0]]
    assert found.worst is not None
    assert cost(found.worst) == min(values)
    assert found.falsified == (min(values) < 0)


def test_bad_arguments_are_config_errors(scenario: Path) -> None:
    with pytest.raises(ap.ConfigError, match="requirement"):
        ap.falsify(scenario, BOX, budget=5, requirement="bnad")
    with pytest.raises(ap.ConfigError):
        ap.falsify(scenario, BOX, budget=5, seed=-1)
    with pytest.raises(ap.ConfigError):
        ap.falsify(scenario, {"Leader.changePeriod": "x"}, budget=5)


def test_ap_run_reports_the_requirements_as_the_command_does(
    scenario: Path, tmp_path: Path
) -> None:
    import json

    got = ap.run(scenario).metrics["requirements"]
    assert main(["run", str(scenario), "--headless", "--out", str(tmp_path / "r")]) in (0, 1)
    want = json.loads((tmp_path / "r" / "metrics.json").read_text())["requirements"]
    assert got == want
    assert set(got["band"]) >= {"formula", "robustness", "verdict", "instant"}
