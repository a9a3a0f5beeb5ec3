"""benchmarks.adapt_seeds: its options' errors, the stall it counts, the seed statistics.

The full benchmark runs thousands of 600 s cases; these tests cover what a user types
(``--seeds``, ``--draws``, a missing sweep) and what the docs' figures are computed from
(the stall spells, the paired standard error, the per-draw counts over a subset of seeds).
"""

from __future__ import annotations

import math
import statistics

import pytest
from refusal import assert_one_line_refusal

from benchmarks import adapt_seeds
from benchmarks.adapt_seeds import (
    SpecError,
    parse_draws,
    parse_seeds,
    stalls,
    stats,
    summary,
)


def test_seeds_count_range_and_list() -> None:
    assert parse_seeds("10") == list(range(1, 11))
    assert parse_seeds("1-3") == [1, 2, 3]
    assert parse_seeds("7,1-3") == [1, 2, 3, 7]  # order given does not matter: sorted


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("", "empty"),
        ("0", "1 to 1000"),
        ("3-1", "A <= B"),
        ("0-2", "seeds from 1"),
        ("1,x", "'x'"),
        ("1-3,2", "seed 2 given twice"),
        ("-3", "'-3'"),
    ],
)
def test_bad_seeds_say_why(text: str, says: str) -> None:
    with pytest.raises(SpecError) as e:
        parse_seeds(text)
    assert str(e.value).startswith("--seeds:")
    assert says in str(e.value)


@pytest.mark.parametrize("text", ["4000", "4000:0", "a:3", "4000:3,4000:5", "4000:3:1"])
def test_bad_draws_say_why(text: str) -> None:
    with pytest.raises(SpecError, match=r"^--draws:"):
        parse_draws(text)


def test_draws_parse() -> None:
    assert parse_draws("4000:30, 5000:2") == [(4000, 30), (5000, 2)]


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["--seeds", "3-1"], "--seeds:"),
        (["--draws", "4000"], "--draws:"),
        ([], "no such file"),
    ],
)
def test_cli_errors_are_one_line_exit_2(tmp_path, capsys, argv, says) -> None:
    # the sweep dir is empty: a bad option is reported before it is read
    code = adapt_seeds.main([str(tmp_path), *argv])
    assert_one_line_refusal(code, capsys.readouterr().err, says, "adapt_seeds: ")


def _trace(spec: list[tuple[float, float, float]], dt: float = 0.25):
    """(t, speed, distance) sampled every dt from (duration, speed, distance) pieces."""
    t, v, d = [], [], []
    now = 0.0
    for duration, speed, distance in spec:
        for _ in range(round(duration / dt)):
            t.append(now)
            v.append(speed)
            d.append(distance)
            now += dt
    return t, v, d


def test_a_long_slow_spell_far_behind_is_a_stall() -> None:
    t, v, d = _trace([(50, 1.0, 15), (30, 0.01, 25), (50, 1.0, 15)])
    (spell,) = stalls(t, v, d)
    assert spell[0] == pytest.approx(50)
    assert spell[1] - spell[0] == pytest.approx(29.75)


def test_a_stall_at_the_end_of_the_run_counts() -> None:
    t, v, d = _trace([(50, 1.0, 15), (25, -0.02, 22)])  # reversing slowly counts as slow
    assert len(stalls(t, v, d)) == 1


@pytest.mark.parametrize(
    "spec",
    [
        [(50, 1.0, 15), (15, 0.01, 25), (50, 1.0, 15)],  # too short
        [(50, 1.0, 15), (30, 0.01, 18), (50, 1.0, 15)],  # standing, but near its reference
        [(50, 1.0, 15), (30, 0.2, 25), (50, 1.0, 15)],  # far behind, but driving
        [(50, 1.0, 15), (30, -0.5, 25), (50, 1.0, 15)],  # far behind, reversing
        [(12, 0.01, 25), (1, 0.01, 19), (12, 0.01, 25)],  # broken by a moment nearer
    ],
)
def test_no_stall(spec) -> None:
    assert stalls(*_trace(spec)) == []


def test_paired_standard_error() -> None:
    robust = [1.0, 2.0, 3.0, 2.0]
    rules = [1.1, 2.0, 3.3, 2.2]
    s = stats(robust, rules)
    assert s.change == pytest.approx(8.6 / 8.0 - 1.0)
    diffs = [0.1, 0.0, 0.3, 0.2]
    assert s.se == pytest.approx(statistics.stdev(diffs) / 2.0 / 2.0)
    # the same noise in both ways cancels: pairing by seed, not two unpaired spreads
    assert stats([1.0, 3.0, 5.0], [1.1, 3.1, 5.1]).se == pytest.approx(0.0, abs=1e-12)
    assert math.isinf(stats([1.0], [1.2]).se)
    assert math.isinf(stats([1.0, 1.0], [1.0, math.inf]).change)


def test_summary_over_a_subset_of_seeds() -> None:
    # seed 2 alone makes the rules lose on three seeds; ten seeds wash it out
    robust = [1.0] * 10
    rules = [0.95, 1.5, 0.95] + [0.93] * 7
    row = {"seeds": {"robust": robust, "rules": rules, "oracle": [0.8] * 10}}
    other = {"seeds": {"robust": robust, "rules": [0.85] * 10, "oracle": [0.85] * 10}}
    seeds = list(range(1, 11))
    few = summary([row, other], seeds, [1, 2, 3])
    many = summary([row, other], seeds, seeds)
    assert few["lost"] == [0]
    assert few["worst"] == pytest.approx(3.4 / 3 - 1)
    assert many["lost"] == []
    assert many["worst"] == pytest.approx((3.4 + 6.51) / 10 - 1)
    # the oracle gains 20 % on the first and 15 % on the second; the rules reach only the second
    assert (few["worth"], few["reached"]) == (2, 1)
    assert many["mean"] == pytest.approx((many["worst"] - 0.15) / 2)


def test_stall_cost_compares_seeds_of_the_same_sequence() -> None:
    spell = [[100.0, 140.0]]
    stalled_some = {"seeds": {"robust": [4.0, 1.0, 2.0]}, "stalls": {"robust": [spell, [], []]}}
    stalled_all = {"seeds": {"robust": [9.0, 9.0]}, "stalls": {"robust": [spell, spell]}}
    never = {"seeds": {"robust": [0.5, 0.5]}, "stalls": {"robust": [[], []]}}
    # a sequence stalled in every seed, or in none, has nothing to compare with: left out
    assert adapt_seeds.stall_cost([stalled_some, stalled_all, never]) == [(4.0, 1.5)]


def test_stall_contexts_are_the_segment_in_force_at_the_start() -> None:
    row = {
        "segments": [
            [0.0, {"Leader.behavior": 1, "MyNormalizePower.motorCoef": 80}],
            [200, {"Leader.behavior": 4, "MyNormalizePower.motorCoef": 30}],
        ],
        "stalls": {"robust": [[[150.0, 210.0]], [[250.0, 290.0], [400.0, 430.0]]]},
    }
    assert adapt_seeds.stall_contexts([row], "robust") == [(1, 80), (4, 30), (4, 30)]


def test_beyond_the_noise() -> None:
    changes = [
        [-0.10, 0.02],  # a gain five standard errors out
        [-0.03, 0.02],  # a gain within two
        [0.09, 0.03],  # a loss: 7 points above the 2 % bound, more than two (6 points)
        [0.07, 0.03],  # above the bound by 5 points: within two standard errors
        [0.30, 0.30],  # one wild seed: far above the bound, and noise
    ]
    assert adapt_seeds.beyond(changes) == (1, 1)


def test_stalled_both_counts_the_same_seed() -> None:
    spell = [[100.0, 140.0]]
    row = {"stalls": {"robust": [spell, spell, []], "rules": [spell, [], spell]}}
    assert adapt_seeds.stalled_both([row]) == 1


def test_verdict_counts_losses_and_the_noisy_ones() -> None:
    def row(rules: list[float]) -> dict:
        return {"seeds": {"robust": [1.0, 1.0, 1.0], "rules": rules, "oracle": [1.0] * 3}}

    rows = [
        row([1.033, 1.033, 1.034]),  # +3.3 %, every seed: a loss beyond the noise
        row([1.0, 1.6, 0.95]),  # +18 % from one seed: a loss within the noise
        row([1.016, 1.03, 1.044]),  # +3 % ± 0.8: a point over the bound, within two s.e.
        row([1.01, 1.01, 1.01]),  # +1 %: inside the bound
        row([0.8, 0.8, 0.8]),  # a gain
    ]
    doc = {"seeds": [1, 2, 3], "draws": [{"rows": rows[:3]}, {"rows": rows[3:]}]}
    assert adapt_seeds.verdict(doc) == (3, 2, 5)
