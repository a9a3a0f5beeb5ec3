"""The one function that turns (metrics, objective name) into (value, higher_is_better)."""

from __future__ import annotations

import pytest

from amsa_phys.requirements.objective import objective_value, unknown_objective

METRICS_JSON = {
    "overall": {"rms_error": 1.25, "settling_time": None},
    "phases": [{"rms_error": 0.5}, {"rms_error": 2.0}],
    "requirements": {
        "band": {
            "formula": "always(x <= 1)",
            "robustness": -0.75,
            "verdict": "fail",
            "instant": 3.0,
        }
    },
}


def test_metrics_json_and_flat_row_give_the_same_value_and_sense() -> None:
    row = {"rms_error": "1.25", "phase1.rms_error": 2.0, "robustness.band": "-0.75"}
    for doc in (METRICS_JSON, row):
        assert objective_value(doc, "rms_error") == (1.25, False)
        assert objective_value(doc, "phase1.rms_error") == (2.0, False)
        assert objective_value(doc, "robustness.band") == (-0.75, True)


def test_missing_values_are_none_never_zero() -> None:
    assert objective_value(METRICS_JSON, "settling_time") == (None, False)
    assert objective_value(METRICS_JSON, "phase5.rms_error") == (None, False)
    assert objective_value(METRICS_JSON, "robustness.other") == (None, True)
    assert objective_value({"rms_error": ""}, "rms_error") == (None, False)


def test_unknown_names() -> None:
    with pytest.raises(KeyError):
        objective_value(METRICS_JSON, "rms_eror")
    assert unknown_objective("robustness.band", 2, ["band"]) is None
    assert unknown_objective("phase1.rms_error", 2, []) is None
    why = unknown_objective("robustness.bnad", 2, ["band"])
    assert why is not None
    assert "did you mean band?" in why
    why = unknown_objective("phase2.rms_error", 2, ["band"])
    assert why is not None
    assert "unknown objective" in why
