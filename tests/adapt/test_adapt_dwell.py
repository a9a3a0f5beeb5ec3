"""A rule's ``dwell``: the least time since the last switch before it may fire.

A fallback to the robust gain must not undo a switch while the estimate's window still
holds the transient that switch caused; it waits ``dwell`` seconds after any switch, yet
still reacts within ``hold`` seconds of unsureness once that time has passed.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import yaml

from amsa_phys.cli.main import main
from amsa_phys.engine.adapt import AdaptRules
from amsa_phys.model.adaptrules import Condition, Rule, describe_rules, written_rules
from amsa_phys.model.scenario import Change, load_scenario

ROOT = Path(__file__).resolve().parents[2]
WORLD = str(ROOT / "worlds" / "mde_adaptive.yaml")


def _fire(rules: AdaptRules, signal: list[float], params: dict) -> list[tuple[Fraction, int]]:
    """Evaluate at 4 Hz, applying each firing's changes as the engine does."""
    fired = []
    for k, x in enumerate(signal):
        f = rules.due(Fraction(k, 4), {"S.x": x})
        if f is not None:
            fired.append((f.t, f.rule.number))
            params.update({c.param: c.value for c in f.rule.changes})
    return fired


def _pair(dwell: Fraction | None) -> tuple[list[Rule], dict]:
    """Rule 1 (a cell) sets Kv 0.6 when S.x > 0.5; rule 2 (a fallback) Kv 0.2 when below."""
    cell = Rule(1, (Condition("S.x", above=0.5),), (Change("C", "Kv", 0.6),), Fraction(2))
    fallback = Rule(
        2, (Condition("S.x", below=0.5),), (Change("C", "Kv", 0.2),), Fraction(2), "", dwell
    )
    return [cell, fallback], {"Kv": 0.2}


def test_a_fallback_waits_its_dwell_after_a_switch_then_its_hold_alone() -> None:
    # sure (1) for 3 s: the cell rule fires at 2 s; unsure (0) from 3 s on
    signal = [1.0] * 12 + [0.0] * 80
    rules, params = _pair(Fraction(10))
    fired = _fire(AdaptRules(rules, lambda leaf, p: params[p]), signal, params)
    # unsure for the hold (2 s) by 5 s, but not before 10 s after the switch at 2 s
    assert fired == [(Fraction(2), 1), (Fraction(12), 2)]
    # without a dwell the hold is the least gap: the fallback undoes the switch at 5 s
    rules, params = _pair(None)
    fired = _fire(AdaptRules(rules, lambda leaf, p: params[p]), signal, params)
    assert fired == [(Fraction(2), 1), (Fraction(5), 2)]


def test_a_dwell_does_not_delay_a_fallback_long_after_the_last_switch() -> None:
    # the switch at 2 s; sure until 20 s, unsure from 20 s: the fallback fires at 22 s
    signal = [1.0] * 80 + [0.0] * 20
    rules, params = _pair(Fraction(10))
    fired = _fire(AdaptRules(rules, lambda leaf, p: params[p]), signal, params)
    assert fired == [(Fraction(2), 1), (Fraction(22), 2)]


def _scenario(rules: list[dict]) -> dict:
    return {"world": WORLD, "duration": 5, "adapt": rules}


FALLBACK = {
    "when": {"MotorMonitor.valid": {"below": 0.5}},
    "set": {"MyFollowerController.Kv": 0.2},
    "hold": 10,
    "dwell": 30,
    "label": "robust",
}


def test_a_dwell_loads_is_described_and_written_back(tmp_path: Path, capsys) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(_scenario([FALLBACK])))
    scenario = load_scenario(path)
    assert scenario.adapt[0].dwell == 30
    # the resolved scenario.yaml keeps it, so its replay switches at the same instants
    assert written_rules(scenario.adapt) == [FALLBACK]
    assert describe_rules(scenario.adapt) == [
        "rule 1 (robust): when MotorMonitor.valid < 0.5 for 10 s, 30 s after a switch: "
        "set MyFollowerController.Kv=0.2"
    ]
    # no dwell written: none read back (the hold is the least gap, as before)
    plain = {k: v for k, v in FALLBACK.items() if k != "dwell"}
    path.write_text(yaml.safe_dump(_scenario([plain])))
    assert written_rules(load_scenario(path).adapt) == [plain]


def test_a_negative_dwell_is_a_one_line_error(tmp_path: Path, capsys) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(_scenario([{**FALLBACK, "dwell": -1}])))
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith(f"error: {path}:"), err
    assert "dwell" in err, err


def test_derived_fallbacks_wait_the_estimators_window_unless_told() -> None:
    """Default: the estimator's window (30 s); ``fallback_dwell`` replaces it, and a dwell
    no longer than the hold is left out (the hold is the least gap anyway)."""
    from amsa_phys.adapt.derive import derive

    fixture = ROOT / "tests" / "fixtures" / "adapt"
    scenario = load_scenario(fixture / "sweep.yaml")

    def dwells(**kw: float) -> list:
        found = derive(fixture / "results.csv", scenario, "rms_error", 5, float("inf"), 0.0, **kw)
        return [r.get("dwell") for r in found.rules if r["label"].startswith("robust")]

    assert dwells() == [30, 30]
    assert dwells(fallback_dwell=45) == [45, 45]
    assert dwells(fallback_dwell=5) == [None, None]
