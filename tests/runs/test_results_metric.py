"""The one-line refusal of a metric name (`sweep`, `plot` and `falsify --metric`)."""

from __future__ import annotations

import pytest

from amsa_phys.runs.results import unknown_metric


@pytest.mark.parametrize(
    ("name", "meant"),
    [
        ("max_after", "max_after_approach"),  # the table's column is `max after`
        ("rms_eror", "rms_error"),
        ("phase0.rms_eror", "phase0.rms_error"),
        ("Collisions", "collisions"),
    ],
)
def test_a_misspelt_metric_gets_the_nearest_name(name: str, meant: str) -> None:
    why = unknown_metric(name, 2)
    assert why is not None
    assert why.startswith(f"unknown metric {name!r} (did you mean {meant}?); known: ")


def test_a_phase_the_runs_do_not_reach_is_not_called_a_typo() -> None:
    why = unknown_metric("phase1.rms_error", 1)
    assert why is not None
    assert "did you mean" not in why
    assert why.endswith("; or phase0.<metric>")


def test_a_known_column_is_accepted() -> None:
    assert unknown_metric("phase1.max_after_approach", 2) is None
    assert unknown_metric("max_after_approach", 0) is None
