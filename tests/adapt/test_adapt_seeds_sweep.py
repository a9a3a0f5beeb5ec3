"""benchmarks.adapt_seeds --sweep, and the finer sweep's committed rules.

``--sweep scenarios/adaptive_sweep_fine.yaml`` scores the rules derived from another swept
scenario on the same held-out draws. These tests cover what a user types (a file that is not
an adaptive sweep, a sweep output of another scenario, ``--set`` beside it), that the docs'
block names the sweep, and (slow) that the committed ``adaptive_rules_fine.yaml`` is what
``amsa-phys adapt`` derives from a sweep of the committed file.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from benchmarks import adapt_seeds
from benchmarks.adapt_seeds import SpecError, check_sweep_contexts, markdown, sweep_key

ROOT = Path(__file__).resolve().parents[2]
FINE = ROOT / "scenarios" / "adaptive_sweep_fine.yaml"
FINE_RULES = ROOT / "scenarios" / "rules" / "adaptive_rules_fine.yaml"


def test_the_key_names_the_results_file() -> None:
    assert sweep_key(FINE) == "fine"


@pytest.mark.parametrize(
    ("name", "says"),
    [
        ("adaptive_sweep.yaml", "expected scenarios/adaptive_sweep_NAME.yaml"),
        ("adaptive_sweep_Fine!.yaml", "expected scenarios/adaptive_sweep_NAME.yaml"),
        ("my_sweep.yaml", "expected scenarios/adaptive_sweep_NAME.yaml"),
        ("adaptive_sweep_none.yaml", "no such file"),
    ],
)
def test_a_file_that_is_not_an_adaptive_sweep_says_why(name: str, says: str) -> None:
    with pytest.raises(SpecError, match=r"^--sweep:") as e:
        sweep_key(ROOT / "scenarios" / name)
    assert says in str(e.value)


def _sweepdir(tmp_path: Path, contexts: dict) -> Path:
    data = {"duration": 200, "sweep": {"contexts": contexts}}
    (tmp_path / "scenario.yaml").write_text(yaml.safe_dump(data))
    (tmp_path / "results.csv").write_text("run\n")
    return tmp_path


def test_the_output_must_be_the_swept_scenarios(tmp_path: Path) -> None:
    from amsa_phys.cli.adapt import load_scenario

    fine = load_scenario(str(FINE))
    shipped = load_scenario(str(adapt_seeds.SWEEP))
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    check_sweep_contexts(_sweepdir(tmp_path / "a", fine.data["sweep"]["contexts"]), fine)
    with pytest.raises(SpecError, match=r"contexts differ .*part-worn motors"):
        check_sweep_contexts(_sweepdir(tmp_path / "b", shipped.data["sweep"]["contexts"]), fine)


@pytest.mark.parametrize(
    ("extra", "says"),
    [
        (["--sweep", "scenarios/adaptive_sweep.yaml"], "expected scenarios/adaptive_sweep_NAME"),
        (["--sweep", str(FINE), "--set", "MyFollowerController.Kw=0.1"], "one at a time"),
        (["--sweep", str(FINE)], "contexts differ"),
    ],
)
def test_cli_errors_are_one_line_exit_2_and_write_nothing(
    tmp_path, capsys, monkeypatch, extra, says
) -> None:
    out = tmp_path / "adapt_seeds.json"
    monkeypatch.setattr(adapt_seeds, "OUT", out)
    from amsa_phys.cli.adapt import load_scenario

    shipped = load_scenario(str(adapt_seeds.SWEEP)).data["sweep"]["contexts"]
    (tmp_path / "sweep").mkdir()
    sweep = _sweepdir(tmp_path / "sweep", shipped)
    code = adapt_seeds.main([str(sweep), "--seeds", "1", *extra])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1
    assert err.startswith("adapt_seeds: ")
    assert says in err
    assert "Traceback" not in err
    assert not list(tmp_path.glob("adapt_seeds*.json"))


def test_the_block_names_the_sweep() -> None:
    doc = {
        "seeds": [1, 2, 3],
        "command": "python -m benchmarks.adapt_seeds DIR --sweep "
        "scenarios/adaptive_sweep_fine.yaml",
        "draws": [],
        "load": [1.0, 1.0, 1.0],
        "date": "2026-11-29T17:00:00+00:00",
        "sweep": "scenarios/adaptive_sweep_fine.yaml",
    }
    text = markdown(doc)
    assert "*Rules derived from `scenarios/adaptive_sweep_fine.yaml` vs the robust Kv 0.2" in text
    assert "--sweep scenarios/adaptive_sweep_fine.yaml`" in text


@pytest.mark.slow
def test_the_committed_fine_rules_are_the_fine_sweeps(tmp_path: Path) -> None:
    """Sweep the committed file, derive as the docs say: the committed rules, rule for rule
    (a change to the dynamics or to the derivation shows here first)."""
    from amsa_phys.adapt.derive import derive
    from amsa_phys.cli.adapt import load_scenario
    from amsa_phys.cli.main import main

    out = tmp_path / "sweep"
    assert main(["sweep", str(FINE), "--out", str(out), "--executor", "batch"]) == 0
    found = derive(out / "results.csv", load_scenario(str(FINE)))
    committed = yaml.safe_load(FINE_RULES.read_text())["adapt"]
    assert found.rules == committed
    labels = [r["label"] for r in committed]
    # the finer cells have rules of their own: measured between the coarser levels
    assert "part-worn motors" in labels
    assert "part-worn, random leader" in labels


def test_the_block_names_the_robust_point_the_rules_fall_back_on() -> None:
    """A sweep run with another setting may have another robust point: the caption says the
    one the scored rules fall back on, not the shipped rules' Kv 0.2."""
    doc = {
        "seeds": [1, 2],
        "command": "python -m benchmarks.adapt_seeds DIR --set MyFollowerController.Kff=1",
        "draws": [],
        "load": [1.0, 1.0, 1.0],
        "date": "2026-11-29T17:00:00+00:00",
        "set": {"MyFollowerController.Kff": 1.0},
        "rules": [
            {"when": {}, "set": {"MyFollowerController.Kv": 0.05}, "label": "damp, swinging"},
            {"when": {}, "set": {"MyFollowerController.Kv": 0.15}, "label": "robust, unsure"},
        ],
    }
    text = markdown(doc)
    assert "vs the robust Kv 0.15, every way with MyFollowerController.Kff 1" in text
    assert "Kv 0.2" not in text
