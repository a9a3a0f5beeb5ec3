"""The instants' exact times (``clock.exact``) are the very Fractions the constructor makes."""

from __future__ import annotations

import random
from fractions import Fraction

from amsa_phys.engine.clock import exact


def test_exact_is_the_reduced_fraction_the_constructor_makes() -> None:
    rng = random.Random(7)
    cases = [(0, 1), (0, 200), (5, 5), (6, 4), (2**70 + 3, 2**40), (10**12, 7)]
    cases += [(rng.randrange(10**12), rng.randrange(1, 10**6)) for _ in range(20_000)]
    for n, d in cases:
        made, reference = exact(n, d), Fraction(n, d)
        assert type(made) is Fraction
        assert (made.numerator, made.denominator) == (reference.numerator, reference.denominator)
        assert made == reference
        assert hash(made) == hash(reference)
        assert float(made) == float(reference)
        assert str(made) == str(reference)
