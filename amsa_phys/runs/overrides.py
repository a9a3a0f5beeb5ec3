"""What a ``--set`` (or ``amsa_phys.run(set=...)``) will not do: hold past the timeline.

An override sets a value at t = 0; a timeline entry that sets the same parameter later
replaces it, so the value given shapes only the phases before that entry, and the overall
metrics mix in the file's later value. The sweep says so for a swept parameter
(``runs.sweep.timeline_overlaps``); a single run says so too, once, before it starts:
the CLI as a ``warning:`` line on stderr, the API as an :class:`OverrideWarning`. The text
is made here, once; each front end only says which of its options it is about.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

from ..model.changes import PHYSICS_PREFIX, parse_setting
from ..model.scenario import Scenario


class OverrideWarning(UserWarning):
    """A value given to ``amsa_phys.run(set=...)`` is replaced later by the timeline."""


def timeline_notes(scenario: Scenario, overrides: Sequence[str], option: str) -> list[str]:
    """One line per overridden parameter the timeline sets again before the run ends.

    ``overrides`` are the ``Comp.param=V`` texts (already judged by the loader); ``option``
    is how the front end names them (``--set`` or ``set=``). Physics settings and Leaf
    frequencies hold for the whole run (a timeline cannot change them): never named.
    """
    keys: dict[str, str] = {}  # resolved key -> as written
    for text in overrides:
        if text.strip().startswith(PHYSICS_PREFIX):
            continue
        change, _world = parse_setting(text, scenario.world)
        if change is not None:
            keys[change.key] = change.written_key
    notes = []
    for key, written in keys.items():
        times = scenario.timeline.changes_of(key, before=scenario.duration)
        if not times:
            continue
        first = min(times)
        when = ", ".join(f"{float(t):g}" for t in sorted(times))
        notes.append(
            f"{written} is given by {option}, but the scenario's timeline sets it again "
            f"(at {when} s): the value given holds only until {float(first):g} s, so it "
            f"shapes {_reach(scenario, first)}"
        )
    return notes


def _reach(scenario: Scenario, first: Fraction) -> str:
    """Which part of the run the value given shapes: ``phase 0 only``, ``phases 0-2``."""
    starts = list(scenario.timeline.starts)
    if first in starts:
        index = starts.index(first)
        return "phase 0 only" if index == 1 else f"phases 0-{index - 1}"
    return f"the first {float(first):g} s of phase {scenario.timeline.phase_at(first)}"
