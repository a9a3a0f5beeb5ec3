"""Space robustness of an STL formula over sampled traces, batched: one column per run.

The semantics are rtamt's discrete-time offline ones, sample by sample (a test checks this
module against rtamt on random formulas): with ``s`` a child's robustness over samples
``0..n-1`` and an interval ``[a, b]`` in samples,

* ``always[a:b] s`` at ``i`` is the least ``s[j]`` for ``j`` in ``[i+a, i+b]`` that the run
  logged (``+inf`` if none: nothing to violate); ``eventually`` the greatest (``-inf``);
* ``historically``/``once`` look back over ``[i-b, i-a]`` the same way;
* ``l until[a:b] r`` at ``i`` is the greatest over ``j`` in ``[i+a, i+b]`` of
  ``min(r[j], least l over [i, j-1])``; ``since`` its mirror in the past;
* ``x <= y`` is ``y - x``, ``x >= y`` is ``x - y`` (strict alike), ``==`` is ``-|x - y|``,
  ``not`` negates, ``and``/``or`` are min/max, ``implies`` is ``max(-l, r)``.

Why our own and not rtamt at run time: rtamt evaluates one run at a time in Python lists
(a sliding window costs a Python ``min`` per sample), so a sweep of a hundred runs would
spend longer monitoring than simulating; here every operator is a handful of numpy
operations over a ``(samples, runs)`` array (a window is a log2-depth min tree), so a
batched sweep or a falsification generation is judged in one pass. rtamt also pins its
ANTLR runtime, a dependency the simulator need not carry.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from .syntax import BINARY_TEMPORAL, UNARY_TEMPORAL, Node

Reduce = Callable[[np.ndarray, np.ndarray], np.ndarray]


class SamplingError(ValueError):
    """A time bound that is not a whole number of log periods."""


def samples(node: Node, period: Fraction) -> tuple[int, int | None]:
    """A temporal node's interval in samples (``hi`` None: unbounded)."""
    assert node.lo is not None or node.hi is None
    lo = Fraction(0) if node.lo is None else node.lo
    out = []
    for bound in (lo, node.hi):
        if bound is None:
            out.append(None)
            continue
        k = bound / period
        if k.denominator != 1:
            raise SamplingError(
                f"{node.op}{node.interval()}: {float(bound):g} s is not a multiple of the "
                f"log period {float(period):g} s (the run logs no sample there)"
            )
        out.append(int(k))
    return out[0], out[1]


def horizon(node: Node) -> tuple[Fraction, Fraction]:
    """How far past and future the formula reads from t = 0, in seconds: (past, future).

    Used to refuse a formula that needs samples after a run's end. An unbounded operator
    reads to the end of the run, whatever its length: it adds nothing.
    """
    past = future = Fraction(0)
    for a in node.args:
        p, f = horizon(a)
        past, future = max(past, p), max(future, f)
    if node.op in ("always", "eventually", "until") and node.hi is not None:
        future += node.hi
    if node.op in ("historically", "once", "since") and node.hi is not None:
        past += node.hi
    return past, future


def _window(s: np.ndarray, a: int, b: int | None, fill: float, fn: Reduce) -> np.ndarray:
    """``out[i] = fn`` of ``s[i+a .. i+b]`` (rows; past the end counts as ``fill``)."""
    n = s.shape[0]
    if b is None:  # a suffix reduction, shifted by a
        acc = fn.accumulate(s[::-1], axis=0)[::-1]  # type: ignore[attr-defined]
        out = np.full_like(s, fill)
        if a < n:
            out[: n - a] = acc[a:]
        return out
    dtype = np.result_type(s.dtype, np.float64)
    if a >= n:  # every window starts after the end: all ``fill`` (fn(fill, fill) is fill)
        return np.full(s.shape, fill, dtype=dtype)
    w = b - a + 1
    # x[i] = s[i + a] (``fill`` past the end), only as far as the last window reads:
    # n + w - 1 rows (the doubling below ends with m[w - k + n - 1] = fn of up to x[n + w
    # - 2]). Padding all b + 1 rows cost a 60 s batch of 250 runs ~10 MB of fill per
    # window of ``always[400:500]``, most of its judging time
    x = np.full((n + w - 1, *s.shape[1:]), fill, dtype=dtype)
    x[: n - a] = s[a:]
    m = x
    k = 1
    while 2 * k <= w:  # m[j] = fn of x[j .. j + 2k - 1]
        m = fn(m[:-k], m[k:])
        k *= 2
    return fn(m[:n], m[w - k : w - k + n])


def _past(s: np.ndarray, a: int, b: int | None, fill: float, fn: Reduce) -> np.ndarray:
    """``out[i] = fn`` of ``s[i-b .. i-a]`` (before the start counts as ``fill``)."""
    return _window(s[::-1], a, b, fill, fn)[::-1]


def _until(left: np.ndarray, right: np.ndarray, a: int, b: int | None) -> np.ndarray:
    """``left until[a:b] right`` (see the module's docstring)."""
    n = left.shape[0]
    if b is None:  # out[i] = max(right[i], min(left[i], out[i+1])) for i >= a, from the end
        base = np.empty_like(left)
        nxt = np.full(left.shape[1:], -np.inf)
        for i in range(n - 1, -1, -1):
            nxt = np.maximum(right[i], np.minimum(left[i], nxt))
            base[i] = nxt
        # with a > 0: the run of left over [i, i+a-1], then the untimed until from i+a
        if a == 0:
            return base
        held = _window(left, 0, a - 1, np.inf, np.minimum)
        later = _window(base, a, a, -np.inf, np.maximum)
        return np.minimum(held, later)
    pad = b + 1
    lp = np.concatenate([left, np.full((pad, *left.shape[1:]), np.inf)])
    rp = np.concatenate([right, np.full((pad, *right.shape[1:]), -np.inf)])
    out = np.full_like(left, -np.inf)
    held = _window(left, 0, a - 1, np.inf, np.minimum) if a > 0 else np.full_like(left, np.inf)
    for d in range(a, b + 1):
        out = np.maximum(out, np.minimum(rp[d : d + n], held))
        held = np.minimum(held, lp[d : d + n])
    return out


@dataclass
class Evaluation:
    """Every node's robustness over every sample: ``values[id(node)]`` is ``(samples, runs)``."""

    root: Node
    values: dict[int, np.ndarray]
    steps: dict[int, tuple[int, int | None]]

    @property
    def robustness(self) -> np.ndarray:
        """Each run's robustness at t = 0 (one value per column)."""
        return self.values[id(self.root)][0]


def evaluate(node: Node, signals: Mapping[str, np.ndarray], period: Fraction) -> Evaluation:
    """The robustness of ``node`` over ``signals`` (each ``(samples,)`` or ``(samples, runs)``,
    sampled every ``period`` seconds from t = 0)."""
    values: dict[int, np.ndarray] = {}
    steps: dict[int, tuple[int, int | None]] = {}
    cols = {k: np.asarray(v, dtype=float) for k, v in signals.items()}
    cols = {k: v[:, None] if v.ndim == 1 else v for k, v in cols.items()}
    shape = next(iter(cols.values())).shape if cols else (1, 1)

    def ev(n: Node) -> np.ndarray:
        op = n.op
        if op == "num":
            out = np.full(shape, n.value)
        elif op == "sig":
            out = cols[n.name]
        elif op == "neg":
            out = -ev(n.args[0])
        elif op in ("abs", "not"):
            x = ev(n.args[0])
            out = np.abs(x) if op == "abs" else -x
        elif op in UNARY_TEMPORAL:
            x = ev(n.args[0])
            a, b = steps.setdefault(id(n), samples(n, period))
            if op == "always":
                out = _window(x, a, b, np.inf, np.minimum)
            elif op == "eventually":
                out = _window(x, a, b, -np.inf, np.maximum)
            elif op == "historically":
                out = _past(x, a, b, np.inf, np.minimum)
            else:
                out = _past(x, a, b, -np.inf, np.maximum)
        elif op in BINARY_TEMPORAL:
            x, y = ev(n.args[0]), ev(n.args[1])
            a, b = steps.setdefault(id(n), samples(n, period))
            if op == "since":  # the past mirror of until
                x, y = x[::-1], y[::-1]
            out = _until(x, y, a, b)
            if op == "since":
                out = out[::-1]
        else:
            x, y = ev(n.args[0]), ev(n.args[1])
            out = _BINARY[op](x, y)
        values[id(n)] = out
        return out

    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # inf - inf: NaN
        ev(node)
    return Evaluation(node, values, steps)


_BINARY: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {
    "+": np.add,
    "-": np.subtract,
    "*": np.multiply,
    "/": np.divide,
    "<": lambda x, y: y - x,
    "<=": lambda x, y: y - x,
    ">": lambda x, y: x - y,
    ">=": lambda x, y: x - y,
    "==": lambda x, y: -np.abs(x - y),
    "!==": lambda x, y: np.abs(x - y),
    "and": np.minimum,
    "or": np.maximum,
    "implies": lambda x, y: np.maximum(-x, y),
    "iff": lambda x, y: -np.abs(x - y),
    "xor": lambda x, y: np.abs(x - y),
}


def explain(ev: Evaluation, run: int = 0) -> tuple[Node, int]:
    """The atomic comparison and the sample index that set run ``run``'s robustness at t = 0.

    Followed down the tree: ``and`` goes to its lesser operand, a window to the sample that
    was its extreme, ``until`` to the instant that set its value; the comparison reached is
    the part of the requirement a violation breaks, and its instant when.
    """
    node, i = ev.root, 0
    n = next(iter(ev.values.values())).shape[0]
    for _ in range(10_000):
        op = node.op
        val = ev.values[id(node)][i, run]
        if op in ("not",):
            node = node.args[0]
            continue
        if op in ("and", "or", "implies", "iff", "xor"):
            x = ev.values[id(node.args[0])][i, run]
            x = -x if op == "implies" else x
            node = node.args[0] if x == val else node.args[1]
            continue
        if op in UNARY_TEMPORAL:
            a, b = ev.steps[id(node)]
            child = ev.values[id(node.args[0])][:, run]
            if op in ("always", "eventually"):
                lo, hi = i + a, n - 1 if b is None else min(n - 1, i + b)
            else:
                lo, hi = 0 if b is None else max(0, i - b), i - a
            if lo > hi:
                return node, i
            seg = child[lo : hi + 1]
            k = int(np.argmin(seg) if op in ("always", "historically") else np.argmax(seg))
            node, i = node.args[0], lo + k
            continue
        if op in BINARY_TEMPORAL:
            node, i = _explain_until(ev, node, i, run, val)
            continue
        return node, i
    return node, i


def _explain_until(ev: Evaluation, node: Node, i: int, run: int, val: float) -> tuple[Node, int]:
    """The operand and instant that set ``until``/``since`` at sample ``i``: the first
    instant ``j`` of the window whose ``min(right[j], least left in between)`` is the value."""
    left = ev.values[id(node.args[0])][:, run]
    right = ev.values[id(node.args[1])][:, run]
    a, b = ev.steps[id(node)]
    n = left.shape[0]
    future = node.op == "until"
    last = n - 1 if b is None else b
    for d in range(a, last + 1):
        j = i + d if future else i - d
        if not 0 <= j < n:
            break
        between = left[i:j] if future else left[j + 1 : i + 1]
        held = float(between.min()) if between.size else np.inf
        if min(right[j], held) == val:
            if right[j] <= held:
                return node.args[1], j
            k = int(np.argmin(between))
            return node.args[0], (i + k) if future else (j + 1 + k)
    return node, i
