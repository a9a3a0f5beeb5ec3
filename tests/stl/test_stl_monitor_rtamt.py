"""The numpy STL monitor against rtamt itself, on random formulas over recorded traces.

rtamt (the reference implementation most STL users know) evaluates one run at a time; our
monitor evaluates a batch of runs as columns. Both must give the same robustness at every
sample, to 1e-9, for every operator with and without intervals.
"""

from __future__ import annotations

import random
import re
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.stl.monitor import evaluate
from amsa_phys.stl.syntax import parse

rtamt = pytest.importorskip("rtamt")

GOLDEN = Path(__file__).resolve().parents[1] / "golden"
PERIOD = Fraction(1, 4)  # the golden traces are logged at 4 Hz
SIGNALS = [
    "MyDistanceMonitor.distanceFollowerToLeader",
    "Follower.speed",
    "Follower.heading",
    "MyFollowerController.LeftPower",
    "t",
]


def _traces() -> dict[str, np.ndarray]:
    """The two golden traces as one batch: a (samples, 2) column per signal."""
    out: dict[str, list[np.ndarray]] = {s: [] for s in SIGNALS}
    for name in ("golden_nominal.csv", "golden_degraded.csv"):
        header = (GOLDEN / name).read_text().splitlines()[0].split(",")
        data = np.loadtxt(GOLDEN / name, delimiter=",", skiprows=1, ndmin=2)
        for s in SIGNALS:
            out[s].append(data[:, header.index(s)])
    return {s: np.stack(v, axis=1) for s, v in out.items()}


def _interval(rng: random.Random) -> str:
    lo = rng.randint(0, 12) * 0.25
    hi = lo + rng.randint(0, 24) * 0.25
    return f"[{lo:g}:{hi:g}]"


def _atom(rng: random.Random) -> str:
    s = rng.choice(SIGNALS)
    c = round(rng.uniform(-20, 40), 2)
    kind = rng.randrange(4)
    if kind == 0:
        return f"(abs({s} - {c}) <= {abs(c) / 4 + 1:g})"
    if kind == 1:
        return f"({s} {rng.choice(['<', '<=', '>', '>='])} {c})"
    if kind == 2:
        s2 = rng.choice(SIGNALS)
        return f"(({s} + {s2} * 0.5) >= {c})"
    return f"({s} {rng.choice(['==', '!=='])} {c})"


def _formula(rng: random.Random, depth: int) -> str:
    if depth == 0 or rng.random() < 0.2:
        return _atom(rng)
    k = rng.randrange(12)
    a = _formula(rng, depth - 1)
    if k < 4:
        op = ["always", "eventually", "historically", "once"][k]
        bounded = rng.random() < 0.75
        return f"({op}{_interval(rng) if bounded else ''}({a}))"
    if k == 4:
        return f"(not({a}))"
    b = _formula(rng, depth - 1)
    if k in (5, 6):
        op = ["until", "since"][k - 5]
        bounded = rng.random() < 0.75
        return f"(({a}) {op}{_interval(rng) if bounded else ''} ({b}))"
    op = ["and", "or", "implies", "iff", "xor"][k - 7]
    return f"(({a}) {op} ({b}))"


def _rtamt(formula: str, columns: dict[str, np.ndarray]) -> np.ndarray:
    """rtamt's robustness at every sample (its names cannot hold dots: they are fields)."""
    spec = rtamt.StlDiscreteTimeOfflineSpecification()
    renamed = formula
    dataset: dict[str, list[float]] = {"time": [float(x) for x in columns["t"]]}
    for i, s in enumerate(sorted(SIGNALS, key=len, reverse=True)):
        var = f"v{i}"
        renamed = re.sub(rf"(?<![\w.]){re.escape(s)}(?![\w.])", var, renamed)
        spec.declare_var(var, "float")
        dataset[var] = [float(x) for x in columns[s]]
    spec.spec = renamed
    spec.set_sampling_period(float(PERIOD), "s", 0.01)
    spec.parse()
    return np.array([v for _, v in spec.evaluate(dataset)], dtype=float)


def test_random_formulas_agree_with_rtamt_at_every_sample() -> None:
    traces = _traces()
    rng = random.Random(20260428)
    for _ in range(120):
        formula = _formula(rng, rng.randint(1, 4))
        ours = evaluate(parse(formula), traces, PERIOD)
        got = ours.values[id(ours.root)]
        for run in range(2):
            want = _rtamt(formula, {s: v[:, run] for s, v in traces.items()})
            np.testing.assert_allclose(got[:, run], want, rtol=0, atol=1e-9, err_msg=formula)


def test_windows_that_reach_past_the_end_agree_with_rtamt() -> None:
    """The last samples' windows are cut at the run's end, as rtamt cuts them."""
    traces = _traces()
    for formula in (
        "always[0:39](Follower.speed > 0.1)",
        "eventually[30:45](Follower.speed > 0.5)",
        "(Follower.speed > 0.2) until[1:41] (t > 38)",
        "historically[1:45](Follower.speed >= 0)",
        "(Follower.speed > 0) since[0:42.5] (t < 1)",
    ):
        ev = evaluate(parse(formula), traces, PERIOD)
        want = _rtamt(formula, {s: v[:, 0] for s, v in traces.items()})
        np.testing.assert_allclose(ev.values[id(ev.root)][:, 0], want, rtol=0, atol=1e-9)
