"""Configuring a loaded scenario: the command line's and the API's options as pure steps.

``configure_scenario`` is a chain: build the file's scenario, then apply each option given —
seed, duration, log rate, trace columns, ``--set`` overrides — each a function from a
Scenario to a new Scenario (``dataclasses.replace``), judged like a file value and refused
with the option's name. Nothing here changes a Scenario, a phase or a world in place: a
sweep caches and shares them between runs.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from fractions import Fraction
from typing import Any

from ..errors import ConfigError
from . import tracecols
from .changes import PHYSICS_PREFIX, parse_physics_override, parse_setting, with_physics
from .params import short_repr
from .rates import MAX_RATE_HZ, MIN_RATE_HZ
from .scenariobuild import (
    build_scenario,
    check_phases,
    effective_log_rate,
    scenario_cycle_problem,
    trace_problem,
)
from .scenariospec import Scenario, shortened
from .schema import MAX_SEED, duration_problem
from .yamlio import YamlDoc


def configure_scenario(
    doc: YamlDoc,
    overrides: list[str] | None = None,
    seed: int | None = None,
    duration: float | None = None,
    log_rate: float | None = None,
    trace_columns: str | Sequence[str] | None = None,
) -> Scenario:
    """``load_scenario`` of a document already parsed (a file, or a mapping given in
    Python: ``amsa_phys.run``), so both judge the options the same way."""
    # with overrides, the rules are checked once they are in: a --set may repair the file
    scenario = build_scenario(doc, check_rules=not overrides)
    if seed is not None:
        scenario = with_seed(scenario, seed)
    if duration is not None:
        scenario = shortened(scenario, duration_option(duration))
    if log_rate is not None:
        scenario = with_log_rate(scenario, log_rate)
    if trace_columns is not None:
        scenario = with_trace_columns(scenario, trace_columns)
    if overrides:
        scenario = with_overrides(scenario, overrides, doc)
    return dataclasses.replace(
        scenario, log_rate=effective_log_rate(scenario.log_rate, scenario.world)
    )


def with_seed(scenario: Scenario, seed: Any) -> Scenario:
    """``scenario`` with ``--seed``: an integer from 0 to 2**63 - 1."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
        raise ConfigError(
            f"must be an integer from 0 to {MAX_SEED} (2**63 - 1), like seed: in a "
            f"scenario; got {short_repr(seed)}",
            key="--seed",
        )
    return dataclasses.replace(scenario, seed=seed)


def with_log_rate(scenario: Scenario, log_rate: float) -> Scenario:
    """``scenario`` with ``--log-rate``, in the rates amsa-phys runs and schedulable."""
    out = dataclasses.replace(scenario, log_rate=positive_fraction(log_rate, "--log-rate"))
    if not MIN_RATE_HZ <= out.log_rate <= MAX_RATE_HZ:
        raise ConfigError(
            f"{log_rate:g} Hz is outside the rates amsa-phys runs "
            f"({MIN_RATE_HZ:g} to {MAX_RATE_HZ:g} Hz)",
            key="--log-rate",
        )
    why = scenario_cycle_problem(out)
    if why is not None:
        raise ConfigError(why, key="--log-rate")
    from ..stl.requirement import sampling_problem

    rate = effective_log_rate(out.log_rate, out.world)
    for e in out.expect:  # the loader judged them at the file's rate
        if e.stl is not None and (why := sampling_problem(e.stl, rate)) is not None:
            raise ConfigError(f"the requirement {e.name} cannot be judged: {why}", key="--log-rate")
    return out


def with_trace_columns(scenario: Scenario, trace_columns: Any) -> Scenario:
    """``scenario`` with ``--trace-columns``: glob patterns, each keeping some buffer."""
    if isinstance(trace_columns, str):
        patterns = tracecols.parse_patterns(trace_columns)
    elif isinstance(trace_columns, (list, tuple)) and all(
        isinstance(p, str) for p in trace_columns
    ):
        patterns = list(trace_columns)
    else:
        raise ConfigError(
            "expected glob patterns: a comma-separated string or a list of strings, got "
            + short_repr(trace_columns),
            key="--trace-columns",
        )
    problem = trace_problem(patterns, list(scenario.world.buffers))
    if problem is not None:
        raise ConfigError(problem[1], key="--trace-columns")
    return dataclasses.replace(scenario, trace_columns=patterns)


def with_ros2(scenario: Scenario, raw: Any, timeout: float | None = None) -> Scenario:
    """``scenario`` with ``--ros2 COMP,...`` (replacing its ``ros2:``) and ``--ros2-timeout``."""
    from . import externals as external  # names only

    out = scenario
    if raw is not None:
        paths = external.parse_list(raw, "--ros2")
        why = external.problem(scenario.world, paths)
        if why is not None:
            raise ConfigError(why, key="--ros2")
        out = dataclasses.replace(out, ros2=paths)
    if timeout is not None:
        if not (isinstance(timeout, (int, float)) and 0 < timeout <= 3600):
            raise ConfigError(
                f"expected seconds in (0, 3600], got {short_repr(timeout)}", key="--ros2-timeout"
            )
        out = dataclasses.replace(out, ros2_timeout=float(timeout))
    return out


def with_overrides(scenario: Scenario, overrides: list[str], doc: YamlDoc | None) -> Scenario:
    """``scenario`` with ``--set`` overrides: physics settings and Leaf frequencies change
    the world, parameter changes join phase 0 after the file's ``set:``; then the templates'
    rules are checked along the phases, naming an override as ``--set``."""
    world = scenario.world
    added = []
    given: dict[str, tuple[str, Any]] = {}  # what each override set, to refuse a conflict
    for text in overrides:
        if text.strip().startswith(PHYSICS_PREFIX):
            physics = parse_physics_override(text)
            world = with_physics(world, physics)
            _refuse_conflict(given, text.partition("=")[0].strip(), text, physics)
            continue
        change, world = parse_setting(text, world)
        if change is not None:  # None: a frequency, set on the world's Leaf
            added.append(change)
            _refuse_conflict(given, change.key, text, change.value)
        else:
            key, _, raw = text.partition("=")
            _refuse_conflict(given, key.strip(), text, raw.strip())
    timeline = scenario.timeline.with_initial(added)
    out = dataclasses.replace(scenario, world=world, timeline=timeline)
    check_phases(out, doc, {c.key for c in added})
    return out


def _refuse_conflict(given: dict[str, tuple[str, Any]], key: str, text: str, value: Any) -> None:
    """Refuse a second ``--set`` of ``key`` with another value, naming both.

    A scenario file refuses a key given twice; ``--set X=1 --set X=2`` (or a parameter and
    its alias) is the same slip on the command line, and taking the last silently hides
    which value the run used. The same value twice is harmless and accepted.
    """
    first = given.setdefault(key, (text, value))
    if first[1] != value or type(first[1]) is not type(value):
        raise ConfigError(
            f"set twice, {first[0].strip()!r} and {text.strip()!r}: give one value",
            key=f"--set {key}",
        )


def duration_option(value: float | Fraction, option: str = "--duration") -> Fraction:
    """``--duration`` (run, sweep, falsify, ``ap.run``'s ``duration=``), exactly: a positive
    finite number up to ``schema.MAX_DURATION_S``, the limit a file's ``duration:`` has."""
    duration = value if isinstance(value, Fraction) else positive_fraction(value, option)
    why = duration_problem(duration)
    if why is not None:
        raise ConfigError(why, key=option)
    return duration


def positive_fraction(value: float, option: str) -> Fraction:
    """An option's positive finite number, exactly (``Fraction(str(value))``)."""
    if value == float("inf"):  # "inf", or digits beyond a float's range (1e400)
        raise ConfigError(
            "must be a positive finite number, got infinity or a number too large for a float",
            key=option,
        )
    if not value > 0 or value != value:
        raise ConfigError(f"must be a positive finite number, got {value}", key=option)
    return Fraction(str(value))
