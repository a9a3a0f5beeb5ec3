"""The timeline of a run: the one owner of "which changes happen when, in which phase".

A scenario's timeline is a list of phases (phase 0 starts at t = 0 with the ``set``
values); each later phase starts with its own changes, and a phase may hold steps
(``new_phase: false`` entries) that change parameters without starting a phase. Before this
module that list was flattened to ``(at, changes)`` in seven places with two idioms for
"phase 0" (``phases[0].changes`` and ``if i > 0``), and the copies drifted: some skipped the
steps, and cutting a run short (``--duration``) forgot the planned bounds in one copy. Every
reader now asks a :class:`Timeline`:

* :attr:`Timeline.initial` — the values in force at t = 0 (phase 0's changes);
* :meth:`Timeline.points` — every later change, in time order, each saying its phase and
  whether it starts that phase;
* :meth:`Timeline.cut` — the timeline of a run stopped early, remembering the file's plan so
  the phase it stops in is reported as partial;
* :meth:`Timeline.phase_at` and :meth:`Timeline.bounds` — which phase holds an instant, and
  where each phase was planned to start and end.

A Timeline is frozen: cutting or extending one returns a new one and never touches the
phases a cached scenario shares with other runs. Adaptation rules are its next
client: a rule's change lands like a point, at an exact instant.
"""

from __future__ import annotations

import bisect
import dataclasses
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction

from .changes import Change


@dataclass(frozen=True)
class Step:
    """Changes made inside a phase without starting a new one, at ``at``.

    A timeline entry with ``new_phase: false`` and a change made live in the window are
    steps: the phase structure (and so what ``expect: {phase: i}`` means) stays the one the
    scenario's author wrote, however many changes land inside a phase.
    """

    at: Fraction
    changes: list[Change]
    label: str = ""
    entry: int | None = None  # index in the file's ``timeline`` (None: made live)


@dataclass(frozen=True)
class Phase:
    """A phase of the scenario: from ``at`` (phase 0 at 0) with the changes made then."""

    at: Fraction
    changes: list[Change]
    label: str = ""
    #: changes inside this phase after its start (``new_phase: false``), in time order
    within: list[Step] = field(default_factory=list)
    entry: int | None = None  # index in the file's ``timeline`` (None: phase 0)


@dataclass(frozen=True)
class Point:
    """Changes applied together at one instant after t = 0."""

    at: Fraction
    #: the phase the changes belong to (a phase's start or a step inside it)
    phase: int
    changes: tuple[Change, ...]
    #: True if these are the changes that start ``phase`` (they move the phase index)
    starts_phase: bool
    label: str = ""
    #: index of the entry in the file's ``timeline`` (None: not from the file)
    entry: int | None = None


@dataclass(frozen=True)
class Timeline:
    """A run's phases and duration, frozen; see the module docstring."""

    phases: tuple[Phase, ...]
    duration: Fraction
    #: when the run was cut short: the file's phase starts followed by its duration
    planned: tuple[Fraction, ...] | None = None

    @classmethod
    def of(
        cls,
        phases: Sequence[Phase],
        duration: Fraction,
        planned: Sequence[Fraction] | None = None,
    ) -> Timeline:
        """A timeline of ``phases`` (none: one empty phase 0) lasting ``duration``."""
        if not phases:
            phases = [Phase(Fraction(0), [])]
        return cls(
            tuple(phases),
            Fraction(duration),
            None if planned is None else tuple(Fraction(b) for b in planned),
        )

    @property
    def initial(self) -> tuple[Change, ...]:
        """The changes in force from t = 0 (phase 0's): components are built with them."""
        return tuple(self.phases[0].changes)

    @property
    def starts(self) -> tuple[Fraction, ...]:
        """When each phase starts (phase 0 at 0)."""
        return tuple(p.at for p in self.phases)

    def points(self) -> tuple[Point, ...]:
        """Every change after t = 0 in time order: phase starts and the steps inside phases.

        At one instant a phase's start comes before its steps (a step at a phase's start
        time cannot be written, but the order is fixed for any caller that builds one).
        """
        out: list[Point] = []
        for i, phase in enumerate(self.phases):
            if i > 0:
                out.append(Point(phase.at, i, tuple(phase.changes), True, phase.label, phase.entry))
            out += [Point(s.at, i, tuple(s.changes), False, s.label, s.entry) for s in phase.within]
        out.sort(key=lambda p: p.at)  # stable: a phase's start stays before its steps
        return tuple(out)

    def changes_of(self, key: str, before: Fraction | None = None) -> tuple[Fraction, ...]:
        """When the timeline after t = 0 sets ``key`` (``Leaf.param``), before ``before``."""
        return tuple(
            p.at
            for p in self.points()
            if (before is None or p.at < before) and any(c.key == key for c in p.changes)
        )

    def phases_before(self, end: Fraction | float) -> tuple[Phase, ...]:
        """The phases that start before ``end`` (phase 0 always): those a run stopped at
        ``end`` has entered."""
        return self.phases[:1] + tuple(p for p in self.phases[1:] if p.at < end)

    def phase_at(self, t: Fraction | float) -> int:
        """The phase in force at time ``t`` (a phase holds from its start, inclusive)."""
        return max(0, bisect.bisect_right(self.starts, t) - 1)

    @property
    def is_cut(self) -> bool:
        """Whether the run stops before the end its file planned."""
        return self.planned is not None

    def bounds(self) -> tuple[Fraction, ...]:
        """The planned phase starts followed by the planned end: the file's, even if cut.

        ``bounds()[i + 1]`` is where phase ``i`` was meant to end; a phase cut short ends at
        the run's duration instead, and its metrics are partial.
        """
        if self.planned is not None:
            return self.planned
        return (*self.starts, self.duration)

    def cut(self, t: Fraction) -> Timeline:
        """The timeline of the same run stopped at ``t`` (``--duration``): later changes drop.

        A cut at or after the end changes only the duration. A shorter run remembers the
        planned bounds (the first cut's, if cut twice), so the phase it stops in is reported
        as cut short rather than judged as if complete. The phases are new objects: the
        ones this timeline holds are left as they are.
        """
        t = Fraction(t)
        planned = self.planned
        if t < self.duration and planned is None:
            planned = self.bounds()
        phases: list[Phase] = []
        for i, phase in enumerate(self.phases):
            if i > 0 and phase.at >= t:
                break
            within = [s for s in phase.within if s.at < t]
            phases.append(phase if len(within) == len(phase.within) else _with_steps(phase, within))
        return Timeline(tuple(phases), t, planned)

    def with_start(self, changes: Iterable[Change]) -> Timeline:
        """The same timeline with ``changes`` as the values at t = 0, in place of phase 0's."""
        phase0 = dataclasses.replace(self.phases[0], changes=list(changes))
        return dataclasses.replace(self, phases=(phase0, *self.phases[1:]))

    def with_initial(self, changes: Iterable[Change]) -> Timeline:
        """The same timeline with ``changes`` added to the values at t = 0 (after the file's:
        a later assignment of one parameter wins).

        A file's assignment that one of ``changes`` overrides is dropped, not kept before it:
        the value never takes effect, and whatever lists phase 0's values (a bag's events, a
        run's description) would otherwise show the key twice with both values.
        """
        latest = {c.key: c for c in changes}  # of one key given twice, the last
        first = self.phases[0]
        kept = [c for c in first.changes if c.key not in latest]
        phase0 = dataclasses.replace(first, changes=[*kept, *latest.values()])
        return dataclasses.replace(self, phases=(phase0, *self.phases[1:]))


def _with_steps(phase: Phase, within: list) -> Phase:
    return dataclasses.replace(phase, within=within)
