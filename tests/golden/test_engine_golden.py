"""Shipped scenarios against the traces stored per pymunk version (``engine_golden.py``)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from engine_golden import (
    TOLERANCE_M,
    largest_position_difference,
    load,
    pymunk_version,
    scenarios,
    simulate,
    stored_versions,
)

SHIPPED = scenarios()


@pytest.mark.parametrize("scenario", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_shipped_scenario_matches_the_trace_of_its_pymunk(scenario: Path) -> None:
    versions = stored_versions()
    assert versions, "no engine golden traces: python tests/golden/regenerate.py --engine"
    mine = pymunk_version()
    ref = mine if mine in versions else versions[-1]
    diff, where = largest_position_difference(load(ref, scenario), simulate(scenario))
    report = f"{scenario.stem}: pymunk {mine} against {ref}'s trace: largest |Δ| {diff:.3g} m"
    if ref != mine:  # an upgrade: say what it moved even when within the tolerance
        warnings.warn(report + (f" ({where})" if where else ""), stacklevel=1)
    assert diff <= TOLERANCE_M, report + f" in {where}, above {TOLERANCE_M:g} m"


def test_the_comparison_catches_a_moved_engine() -> None:
    """The check can fail: a trace moved by 1e-5 m in one position is reported and refused."""
    old = (["t", "A.posX", "A.speed"], np.array([[0.0, 1.0, 0.5], [0.1, 2.0, 0.5]]))
    moved = (old[0], old[1] + np.array([[0.0, 0.0, 1.0], [0.0, 1e-5, 1.0]]))
    diff, where = largest_position_difference(old, moved)
    assert where == "A.posX"
    assert diff == pytest.approx(1e-5)
    assert diff > TOLERANCE_M
    assert largest_position_difference(old, (old[0], old[1][:1]))[0] == float("inf")
