"""The environment's arguments, each judged before use.

A wrong argument must be a :class:`~amsa_phys.errors.ConfigError` naming it, in one line,
at the call that passed it, not an error from deep inside: ``render_size=(0, 0)`` was a
ZeroDivisionError at the first ``render()``, a negative size a ``pygame.error``, a seed of
2**64 was accepted (and not the seed the run used), ``action_scale=nan`` made every action
NaN and ``collision_penalty=inf`` every reward -inf.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..model.params import exact_int, short_repr
from ..model.schema import MAX_SEED

#: The largest picture side, in pixels (8K is 7,680): a frame is width x height x 3 bytes,
#: so 8192 x 8192 is 200 MB, and pygame refuses far larger surfaces with an unhelpful error.
MAX_RENDER_PX = 8192


def render_size(value: Any) -> tuple[int, int]:
    """``(width, height)``: two whole numbers of pixels from 1 to :data:`MAX_RENDER_PX`."""
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) != 2:
        raise ConfigError(
            f"expected (width, height) in pixels, got {short_repr(value)}", key="render_size"
        )
    size = []
    for side in value:
        try:
            if isinstance(side, bool):
                raise TypeError
            px = operator.index(side)
        except TypeError:
            raise ConfigError(
                f"expected whole numbers of pixels, got {short_repr(value)}", key="render_size"
            ) from None
        if not 1 <= px <= MAX_RENDER_PX:
            raise ConfigError(
                f"each side must be 1 to {MAX_RENDER_PX} pixels, got {short_repr(value)}",
                key="render_size",
            )
        size.append(px)
    return size[0], size[1]


def finite_number(value: Any, name: str, *, positive: bool) -> float:
    """A finite real number: > 0 when ``positive``, else >= 0."""
    is_numpy = type(value).__module__ == "numpy" and hasattr(value, "item")
    if isinstance(value, bool) or not (isinstance(value, (int, float)) or is_numpy):
        raise ConfigError(f"expected a number, got {short_repr(value)}", key=name)
    number = float(value)
    bound_ok = number > 0 if positive else number >= 0
    if not math.isfinite(number) or not bound_ok:
        need = "a positive finite number" if positive else "a finite number >= 0"
        raise ConfigError(f"must be {need}, got {short_repr(value)}", key=name)
    return number


def seed(value: Any) -> int | None:
    """``reset(seed=...)``: None, or an integer a scenario's ``seed:`` may hold."""
    if value is None:
        return None
    number = exact_int(value)
    if number is None or not 0 <= number <= MAX_SEED:
        raise ConfigError(
            f"must be an integer from 0 to {MAX_SEED} (2**63 - 1), like seed: in a "
            f"scenario; got {short_repr(value)}",
            key="seed",
        )
    return number


def seeds_from(base: int | None, n: int) -> list[int | None]:
    """A vector env's ``reset(seed=base)``: env ``i`` gets ``base + i``, so the last of ``n``
    envs must still be a seed a scenario may hold (checked here, before any env is reset:
    the batch took a larger one as it came, the single envs refused it midway, naming a
    seed nobody passed)."""
    if base is None:
        return [None] * n
    top = MAX_SEED - (n - 1)
    if base > top:
        raise ConfigError(
            f"must be an integer from 0 to {top} (2**63 - 1 less {n - 1}: env i is seeded "
            f"with seed + i); got {base}",
            key="seed",
        )
    return [base + i for i in range(n)]


def reset_set(options: Any) -> dict[str, Any]:
    """The ``set`` of ``reset(options=...)`` (its only option), as a dict."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise ConfigError(
            f'expected a mapping like {{"set": {{...}}}}, got {short_repr(options)}',
            key="options",
        )
    unknown = sorted(str(k) for k in options if k != "set")
    if unknown:
        raise ConfigError(f"unknown reset option {unknown[0]!r}; known: set", key="options")
    extra = options.get("set") or {}
    if not isinstance(extra, Mapping):
        raise ConfigError(
            f'expected a mapping like {{"Comp.param": value}}, got {short_repr(extra)}',
            key="options.set",
        )
    return dict(extra)


def names(value: Any, key: str) -> list[str] | None:
    """``actions=``: None, or a list of output names (a lone string is one name's letters)."""
    if value is None:
        return None
    if isinstance(value, str) or not isinstance(value, Sequence):
        raise ConfigError(
            f"expected a list of names, got {short_repr(value)}"
            + (f" (one name: [{value!r}])" if isinstance(value, str) else ""),
            key=key,
        )
    if not all(isinstance(v, str) for v in value):
        raise ConfigError(f"expected names (strings), got {short_repr(value)}", key=key)
    return list(value)


def flag(value: Any, name: str) -> bool:
    """A switch: True or False (numpy's too). ``record_trace="no"`` was taken as True."""
    if isinstance(value, bool | np.bool_):
        return bool(value)
    raise ConfigError(f"expected True or False, got {short_repr(value)}", key=name)


def component(value: Any) -> str | None:
    """``controller=``: None or a component's dotted path."""
    if value is not None and not isinstance(value, str):
        raise ConfigError(
            f"expected a component's path (a string), got {short_repr(value)}", key="controller"
        )
    return value
