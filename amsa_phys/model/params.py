"""Typed template parameters: the paper's (name, type, description, default, min, max).

``Param.coerce`` is the one judge of a value: the world loader, the scenario timeline and
``--set`` all call it, so a value is accepted or refused the same way everywhere.
"""

from __future__ import annotations

import math
import operator
import re
import reprlib
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

#: The parameter types a template may declare, by the name shown to users.
TYPE_NAMES = ("int", "float", "bool", "str", "enum", "points")


@dataclass(frozen=True)
class Param:
    """One declared parameter of a template.

    ``type`` is one of :data:`TYPE_NAMES`. ``enum`` parameters take one of ``choices``;
    ``aliases`` lets a user write a readable name (``behavior: circle``) for an enum value.
    ``points`` is a list of ``[x, y]`` pairs in metres (waypoints).
    """

    name: str
    type: str
    description: str
    default: Any
    min: float | None = None
    max: float | None = None
    unit: str = ""
    choices: tuple[Any, ...] | None = None
    aliases: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.type not in TYPE_NAMES:
            raise ValueError(f"parameter {self.name}: unknown type {self.type!r}")
        if self.type == "enum" and not self.choices:
            raise ValueError(f"parameter {self.name}: an enum needs choices")
        # The default must itself be valid: a template author's mistake shows up at import.
        self.coerce(self.default)

    def range_text(self) -> str:
        """Human-readable domain, used by ``describe``, ``templates`` and error messages."""
        if self.type == "enum":
            names = [f"{v}" for v in self.choices or ()]
            names += [f"{k}" for k in self.aliases]
            return "one of " + ", ".join(names)
        if self.min is not None or self.max is not None:
            lo = "-inf" if self.min is None else f"{self.min:g}"
            hi = "inf" if self.max is None else f"{self.max:g}"
            return f"[{lo}, {hi}]"
        return ""

    def coerce(self, value: Any) -> Any:
        """Return ``value`` converted to this parameter's type, or raise ``ValueError``.

        The message says what was expected and what was given; the caller adds file, line
        and key. Integral floats are accepted for ints (YAML writes ``4.0`` easily); bools
        are never numbers, and NaN or infinity is never a valid number.
        """
        kind = self.type
        if kind == "bool":
            if isinstance(value, bool):
                return value
            raise ValueError(f"expected true or false, got {_show(value)}")
        if kind == "str":
            if isinstance(value, str):
                return value
            raise ValueError(f"expected a string, got {_show(value)}")
        if kind == "enum":
            if isinstance(value, str) and value in self.aliases:
                return self.aliases[value]
            if not isinstance(value, bool) and value in (self.choices or ()):
                return value
            raise ValueError(f"expected {self.range_text()}, got {_show(value)}")
        if kind == "points":
            return self._coerce_points(value)
        number = _number(value, integer=kind == "int")
        if self.min is not None and number < self.min:
            raise ValueError(
                f"{number:g} is below the minimum {self.min:g} (range {self.range_text()})"
            )
        if self.max is not None and number > self.max:
            raise ValueError(
                f"{number:g} is above the maximum {self.max:g} (range {self.range_text()})"
            )
        return number

    def _coerce_points(self, value: Any) -> tuple[tuple[float, float], ...]:
        if not isinstance(value, Sequence) or isinstance(value, str):
            raise ValueError(f"expected a list of [x, y] points, got {_show(value)}")
        points = []
        for item in value:
            if not isinstance(item, Sequence) or isinstance(item, str) or len(item) != 2:
                raise ValueError(f"expected an [x, y] pair, got {_show(item)}")
            points.append((_number(item[0], False), _number(item[1], False)))
        return tuple(points)


#: Largest integer parameter: copies of a component keep their parameters in int64 arrays.
MAX_INT = 2**63 - 1


def _number(value: Any, integer: bool) -> Any:
    if isinstance(value, bool) or not isinstance(value, int | float):
        want = "an integer" if integer else "a number"
        raise ValueError(f"expected {want}, got {_show(value)}{number_text_hint(value)}")
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"expected a finite number, got {value}")
    if integer:
        if isinstance(value, float):
            if not value.is_integer():
                raise ValueError(f"expected an integer, got {value}")
            value = int(value)
        if abs(value) > MAX_INT:
            raise ValueError(f"integer too large ({digits_text(value)}; at most {MAX_INT})")
        return value
    try:
        return float(value)
    except OverflowError:
        raise ValueError(
            f"number too large ({digits_text(value)}; a number must fit a float, at most "
            "about 1.8e308)"
        ) from None


def digits_text(value: int) -> str:
    """``401 digits``; past Python's digit limit (``0x`` and 5 000 hex digits reads in, but
    cannot be written in decimal) ``more than 4300 digits``."""
    try:
        return f"{len(str(abs(value)))} digits"
    except ValueError:  # past Python's digit limit, it cannot even be written in decimal
        return f"more than {sys.get_int_max_str_digits()} digits"


_YAML_TYPES = {
    bool: "boolean",
    int: "integer",
    float: "number",
    str: "string",
    list: "list",
    dict: "mapping",
    type(None): "null",
}


def yaml_type(value: Any) -> str:
    """The YAML word for a value's type (``mapping``, ``integer``, ...) for messages."""
    return _YAML_TYPES.get(type(value), type(value).__name__)


_REPR = reprlib.Repr()
_REPR.maxlevel = 3
_REPR.maxstring = _REPR.maxother = _REPR.maxlong = 40


def exact_int(value: Any) -> int | None:
    """``value`` as an integer if it is one (an ``int``, a numpy integer: ``__index__``),
    else None: a bool or a float is refused, as argparse's ``type=int`` refuses ``1.5``."""
    if isinstance(value, bool):
        return None
    try:
        return operator.index(value)
    except TypeError:
        return None


def short_repr(value: Any) -> str:
    """``repr`` cut to 40 characters, for one-line messages.

    Bounded work whatever the value: a list shared a billion times over by YAML aliases
    is not spelled out before it is cut.
    """
    text = _cut_repr(value)
    if text is not None:
        return text
    huge = f"a number of more than {sys.get_int_max_str_digits()} digits"
    return huge if isinstance(value, int) else f"a {yaml_type(value)} holding {huge}"


def _cut_repr(value: Any) -> str | None:
    """The cut ``repr``, or None for a value holding an integer past Python's digit limit
    (``0x`` and 5 000 hex digits reads in, but cannot be written in decimal)."""
    try:
        text = _REPR.repr(value)
    except ValueError:
        return None
    return text if len(text) <= 40 else text[:37] + "..."


def _show(value: Any) -> str:
    """Describe a wrong value briefly: its YAML type and its (cut) repr."""
    text = _cut_repr(value)
    return short_repr(value) if text is None else f"{yaml_type(value)} {text}"


#: A number in exponent notation that YAML 1.1 reads as text (mantissa, exponent).
_EXPONENT = re.compile(r"([-+]?(?:\d[\d_]*)?(?:\.[\d_]*)?)[eE]([-+]?\d+)")


def number_text_hint(value: Any) -> str:
    """`` (YAML reads 1e-3 as text: write 1.0e-3)`` for such a string, else ``""``.

    PyYAML follows YAML 1.1, whose floats need a dot and a signed exponent: ``1e-3``,
    ``1e12`` and ``1.0e12`` are strings there, though YAML 1.2, JSON and Python read them
    as numbers. "expected a number, got string '1e-3'" alone leaves the reader puzzled;
    the hint gives the spelling that is read as a number.
    """
    if not isinstance(value, str):
        return ""
    match = _EXPONENT.fullmatch(value)
    if match is None or not any(c.isdigit() for c in match.group(1)):
        return ""
    mantissa, exponent = match.groups()
    if "." not in mantissa:
        mantissa += ".0"
    if exponent[0] not in "+-":
        exponent = "+" + exponent
    return f" (YAML reads {value} as text: write {mantissa}e{exponent})"
