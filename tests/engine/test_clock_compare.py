"""``clock.seconds`` and ``clock.at_or_after``: the group steps' float of an instant and its
compare with a kept time, without Fraction's slow paths, must be ``float(t)`` and ``t >= then``
exactly, also where two times round to the same float."""

from __future__ import annotations

import random
from fractions import Fraction

from amsa_phys.engine.clock import at_or_after, exact, seconds


def _times() -> list[Fraction]:
    rng = random.Random(7)
    times = [Fraction(0), Fraction(1, 3), Fraction(2, 3), Fraction(10**20 + 1, 3)]
    times += [Fraction(rng.randrange(0, 10**6), rng.randrange(1, 10**4)) for _ in range(200)]
    # neighbours closer than a float's resolution: equal floats, unequal times
    times += [t + Fraction(1, 10**30) for t in times[:50]]
    times += [t - Fraction(1, 10**30) for t in times[1:50]]
    times += [exact(7, 4), exact(10**18 + 3, 10**9)]  # as the walk makes them
    return times


def test_seconds_is_float_to_the_bit() -> None:
    for t in _times():
        assert seconds(t).hex() == float(t).hex()
    assert seconds(2.5) == 2.5  # not a Fraction: float() as ever
    assert seconds(3) == 3.0


def test_at_or_after_is_the_exact_compare() -> None:
    times = _times()
    close = 0
    for t in times[:120] + times[-60:]:
        for then in times[:120] + times[-60:]:
            assert at_or_after(t, then, float(then)) is (t >= then), (t, then)
            close += t != then and float(t) == float(then)
    assert close > 0  # the float alone could not have decided those
