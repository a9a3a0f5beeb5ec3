"""The shipped rules' held-out validation, as docs/adaptation.md shows it, says they hold.

``scenarios/rules/adaptive_rules.validate.json`` is what ``amsa-phys adapt --validate
--results`` wrote for the shipped rules (the docs render their table from it). Regenerating
the rules after a change of the dynamics rewrites it; this test fails when the rules then
lose to the robust gain on a held-out sequence, or when the file no longer matches the rules
it claims to score, rather than letting the page show a losing table under a claim that they
hold.
"""

from __future__ import annotations

import json
from pathlib import Path

import yaml

from amsa_phys.adapt.validate import loses
from amsa_phys.tune.contexts import Sequence

ROOT = Path(__file__).resolve().parents[2]
RULES = ROOT / "scenarios" / "rules" / "adaptive_rules.yaml"
RESULTS = ROOT / "scenarios" / "rules" / "adaptive_rules.validate.json"


def _doc() -> dict:
    return json.loads(RESULTS.read_text())


def test_the_shipped_rules_never_lose_on_the_held_out_sequences() -> None:
    doc = _doc()
    tolerance = doc["settings"]["tolerance"]
    assert doc["settings"]["sequences"] == len(doc["rows"]) >= 20
    lost = [r["sequence"] for r in doc["rows"] if r["change"] > tolerance]
    assert not lost, f"the shipped rules lose to the robust gain on {lost}"
    # the same verdict as `adapt --validate`'s own (its exit status)
    rows = [_row(r) for r in doc["rows"]]
    assert loses(rows, tolerance) == []


def test_the_validation_scores_the_shipped_rules_robust_gain() -> None:
    rules = yaml.safe_load(RULES.read_text())["adapt"]
    fallbacks = [r for r in rules if str(r.get("label", "")).startswith("robust")]
    assert fallbacks, "the shipped rules have no fallback to the robust gain"
    assert all(r["set"] == _doc()["robust"] for r in fallbacks)


def _row(r: dict):
    from amsa_phys.adapt.validate import Row

    segments = tuple((at, sets) for at, sets in r["segments"])
    return Row(Sequence(segments), r["robust"], r["oracle"], r["rules"])
