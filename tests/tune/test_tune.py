"""``amsa-phys tune``: the optimizer finds known minima within its budget, and the command
tunes a gain over a scenario's contexts, refusing bad input in one line."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.tune.search import minimise

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "adapt"


def test_one_parameter_is_found_within_the_budget() -> None:
    calls = []

    def f(x: tuple[float, ...]) -> float:
        calls.append(x)
        return abs(x[0] - 0.31) + (5.0 if x[0] > 0.6 else 0.0)  # a cliff, as instability

    found = minimise(f, [(0.05, 0.8)], budget=14)
    assert len(calls) <= 14
    assert found.best.values[0] == pytest.approx(0.31, abs=0.01)


def test_several_parameters_use_cma_es_within_the_budget() -> None:
    found = minimise(lambda x: (x[0] - 2.0) ** 2 + (x[1] + 1.0) ** 2, [(0, 5), (-3, 3)], 120)
    assert len(found.trials) <= 120
    assert found.best.values == pytest.approx((2.0, -1.0), abs=0.1)


def test_integer_parameters_are_whole() -> None:
    found = minimise(lambda x: abs(x[0] - 7.4), [(0, 20)], 10, integer=[True])
    assert all(float(t.values[0]).is_integer() for t in found.trials)
    assert found.best.values == (7.0,)


def test_tune_a_gain_over_the_scenario_contexts(capsys) -> None:
    argv = ["tune", str(FIXTURE / "sweep.yaml"), "--range", "MyFollowerController.Kv=0.05:0.8"]
    assert main([*argv, "--budget", "5", "--seeds", "1", "--duration", "20"]) == 0
    out = capsys.readouterr().out.splitlines()
    trials = [float(line.rsplit("worst ", 1)[1]) for line in out if line.startswith("  ")]
    assert len(trials) == 5
    assert out[-1].startswith("robust choice: MyFollowerController.Kv=")
    assert f"(worst {min(trials):.4g} over 4 contexts x 1 seed;" in out[-1]


@pytest.mark.parametrize(
    ("extra", "key"),
    [
        (["--range", "MyFollowerController.Kv=0.8:0.1"], "--range"),
        (["--range", "MyFollowerController.Kv=0.1:20"], "--range MyFollowerController.Kv"),
        (["--range", "Nope.Kv=0.1:0.2"], "--range Nope.Kv"),
        (["--range", "MyFollowerController.Kv=0.1:0.2", "--budget", "0"], "--budget"),
        (["--range", "MyFollowerController.Kv=0.1:0.2", "--alpha", "0"], "--alpha"),
        ([], "--range"),
    ],
)
def test_bad_input_is_one_line_exit_2(capsys, extra, key) -> None:
    assert main(["tune", str(FIXTURE / "sweep.yaml"), *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert key in err, err
