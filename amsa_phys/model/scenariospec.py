"""A loaded scenario as data: the quality signal, the expectations, the Scenario itself.

Built by ``scenariobuild.py`` from a file, configured by ``configure.py`` (pure transforms:
each returns a new Scenario), read everywhere else. It holds a Timeline (``timeline.py``:
phases, the changes inside them, duration, the file's plan when cut short) and every reader
asks that Timeline; its parameter changes are ``changes.py``'s.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from . import tracecols
from .adaptrules import RULE_COLUMN, Rule
from .timeline import Timeline
from .world import WorldSpec

DEFAULT_LOG_RATE_HZ = 20
#: Wall seconds a user's ROS 2 node may take to answer a step (``ros2_timeout:``)
DEFAULT_ROS2_TIMEOUT_S = 10.0
DEFAULT_TOLERANCE = 1.5


@dataclass(frozen=True)
class Quality:
    """The quality-of-control signal (a Data buffer) and its reference and tolerance."""

    signal: str
    reference: float
    tolerance: float
    #: seconds the signal must stay in the band for ``settling_time`` (None: the default,
    #: ``model/metrics.default_dwell`` of each block)
    dwell: float | None = None


@dataclass(frozen=True)
class Expectation:
    """A bound on a run.

    Either ``metric`` (overall, or of ``phase``) must be ``below`` and/or ``above`` a bound,
    or every sample of the Data ``trace`` in [``after``, ``before``] must be, or the STL
    formula ``stl`` (named ``name``) must hold: robustness at t = 0 at least 0
    (``stl/``).
    """

    metric: str | None
    phase: int | None
    below: float | None
    above: float | None
    line: int | None
    trace: str | None = None
    after: float | None = None
    before: float | None = None
    stl: str | None = None
    name: str | None = None


@dataclass(frozen=True)
class Scenario:
    """A loaded, checked scenario.

    Frozen, its sequences tuples: a sweep caches one Scenario and shares it between its
    runs, the ROS simulator and the window hold theirs for a whole session, so a change is
    a new Scenario (``dataclasses.replace``; ``configure.py``'s ``with_*`` functions,
    :func:`shortened`, :func:`without_adapt`), never an edit that another holder would see.
    Lists given to the constructor are stored as tuples. ``data`` is the file's parsed
    document, read (``sweep:``) but never written.
    """

    path: Path
    name: str
    world: WorldSpec
    #: the phases, the changes inside them, the duration and (cut short by ``--duration``)
    #: the file's plan: the one owner of "what changes when"; every reader asks it
    timeline: Timeline
    seed: int
    log_rate: Fraction
    quality: Quality | None
    expect: tuple[Expectation, ...] = ()
    data: dict[str, Any] = field(default_factory=dict)
    #: ``trace_columns:`` glob patterns (None: trace every Data buffer); see
    #: :func:`traced_columns` for what is kept
    trace_columns: tuple[str, ...] | None = None
    #: ``adapt:`` reconfiguration rules (``model/adaptrules.py``); empty with ``--no-adapt``
    adapt: tuple[Rule, ...] = ()
    #: ``ros2:`` Leaves stepped by a user's ROS 2 nodes (``ros/external.py``), and how long
    #: (wall seconds) a node may take to answer
    ros2: tuple[str, ...] = ()
    ros2_timeout: float = DEFAULT_ROS2_TIMEOUT_S

    def __post_init__(self) -> None:
        # a list given by the builder or a caller becomes a tuple: nobody can append to the
        # phases or the expectations of a Scenario someone else holds
        # (a replace passes tuples already: only a list costs a copy, ~1 µs a sweep's job)
        for name in ("expect", "adapt", "trace_columns", "ros2"):
            value = getattr(self, name)
            if value is not None and type(value) is not tuple:
                object.__setattr__(self, name, tuple(value))

    @property
    def duration(self) -> Fraction:
        """How long the run lasts: the timeline's (a read, never a second copy)."""
        return self.timeline.duration


def traced_columns(scenario: Scenario) -> list[str]:
    """The Data buffers the scenario's trace holds, in world order (``model/tracecols``).

    The quality signal, every ``expect: {trace: ...}`` column and every signal of an STL
    requirement are always kept: the run reads them back.
    """
    required = [e.trace for e in scenario.expect if e.trace]
    required += [s for r in requirements(scenario) for s in r.signals]
    if scenario.quality:
        required.append(scenario.quality.signal)
    columns = tracecols.selected(scenario.trace_columns, list(scenario.world.buffers), required)
    return [*columns, RULE_COLUMN] if scenario.adapt else columns


def shortened(scenario: Scenario, duration: Fraction) -> Scenario:
    """``scenario`` run until ``duration`` instead (``--duration``): later changes drop out.

    A shorter run remembers the file's duration, so the phase it stops in is reported as
    cut short (partial) rather than judged as if it were complete (``Timeline.cut``). A new
    Scenario: the given one (perhaps cached and shared) is untouched.
    """
    return dataclasses.replace(scenario, timeline=scenario.timeline.cut(duration))


def without_adapt(scenario: Scenario) -> Scenario:
    """``scenario`` as if it had no ``adapt:`` section (``--no-adapt``, ``adapt=False``)."""
    return dataclasses.replace(scenario, adapt=())


def requirements(scenario: Scenario) -> list[Any]:
    """The scenario's STL requirements (``stl.requirement.Requirement``), in file
    order: parsed again from the checked text (cheap, and the Scenario stays plain data)."""
    from ..stl.requirement import Requirement
    from ..stl.syntax import parse

    return [
        Requirement(str(e.name), e.stl, parse(e.stl)) for e in scenario.expect if e.stl is not None
    ]
