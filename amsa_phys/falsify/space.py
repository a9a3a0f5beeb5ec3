"""The box a falsification searches: continuous, integer and categorical dimensions.

The optimizer works in the unit box (every continuous and integer axis scaled to [0, 1], so
one step size fits every axis whatever its unit); :meth:`Space.decode` turns its vectors
into the ``(Comp.param, value)`` settings a run takes. Bounds are judged up front by the
same ``Param.coerce`` the loader uses, so a range the template refuses fails before any run,
with the parameter's own range in the message.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..errors import ConfigError
from ..model.scenario import PHYSICS_PREFIX, Scenario, resolve_change
from ..runs.sweep import Axis, check_axes, parse_grid

#: An integer axis with more values than this is searched as a continuous one, rounded
#: (the optimizer keeps one threshold per value).
MAX_INTEGER_VALUES = 1000
#: Significant digits kept of a continuous value, relative to its range's width: enough
#: for any metric's resolution, short enough to read in results.csv and worst.yaml.
DIGITS = 6


@dataclass(frozen=True)
class Dim:
    """One axis of the box: ``kind`` is ``float``, ``int`` or ``cat`` (values from --grid)."""

    key: str
    kind: str
    lo: float = 0.0
    hi: float = 1.0
    choices: tuple[Any, ...] = ()

    @property
    def is_integer(self) -> bool:
        """Whether the optimizer sees this axis as integers (few enough values)."""
        return self.kind == "int" and self.hi - self.lo + 1 <= MAX_INTEGER_VALUES

    def levels(self) -> list[float]:
        """An integer axis's values in the unit box (the optimizer's discrete levels)."""
        n = int(self.hi - self.lo)
        return [i / n for i in range(n + 1)]

    def value(self, u: float) -> Any:
        """The parameter value at ``u`` in [0, 1] (clipped): rounded to an integer for an
        integer parameter, to :data:`DIGITS` significant digits of the width otherwise."""
        u = min(1.0, max(0.0, float(u)))
        x = self.lo + u * (self.hi - self.lo)
        if self.kind == "int":
            return round(x)
        places = max(0, DIGITS - 1 - math.floor(math.log10(self.hi - self.lo)))
        return min(self.hi, max(self.lo, round(x, places)))


@dataclass(frozen=True)
class Space:
    """The numeric dimensions (continuous and integer, in the command line's order) and the
    categorical ones."""

    numeric: tuple[Dim, ...]
    categorical: tuple[Dim, ...]

    @property
    def dims(self) -> tuple[Dim, ...]:
        """Every dimension, numeric first: the column order of results.csv."""
        return (*self.numeric, *self.categorical)

    def encode(self, point: tuple[tuple[str, Any], ...]) -> list[float]:
        """The unit-box coordinates of a point's numeric settings (decode's inverse)."""
        values = dict(point)
        return [(float(values[d.key]) - d.lo) / (d.hi - d.lo) for d in self.numeric]

    def decode(self, u: list[float], cats: list[int]) -> tuple[tuple[str, Any], ...]:
        """Settings from a unit-box vector and one choice index per categorical axis."""
        out = [(d.key, d.value(x)) for d, x in zip(self.numeric, u, strict=True)]
        out += [(d.key, d.choices[c]) for d, c in zip(self.categorical, cats, strict=True)]
        return tuple(out)


def parse_bounds(text: str) -> tuple[str, float, float]:
    """``Comp.param=lo:hi`` -> key, lo, hi (lo < hi, both finite)."""
    key, sep, spec = text.partition("=")
    key = key.strip()
    parts = spec.split(":")
    try:
        if not sep or not key or len(parts) != 2:
            raise ValueError
        lo, hi = float(parts[0]), float(parts[1])
    except ValueError:
        raise ConfigError(f"expected Comp.param=lo:hi, got {text!r}", key="--range") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ConfigError(f"bounds must be finite numbers, got {spec!r}", key=f"--range {key}")
    if lo >= hi:
        raise ConfigError(
            f"the lower bound {lo:g} must be below the upper bound {hi:g}", key=f"--range {key}"
        )
    return key, lo, hi


def _numeric_dim(text: str, scenario: Scenario) -> Dim:
    """A --range axis, judged against the template's parameter (type, min and max)."""
    key, lo, hi = parse_bounds(text)
    option = f"--range {key}"
    if key.startswith(PHYSICS_PREFIX):
        raise ConfigError(
            "a physics setting splits batches by value: search it with --grid", key=option
        )
    leaf_path, _, name = key.rpartition(".")
    leaf = scenario.world.leaves.get(leaf_path)
    try:
        param = leaf.template.param(leaf.template.canonical(name)) if leaf else None
    except KeyError:
        param = None
    if param is None or param.name in leaf.template.size_params():
        try:  # resolve_change says what is wrong, with a did-you-mean
            resolve_change(key, 0, scenario.world)
        except ValueError as exc:
            raise ConfigError(str(exc), key=option) from None
        raise ConfigError("not a parameter a run can set", key=option)
    if param.type not in ("int", "float"):
        raise ConfigError(
            f"{param.name} is not a number ({param.type}"
            + (f": {param.range_text()}" if param.range_text() else "")
            + "): give its values with --grid",
            key=option,
        )
    if param.type == "int":
        if math.ceil(lo) >= math.floor(hi):
            raise ConfigError(
                f"an integer parameter needs two integers in {lo:g}:{hi:g}", key=option
            )
        lo, hi = math.ceil(lo), math.floor(hi)
    for bound in (lo, hi):  # the template's min and max
        try:
            param.coerce(bound)
        except ValueError as exc:
            raise ConfigError(str(exc), key=option) from None
    return Dim(key, str(param.type), float(lo), float(hi))


def build_space(scenario: Scenario, ranges: list[str], grids: list[str]) -> Space:
    """The box of ``--range Comp.param=lo:hi`` and ``--grid Comp.param=a,b,...`` options.

    A parameter named twice, one the world does not have (with a did-you-mean), a bound the
    template's min/max refuses or a grid value it refuses: one line each, before any run.
    """
    if not ranges and not grids:
        raise ConfigError(
            "nothing to search: give --range Comp.param=lo:hi or --grid Comp.param=a,b,...",
            key="falsify",
        )
    numeric = [_numeric_dim(r, scenario) for r in ranges]
    axes: list[Axis] = [parse_grid(g) for g in grids]
    seen: set[str] = set()
    for key in [d.key for d in numeric] + [a.key for a in axes]:
        if key in seen:
            raise ConfigError(f"{key} appears twice", key="falsify")
        seen.add(key)
    check_axes(axes, scenario, ranges="lo:hi")
    for axis in axes:
        if len(set(map(repr, axis.values))) != len(axis.values):
            raise ConfigError("a value appears twice", key=f"--grid {axis.key}")
    categorical = [Dim(a.key, "cat", choices=a.values) for a in axes]
    if not numeric and all(len(d.choices) < 2 for d in categorical):
        raise ConfigError("nothing varies: give a --range or a --grid of two values", key="falsify")
    return Space(tuple(numeric), tuple(categorical))
