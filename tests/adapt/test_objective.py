"""Objectives: a plain metric is lower-is-better, ``robustness.NAME`` higher-is-better, in
``tune`` (``objective_value``) and in ``adapt`` (a results.csv column of that name)."""

from __future__ import annotations

import math
from pathlib import Path

from amsa_phys.adapt.derive import derive
from amsa_phys.model.scenario import load_scenario
from amsa_phys.tune.objective import objective_value
from amsa_phys.tune.robust import tail

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "adapt"


def test_objective_value_reads_metrics_phases_and_robustness() -> None:
    metrics = {
        "overall": {"rms_error": 0.5, "settling_time": None},
        "phases": [{"rms_error": 0.25}, {"rms_error": math.inf}],
        "requirements": {"keep": {"robustness": -0.3, "verdict": "violated"}},
    }
    assert objective_value(metrics, "rms_error") == (0.5, False)
    assert objective_value(metrics, "phase0.rms_error") == (0.25, False)
    assert objective_value(metrics, "phase1.rms_error") == (None, False)  # not finite
    assert objective_value(metrics, "phase7.rms_error") == (None, False)
    assert objective_value(metrics, "settling_time") == (None, False)
    assert objective_value(metrics, "robustness.keep") == (-0.3, True)
    assert objective_value(metrics, "robustness.other") == (None, True)


def test_tail_measures() -> None:
    values = [1.0, 5.0, 2.0, 3.0, 4.0]
    assert tail(values, "worst") == 5.0
    assert tail(values, "cvar", 0.4) == 4.5  # the mean of the two worst
    assert tail(values, "cvar", 0.01) == 5.0  # at least one
    assert tail([1.0, None], "worst") == math.inf


def test_adapt_maximises_a_robustness_column(tmp_path: Path) -> None:
    """The fixture's rms as a robustness (its negative): the same cells win, highest first."""
    lines = (FIXTURE / "results.csv").read_text().splitlines()
    header = lines[0].replace("rms_error", "robustness.keep")
    rows = []
    for line in lines[1:]:
        cells = line.split(",")
        cells[6] = str(-float(cells[6]))
        rows.append(",".join(cells))
    path = tmp_path / "results.csv"
    path.write_text("\n".join([header, *rows]) + "\n")
    scenario = load_scenario(FIXTURE / "sweep.yaml")
    found = derive(path, scenario, "robustness.keep", 5, float("inf"), 0.0)
    best = {c.name: c.best["MyFollowerController.Kv"] for c in found.cells}
    assert best == {"nominal": 0.2, "worn": 0.4, "random": 0.4, "speed changes": 0.1}
    assert found.robust == {"MyFollowerController.Kv": 0.2}
    assert found.gain > 0.3
