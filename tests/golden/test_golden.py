"""Golden traces: reference runs compared column by column with stated tolerances.

Regenerate after an intended change with ``python tests/golden/regenerate.py``, which prints
what moved. Tolerances: the runs are deterministic, so on one platform they match exactly;
the tolerances only absorb last-bit differences of libm across platforms, amplified over
40 s of closed-loop motion (positions 1e-6 m, angles 1e-6 rad, powers 1e-4 %).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from regenerate import load, simulate

HERE = Path(__file__).resolve().parent
GOLDEN = sorted(HERE.glob("golden_*.yaml"))


def tolerance(column: str) -> float:
    if column.endswith(("Power", "PowerL", "PowerR")):
        return 1e-4
    return 1e-6


@pytest.mark.parametrize("scenario", GOLDEN, ids=[p.stem for p in GOLDEN])
def test_trace_matches_golden(scenario: Path) -> None:
    stored = scenario.with_suffix(".csv")
    assert stored.exists(), "missing golden trace: run python tests/golden/regenerate.py"
    h_old, old = load(stored)
    h_new, new = load(simulate(scenario))
    assert h_new == h_old
    assert new.shape == old.shape
    moved = [
        f"{name}: {np.abs(old[:, i] - new[:, i]).max():.3g}"
        for i, name in enumerate(h_new)
        if np.abs(old[:, i] - new[:, i]).max() > tolerance(name)
    ]
    assert not moved, "columns moved beyond tolerance (regenerate if intended): " + ", ".join(moved)
