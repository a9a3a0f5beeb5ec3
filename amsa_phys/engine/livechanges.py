"""Changes a run takes while it runs: by hand (live), by ``adapt:`` rules, and events.

:class:`LiveChanges` is the part of ``Simulation`` (``runner.py``) that sets parameters at
an instant and records what happened: ``apply_change`` (timeline and live, the component
told after), ``apply_live`` (queued for the next instant the loop runs), the ``adapt:``
rules' firing, and the run's events. Kept apart from the hot loop so each module has one
job; the loop calls ``_apply_live`` and ``_apply_adapt`` at the point of the instant where
they belong (``Simulation._advance``).
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

from ..errors import RunFault
from ..model.adaptrules import RULE_COLUMN
from ..model.scenario import Change
from . import schedule
from .adapt import MAX_SWITCH_EVENTS
from .context import Event
from .plugs import Plugs
from .tasks import COMPONENT_ERRORS, in_run


class LiveChanges:
    """Parameter changes at an instant and the run's events (``Simulation``'s)."""

    # what ``Simulation`` provides
    members: list[dict[str, Any]]
    components: dict[str, Any]
    change_log: list[tuple[Fraction, Change]]
    live_changes: list[tuple[Fraction, Change]]
    events: list[Event]
    values: Any
    grid: Any
    _pending_live: list[Change]
    _adapt: Any
    _table: list[schedule.Entry]
    _cycle: int
    _cursor: int
    now: Fraction
    plugs: Plugs

    def initialize(self) -> None:  # pragma: no cover - Simulation's
        raise NotImplementedError

    def _who(self, path: str) -> str:  # pragma: no cover - Simulation's
        raise NotImplementedError

    @property
    def pending_live(self) -> list[Change]:
        """Live changes queued for the next instant, not yet applied."""
        return list(self._pending_live)

    def apply_change(self, change: Change) -> None:
        """Set a parameter now (timeline or live); the component is told after."""
        self._change(change, 0)

    def _change(self, change: Change, run: int) -> None:
        """:meth:`apply_change` in run ``run`` of a batch."""
        comp = self.members[run][change.leaf]
        setattr(comp.p, change.param, change.value)
        for group in getattr(self, "_groups_of", {}).get((run, change.leaf), ()):
            group.params.invalidate()
        self.change_log.append((self.now, change))
        try:
            comp.on_param_change(change.param, change.value)
        except RunFault as exc:
            in_run(exc, run)
            raise
        except COMPONENT_ERRORS as exc:
            why = f"on_param_change raised {exc!r}" if isinstance(exc, SystemExit) else exc
            fault = RunFault(
                self._who(change.leaf), self.now, f"rejected {change.param}={change.value!r}: {why}"
            )
            raise in_run(fault, run) from None  # a message, not a crash (--debug finds it)

    def next_instant(self) -> Fraction:
        """Time of the next instant at which something runs (where a live change lands)."""
        self.initialize()
        return self.grid.time(schedule.next_tick(self._table, self._cycle, self._cursor))

    def apply_live(self, change: Change) -> Fraction:
        """Queue a change made by hand (the window); it lands at :meth:`next_instant`.

        It is applied after the timeline changes due at that instant and before the
        components, exactly where a timeline entry at that time would be, so writing it into
        the resolved scenario's timeline replays the session. Returns the instant.
        """
        at = self.next_instant()
        self._pending_live.append(change)
        return at

    def _apply_live(self) -> None:
        pending, self._pending_live = self._pending_live, []
        for change in pending:
            self.apply_change(change)
            self.live_changes.append((self.now, change))
            self.record_event("live change", f"{change.key}={change.value}")

    def _apply_adapt(self) -> None:
        """Apply the ``adapt:`` rule due now, like a timeline change at this instant."""
        assert self._adapt is not None
        fired = self.plugs.rule_due(self._adapt, self.now, self.values)
        if fired is None:
            return
        rule, detail = fired
        for change in rule.changes:
            self.plugs.rule_change(change)
            self.apply_change(change)
        self.values[RULE_COLUMN] = float(rule.number)
        if self._adapt.switches <= MAX_SWITCH_EVENTS:  # later ones are counted, not kept
            self.record_event("adapt", detail)

    def _param_value(self, leaf: str, param: str) -> Any:
        """The value of ``leaf.param`` in force now."""
        return getattr(self.components[leaf].p, param)

    def record_event(self, kind: str, detail: str) -> None:
        """See :meth:`Context.record_event`."""
        self.events.append(Event(float(self.now), kind, detail))
