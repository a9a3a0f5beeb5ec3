"""A scenario's STL requirements: judged at load, evaluated on a run's (or a batch's) samples.

At load (:func:`check_formula`) a formula is refused, one line, if it does not parse, names a
signal the world does not have (with a did-you-mean), or needs samples a run never logs: a
time bound that is not a whole number of log periods, or a window that reaches past the
scenario's end. After a run (:func:`judge`) each requirement gets the entry of
``metrics.json``'s ``requirements``: its formula, its robustness at t = 0, its verdict
(pass when the robustness is at least 0, as in rtamt's and Breach's Boolean semantics: a
bound met exactly is met) and the instant that sets the robustness.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from .monitor import Evaluation, SamplingError, evaluate, explain, horizon
from .syntax import FormulaError, Node, parse

#: The run's time, always a signal of a formula.
TIME = "t"
#: What a requirement's name may be: it becomes a results.csv column and a CLI argument.
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_\-]{0,63}")


@dataclass(frozen=True)
class Requirement:
    """One ``expect: {stl: ..., name: ...}`` entry, parsed."""

    name: str
    formula: str
    node: Node

    @property
    def signals(self) -> list[str]:
        """The trace columns the formula reads (without ``t``), sorted."""
        return sorted(self.node.signals() - {TIME})


def check_formula(
    text: Any,
    buffers: Iterable[str],
    log_rate: Fraction,
    duration: Fraction,
    hint: Callable[[str, list[str]], str] = lambda _name, _known: "",
) -> Node:
    """The parsed formula, or ``ValueError`` saying in one line why a run could not judge it
    (``hint(name, known)``: the loader's did-you-mean for an unknown signal)."""
    try:
        node = parse(text)
    except FormulaError as exc:
        raise ValueError(f"the formula does not parse: {exc}") from None
    known = list(buffers)
    names = set(known)
    for sig in sorted(node.signals()):
        if sig != TIME and sig not in names:
            raise ValueError(
                f"unknown signal {sig!r}{hint(sig, [*known, TIME])}: a signal is a "
                "Data buffer Component.output, or t"
            )
    period = 1 / Fraction(log_rate)
    try:
        _check_sampling(node, period)
    except SamplingError as exc:
        raise ValueError(str(exc)) from None
    _past, future = horizon(node)
    if future > duration:
        raise ValueError(
            f"the formula reads samples to t = {float(future):g} s, after the run's end at "
            f"{float(duration):g} s: shorten its windows"
        )
    return node


def sampling_problem(formula: str, log_rate: Fraction) -> str | None:
    """Why a run logged at ``log_rate`` cannot judge ``formula`` (a window bound that is not
    a whole number of log periods), or None: ``--log-rate`` asks it again of a scenario the
    loader judged at the file's rate."""
    try:
        _check_sampling(parse(formula), 1 / Fraction(log_rate))
    except SamplingError as exc:
        return str(exc)
    except FormulaError:  # judged at load already
        return None
    return None


def reads_until(formula: str) -> float:
    """The last instant (s) a formula reads from t = 0: a run that ends before it cannot
    judge it (its windows would be cut short)."""
    return float(horizon(parse(formula))[1])


def cut_windows(
    expect: Sequence[Any], end: float, only: Sequence[str] | None = None
) -> list[tuple[str, float]]:
    """``(name, reads until)`` of each STL requirement of ``expect`` (those named in
    ``only``, if given) whose windows read past ``end``, the runs' length: runs that short
    cannot judge it whole (``sweep`` and ``falsify`` say so once, before any run)."""
    out = []
    for e in expect:
        if e.stl is None or (only is not None and e.name not in only):
            continue
        until = reads_until(e.stl)
        if until > end:
            out.append((str(e.name), until))
    return out


def _check_sampling(node: Node, period: Fraction) -> None:
    from .monitor import samples

    if node.op in ("always", "eventually", "historically", "once", "until", "since"):
        samples(node, period)
    for a in node.args:
        _check_sampling(a, period)


def signals_of(requirements: Sequence[Requirement]) -> list[str]:
    """Every trace column some requirement reads, sorted."""
    return sorted({s for r in requirements for s in r.signals})


def judge(
    requirements: Sequence[Requirement],
    t: np.ndarray,
    columns: Mapping[str, np.ndarray],
    period: Fraction,
    runs: int = 1,
) -> list[dict[str, dict[str, Any]]]:
    """Each run's ``requirements`` entry of ``metrics.json``.

    ``t`` holds the logged instants (``(samples,)``), ``columns`` each signal as
    ``(samples, runs)`` (or ``(samples,)`` for one run): the whole batch is evaluated in
    one pass per requirement. A run that logged nothing has no robustness (None, fail).
    """
    cols = {k: (v[:, None] if np.ndim(v) == 1 else np.asarray(v)) for k, v in columns.items()}
    if cols:
        runs = next(iter(cols.values())).shape[1]
    n = len(t)
    cols[TIME] = np.repeat(np.asarray(t, dtype=float)[:, None], runs, axis=1)
    out: list[dict[str, dict[str, Any]]] = [{} for _ in range(runs)]
    for req in requirements:
        if n == 0:
            for r in range(runs):
                out[r][req.name] = _entry(req, None, None)
            continue
        ev = evaluate(req.node, {s: cols[s] for s in req.node.signals()}, period)
        rob = ev.robustness
        until, ended = reads_until(req.formula), float(t[-1])
        for r in range(runs):
            entry = _entry(req, float(rob[r]), _instant(ev, r, t))
            if until > ended + 1e-9:  # a run cut short: its windows were cut, so no verdict
                entry["verdict"] = "skipped"
                entry["note"] = f"it reads until t={until:g} s; the run ended at t={ended:g} s"
            out[r][req.name] = entry
    return out


def _instant(ev: Evaluation, run: int, t: np.ndarray) -> tuple[float, str] | None:
    """The time and the comparison that set a run's robustness."""
    try:
        node, i = explain(ev, run)
    except (IndexError, KeyError):
        return None
    return float(t[min(i, len(t) - 1)]), node.text()


def _entry(req: Requirement, rob: float | None, why: tuple[float, str] | None) -> dict[str, Any]:
    """One requirement's entry: formula, robustness, verdict, instant (and what set it).

    A robustness that is not finite (a window that held no sample: nothing to judge, or a
    signal that was NaN) is written as null, so ``metrics.json`` stays valid JSON; the
    verdict says what it meant.
    """
    finite = rob is not None and math.isfinite(rob)
    verdict = "pass" if rob is not None and not math.isnan(rob) and rob >= 0 else "fail"
    entry: dict[str, Any] = {
        "formula": req.formula,
        "robustness": rob if finite else None,
        "verdict": verdict,
        "instant": why[0] if why else None,
    }
    if why:
        entry["atom"] = why[1]
    if not finite:
        entry["note"] = (
            "no sample to judge" if rob is None else f"robustness {rob} (not a finite number)"
        )
    return entry
