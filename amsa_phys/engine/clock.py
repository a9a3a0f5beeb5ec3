"""Exact simulated time: every rate becomes an integer number of ticks on one grid.

Rates are rationals (``Fraction(str(4.0)) == 4``), the tick is the greatest common divisor of
every period and instant in the run, so ``t = tick * n`` is exact for any ``n`` — no float
drift after 10^6 steps, and 3 Hz with 7 Hz lands on the same instants every second.
"""

from __future__ import annotations

from collections.abc import Iterable
from fractions import Fraction
from math import gcd, lcm

from ..model.rates import MAX_EVENTS_PER_CYCLE

#: Refuse schedules whose repeating pattern would be absurdly long (incommensurate rates);
#: the loader checks the same limit first (``model/rates.py``).
__all__ = [
    "MAX_EVENTS_PER_CYCLE",
    "TickGrid",
    "at_or_after",
    "exact",
    "fraction_gcd",
    "hyperperiod",
    "seconds",
    "to_fraction",
]

_new = object.__new__


def exact(n: int, d: int) -> Fraction:
    """``Fraction(n, d)`` for ints ``n >= 0``, ``d > 0``, in half the time: the time of an
    instant (``tick * num / den``), made once per instant where components run. The
    constructor's type checks and sign handling are what costs; the result is the same
    reduced Fraction (equal, same hash), its two slots set as ``Fraction`` sets them."""
    g = gcd(n, d)
    f = _new(Fraction)
    f._numerator = n // g  # type: ignore[attr-defined]
    f._denominator = d // g  # type: ignore[attr-defined]
    return f


if getattr(Fraction, "__slots__", None) != ("_numerator", "_denominator"):  # not CPython's
    exact = Fraction  # type: ignore[assignment]  # same results, the constructor's speed


def seconds(t: Fraction | float) -> float:
    """``float(t)``, the same float, without the ABC method a Fraction's ``float()`` goes
    through (``numbers.Rational.__float__``: int / int, ~1 µs): group steps ask it of the
    instant's time at every instant."""
    if t.__class__ is Fraction:
        return t._numerator / t._denominator  # type: ignore[union-attr,no-any-return]
    return float(t)


def at_or_after(t: Fraction, then: Fraction, then_s: float) -> bool:
    """``t >= then`` for Fractions, where ``then_s`` is ``float(then)``: exact, and a float
    compare when it decides (rounding to float never reverses an order: ``t >= then``
    implies ``float(t) >= float(then)``), instead of Fraction's cross-multiplied compare."""
    if seconds(t) < then_s:
        return False
    return t >= then


def to_fraction(value: float | int | str | Fraction) -> Fraction:
    """Decimal-exact conversion: 0.1 -> 1/10 (not the binary float's 3602879701896397/...)."""
    if isinstance(value, Fraction):
        return value
    return Fraction(str(value))


def fraction_gcd(values: Iterable[Fraction]) -> Fraction:
    """Greatest common divisor of positive rationals: gcd(numerators) / lcm(denominators)."""
    num = 0
    den = 1
    for v in values:
        if v <= 0:
            continue
        num = gcd(num, v.numerator)
        den = lcm(den, v.denominator)
    if num == 0:
        raise ValueError("no positive value")
    return Fraction(num, den)


class TickGrid:
    """The integer time grid of one run."""

    def __init__(self, tick: Fraction) -> None:
        self.tick = tick

    @classmethod
    def for_run(cls, periods: Iterable[Fraction], instants: Iterable[Fraction]) -> TickGrid:
        """A grid on which every period and instant is a whole number of ticks."""
        return cls(fraction_gcd([*periods, *instants]))

    def ticks(self, t: Fraction) -> int:
        """Whole ticks in ``t`` (which must lie on the grid)."""
        n = t / self.tick
        if n.denominator != 1:
            raise ValueError(f"{t} is not on the tick grid {self.tick}")
        return int(n)

    def time(self, n: int) -> Fraction:
        """Exact time of tick ``n``."""
        return self.tick * n

    def seconds(self, n: int) -> float:
        """Float seconds of tick ``n`` (only for output)."""
        return float(self.tick * n)


def hyperperiod(periods_ticks: Iterable[int]) -> int:
    """The least common multiple of the periods: the schedule repeats after it."""
    return lcm(*periods_ticks)


#: instants' times kept per tick grid (``kept_times``): a Gymnasium env's episodes or a loop's
#: runs meet the same instants again; bounded, ~1.5 MB a grid at most
NOWS_KEPT = 8192
_GRIDS_KEPT = 4
_nows_of: dict[tuple[int, int], dict[int, Fraction]] = {}


def kept_times(num: int, den: int) -> dict[int, Fraction]:
    """The instants' times kept for the tick grid ``num / den`` s (tick -> exact time):
    Fractions are immutable, so runs on one grid share them; the oldest grid goes first."""
    nows = _nows_of.get((num, den))
    if nows is None:
        if len(_nows_of) >= _GRIDS_KEPT:
            _nows_of.pop(next(iter(_nows_of), None), None)
        nows = _nows_of[(num, den)] = {}
    return nows
