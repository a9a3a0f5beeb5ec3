"""``benchmarks/adapt_case.py``: a draw's held-out sequence as a scenario file to trace.

The docs trace the rules' losses with it, so the file it writes must be the case
``--validate`` scores: its run's rms error is the seed's value in the validation, with the
rules and without them; a spell of another gain lands at the instants asked; a bad index
is one line and exit 2.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

import amsa_phys as ap
from amsa_phys.cli.adapt import load_scenario
from amsa_phys.tune.contexts import box, sequences
from amsa_phys.tune.evaluate import evaluate

ROOT = Path(__file__).resolve().parents[2]

from benchmarks import adapt_case  # noqa: E402

SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
RULES = ROOT / "scenarios" / "rules" / "adaptive_rules.yaml"


@pytest.mark.parametrize("robust", [False, True])
def test_the_case_runs_to_the_value_validate_scores(tmp_path: Path, robust: bool) -> None:
    out = tmp_path / "case.yaml"
    assert adapt_case.main(["4000", "12", "-o", str(out), *(["--robust"] if robust else [])]) == 0
    scenario = load_scenario(str(SWEEP))
    axes = box(scenario, dict(scenario.data["sweep"]["contexts"]))
    sequence = list(sequences(axes, 13, 600.0, 4000))[12]
    rules = None if robust else yaml.safe_load(RULES.read_text())["adapt"]
    kv = {"MyFollowerController.Kv": 0.2}
    scored = evaluate(scenario, sequence, kv, 3, "rms_error", 600.0, rules)
    run = ap.run(str(out), seed=3, trace_columns="MyDistanceMonitor.*")
    assert run.metrics["overall"]["rms_error"] == pytest.approx(scored, rel=1e-12)


def test_a_spell_of_another_gain_lands_where_asked(tmp_path: Path) -> None:
    out = tmp_path / "case.yaml"
    args = ["4000", "12", "-o", str(out), "--robust", "--set", "356.1:0.2", "--set", "326.1:0.3"]
    assert adapt_case.main(args) == 0
    data = yaml.safe_load(out.read_text())
    assert "adapt" not in data
    spells = [e for e in data["timeline"] if "MyFollowerController.Kv" in e["set"]]
    assert [(e["at"], e["set"]["MyFollowerController.Kv"]) for e in spells] == [
        (326.1, 0.3),
        (356.1, 0.2),
    ]
    # the spells sit among the sequence's own switches (88 s, 286 s), in time order
    assert [e["at"] for e in data["timeline"]] == [88, 286, 326.1, 356.1]


def test_a_bad_index_is_one_line_and_exit_2(tmp_path: Path, capsys) -> None:
    assert adapt_case.main(["4000", "-1", "-o", str(tmp_path / "c.yaml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "index" in err[0]
    assert not (tmp_path / "c.yaml").exists()
