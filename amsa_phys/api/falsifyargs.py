"""``ap.falsify``'s arguments, each judged before the search, as ``amsa-phys falsify`` judges
its options.

Why a module of its own: the command's checks live in its argument parsing (argparse's
``type=int``) and in ``cli/falsify.py``; the Python front door skipped them, so a wrong
argument met the search deep inside: ``budget=1.5`` a numpy TypeError, ``duration=-1`` a
ZeroDivisionError, ``duration=nan`` every run an error row, ``duration=1e9`` a search that
never ended, ``metric="rms_eror"`` the whole budget spent maximising a column no row has.
Each is now a one-line :class:`~amsa_phys.errors.ConfigError` naming the argument as it was
passed (``budget=``), with the command's bounds.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ..errors import ConfigError
from ..model.configure import duration_option
from ..model.params import exact_int, short_repr
from ..model.schema import MAX_SEED
from ..requirements.objective import requirement_of
from ..runs.sweep import MAX_RUNS, unknown_metric

#: how many trials one call may ask for (the command's ``--trials`` limit)
MAX_TRIALS = 1000
#: where a generation's runs may go from Python (Dask needs the command's ``--scheduler``)
EXECUTORS = ("batch", "local")


def whole(value: Any, name: str, low: int, high: int | None) -> int:
    """An integer argument from ``low`` to ``high`` (None: no upper bound); a bool or a
    float is refused, as argparse's ``type=int`` refuses ``1.5``."""
    number = exact_int(value)
    if number is None or number < low or (high is not None and number > high):
        bounds = f"from {low:,} to {high:,}" if high is not None else f">= {low:,}"
        raise ConfigError(f"must be an integer {bounds}, got {short_repr(value)}", key=f"{name}=")
    return number


def check_arguments(
    scenario: Any,
    box: Any,
    *,
    budget: Any,
    cost: Any,
    seed: Any,
    trials: Any,
    duration: Any,
    executor: Any,
    workers: Any,
) -> None:
    """Refuse a wrong argument of :func:`~amsa_phys.api.falsify.falsify` before anything
    is loaded or run; ``seed`` may be at most 2**63 - 1 less the further trials' seeds."""
    if not isinstance(scenario, str | os.PathLike):
        raise TypeError(
            f"scenario: expected a scenario file path, got {type(scenario).__name__} "
            "(ap.falsify searches a scenario file; save a mapping to YAML first)"
        )
    if not isinstance(box, Mapping):
        raise ConfigError(
            'expected a mapping like {"Comp.param": (lo, hi)} or {"Comp.param": [a, b]}, '
            f"got {short_repr(box)}",
            key="box=",
        )
    if not box:
        raise ConfigError(
            'nothing to search: give at least one {"Comp.param": (lo, hi)} or '
            '{"Comp.param": [a, b, ...]}',
            key="box=",
        )
    for key, spec in box.items():
        if isinstance(spec, tuple) and len(spec) == 2:
            for bound in spec:
                real = isinstance(bound, numbers.Real) and not isinstance(bound, bool)
                if not real or not math.isfinite(bound):
                    raise ConfigError(
                        f"a range's bounds must be finite numbers, got {short_repr(spec)}",
                        key=f'box={{"{key}": ...}}',
                    )
    whole(budget, "budget", 1, MAX_RUNS)
    count = whole(trials, "trials", 1, MAX_TRIALS)
    top = MAX_SEED - (count - 1)
    try:
        whole(seed, "seed", 0, top)
    except ConfigError:  # said as the command says --seed
        less = "" if count == 1 else f" less the {count - 1} more trials"
        raise ConfigError(
            f"must be an integer from 0 to {top} (2**63 - 1{less}), got {short_repr(seed)}",
            key="seed=",
        ) from None
    if duration is not None:
        exact = isinstance(duration, Fraction)
        if isinstance(duration, bool) or not isinstance(duration, numbers.Real):
            raise ConfigError(f"expected a number, got {short_repr(duration)}", key="duration=")
        duration_option(duration if exact else float(duration), "duration=")
    if executor not in EXECUTORS:
        more = (
            " ('dask' needs a scheduler address: amsa-phys falsify --executor dask "
            "--scheduler ADDR)"
            if executor == "dask"
            else ""
        )
        raise ConfigError(
            f"expected one of {', '.join(EXECUTORS)}, got {short_repr(executor)}{more}",
            key="executor=",
        )
    whole(workers, "workers", 1, None)
    if cost is not None and not callable(cost):
        raise ConfigError(
            f"expected a function of a result row, got {short_repr(cost)}", key="cost="
        )


def check_metric(metric: str | None, n_phases: int) -> None:
    """A metric the runs' rows have (``phase<i>.`` of a phase they reach), as the command
    checks ``--metric``; a requirement's ``robustness.NAME`` is judged with the objective."""
    if metric is None:
        return
    if not isinstance(metric, str):
        raise ConfigError(f"expected a metric's name, got {short_repr(metric)}", key="metric=")
    if requirement_of(metric) is None:
        why = unknown_metric(metric, n_phases)
        if why is not None:
            raise ConfigError(why, key="metric=")
