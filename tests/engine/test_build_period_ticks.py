"""A task's period in ticks (``build.period_ticks``) is ``grid.ticks(1 / freq)`` exactly: the
same whole number of ticks on the grid, the same refusal off it."""

from __future__ import annotations

from fractions import Fraction

import pytest

from amsa_phys.engine.build import period_ticks
from amsa_phys.engine.clock import TickGrid

TICKS = [Fraction(1, 1000), Fraction(1, 300), Fraction(1, 7), Fraction(3, 1000), Fraction(1, 10)]
FREQS = [Fraction(f) for f in ("1", "10", "100", "3", "7", "20/3", "1/2", "1000", "333", "2.5")]


@pytest.mark.parametrize("tick", TICKS)
@pytest.mark.parametrize("freq", FREQS)
def test_period_ticks_is_the_grids_ticks_of_the_period(tick: Fraction, freq: Fraction) -> None:
    grid = TickGrid(tick)
    refusal = ""
    try:
        expected = grid.ticks(1 / freq)
    except ValueError as exc:
        refusal = str(exc)
    if refusal:
        with pytest.raises(ValueError, match="not on the tick grid") as got:
            period_ticks(grid, freq)
        assert str(got.value) == refusal
        return
    got_ticks = period_ticks(grid, freq)
    assert got_ticks == expected
    assert type(got_ticks) is int
