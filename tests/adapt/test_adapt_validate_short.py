"""Where the oracle gains, do the rules? A rule set that never switches never loses to the
robust choice either: ``adapt --validate`` also counts the sequences worth adapting on (the
oracle 10 % or more better) where the rules fall short of 10 %."""

from __future__ import annotations

from amsa_phys.adapt.validate import Row, short_of_oracle
from amsa_phys.tune.contexts import Sequence

SEQ = Sequence(((0.0, {"MyNormalizePower.motorCoef": 50}),))


def test_sequences_worth_adapting_on_and_those_the_rules_fall_short_on() -> None:
    rows = [
        Row(SEQ, robust=1.0, oracle=0.8, adaptive=0.85),  # worth it, rules deliver (15 %)
        Row(SEQ, robust=1.0, oracle=0.8, adaptive=0.95),  # worth it, rules short (5 %)
        Row(SEQ, robust=1.0, oracle=0.95, adaptive=1.0),  # oracle gains 5 %: not counted
        Row(SEQ, robust=1.0, oracle=0.8, adaptive=float("inf")),  # a fault is short
    ]
    worth, short = short_of_oracle(rows)
    assert worth == [rows[0], rows[1], rows[3]]
    assert short == [rows[1], rows[3]]
