"""A batch's power commands in C (``_step.column_powers``) are the numpy rule they replace
(``ColumnPhysics.set_powers``: NaN to -100, clipped to ±100, 0 inside the deadband), to the
bit, on random commands and on every edge: NaN, infinities, -0.0, the limits, the band's
edges, rovers given in any order."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from amsa_phys.engine.multirun import MultiRun
from amsa_phys.model.scenario import load_scenario
from amsa_phys.physics import compiled
from amsa_phys.physics.columns import ColumnPhysics

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(
    not compiled.columns_compiled(), reason="the compiled step was not built (no C compiler)"
)


def _columns(runs: int) -> ColumnPhysics:
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=1)
    columns = ColumnPhysics()
    sim = MultiRun([scenario] * runs, columns=columns)
    sim.initialize()
    columns.index_of(columns.rovers)  # starts the model
    return columns


def test_the_c_rule_is_the_numpy_rule_bit_for_bit() -> None:
    columns = _columns(40)  # 80 rovers
    assert columns._powers is not None
    n = len(columns.rovers)
    band = columns._band
    rng = np.random.default_rng(11)
    edges = [np.nan, np.inf, -np.inf, -0.0, 0.0, 100.0, -100.0, 100.5, -1e300, 1e-300]
    b = float(band[0])
    edges += [b, -b, np.nextafter(b, 0), np.nextafter(-b, 0), np.nextafter(b, 200)]
    for trial in range(30):
        index = rng.permutation(n)[: rng.integers(1, n + 1)]
        m = len(index)
        left = rng.uniform(-150, 150, m)
        right = rng.normal(0, 3 * b + 1, m)
        take = rng.integers(0, len(edges), m)
        hit = rng.random(m) < 0.4
        left[hit] = np.array(edges)[take[hit]]
        right[~hit] = np.array(edges)[take[~hit]]
        before = rng.uniform(-50, 50, (2, n))
        columns._model.drives[...] = before
        columns.set_powers([], index, left, right)
        in_c = columns._model.drives.copy()
        powers, columns._powers = columns._powers, None
        try:
            columns._model.drives[...] = before
            columns.set_powers([], index, left, right)
            in_numpy = columns._model.drives.copy()
        finally:
            columns._powers = powers
        assert in_c.tobytes() == in_numpy.tobytes(), trial
        untouched = np.setdiff1d(np.arange(n), index)
        assert (in_c[:, untouched] == before[:, untouched]).all()


def test_bad_arrays_are_refused_not_written_past() -> None:
    from amsa_phys.physics.compiled import _step

    drives = np.zeros((2, 3))
    band = np.ones(3)
    one = np.ones(1)
    with pytest.raises(IndexError, match="out of range"):
        _step.column_powers(one, one, np.array([3]), band, drives)
    with pytest.raises(ValueError, match="one length"):
        _step.column_powers(np.ones(2), one, np.array([0]), band, drives)
    with pytest.raises(ValueError, match="float64"):
        _step.column_powers(one.astype(np.float32), one, np.array([0]), band, drives)
    assert not drives.any()
