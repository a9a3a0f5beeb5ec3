"""The window's parameter panel: pick any parameter of any component, edit it within range.

Pure logic (no pygame), so the keyboard behaviour is tested directly. Arrow keys step a
*pending* value and typing replaces it; nothing reaches the simulation until Enter, so
holding an arrow key does not write fifty timeline entries. The committed value goes through
the parameter's own ``coerce`` (type, [min, max]) — the same check a scenario file gets.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..engine.face import SimView
from ..model.params import Param
from ..model.scenario import Change
from ..valuetext import value_text

#: Steps per full range for the arrow keys (Shift: ten times finer).
COARSE_STEPS = 20
FINE_STEPS = 200
EDITABLE_TYPES = ("int", "float", "bool", "enum")


@dataclass(frozen=True)
class Row:
    """One editable parameter."""

    leaf: str
    param: Param
    fixed: bool  # read only at initialize: shown, not editable once running

    @property
    def editable(self) -> bool:
        """A number, a flag or a choice: what arrows and typing can change. A list of points
        (``Leader.waypoints``) or a text is shown, with its value, but set in the scenario."""
        return self.param.type in EDITABLE_TYPES

    @property
    def key(self) -> str:
        """``Leaf.param``."""
        return f"{self.leaf}.{self.param.name}"


class ParamPanel:
    """Selection, pending value and feedback of the parameter panel."""

    def __init__(self, sim: SimView) -> None:
        self.sim = sim
        self.rows = [
            Row(path, p, p.name in comp.fixed_once_running)
            for path, comp in sim.components.items()
            for p in comp.params
        ]
        self.visible = False
        self.index = 0
        self.pending: Any = None  # a value stepped with the arrows
        self.text: str | None = None  # a value being typed
        self.message = ""
        #: the message says a value was refused (drawn in the alert colour)
        self.refused = False

    # -- reading -------------------------------------------------------------------------
    @property
    def row(self) -> Row:
        """The selected row."""
        return self.rows[self.index]

    def value(self, row: Row | None = None) -> Any:
        """The value in force in the running component."""
        row = row or self.row
        return getattr(self.sim.components[row.leaf].p, row.param.name)

    def shown(self, row: Row) -> str:
        """How the value of ``row`` is printed (pending edit included for the selection)."""
        current = _fmt(self.value(row))
        if row is not self.row:
            return current
        if self.text is not None:
            return f"{current} -> {self.text}_"
        if self.pending is not None:
            return f"{current} -> {_fmt(self.pending)}"
        return current

    def lines(self, height: int = 14) -> list[str]:
        """The rows around the selection, for drawing."""
        if not self.rows:
            return ["no editable parameters"]
        start = max(0, min(self.index - height // 2, len(self.rows) - height))
        out = []
        for i in range(start, min(len(self.rows), start + height)):
            row = self.rows[i]
            mark = ">" if i == self.index else " "
            lock = " (fixed)" if row.fixed else ""
            if not row.editable:
                lock = " (set it in the scenario)"
            span = f"  {row.param.range_text()}" if row.editable else ""
            out.append(f"{mark} {row.key} = {self.shown(row)}{span}{lock}")
        return out

    # -- navigation ----------------------------------------------------------------------
    def move(self, delta: int) -> None:
        """Select another row (the pending edit is dropped)."""
        if self.rows:
            self.index = (self.index + delta) % len(self.rows)
        self.cancel()

    def next_component(self, direction: int) -> None:
        """Jump to the first parameter of the next (or previous) component."""
        if not self.rows:
            return
        leaf = self.row.leaf
        i = self.index
        for _ in range(len(self.rows)):
            i = (i + direction) % len(self.rows)
            if self.rows[i].leaf != leaf:
                break
        while direction < 0 and i > 0 and self.rows[i - 1].leaf == self.rows[i].leaf:
            i -= 1
        self.index = i
        self.cancel()

    # -- editing -------------------------------------------------------------------------
    def step(self, direction: int, fine: bool = False) -> None:
        """Step the pending value by a share of the range (enum: next choice; bool: flip)."""
        p = self.row.param
        if not self.row.editable:
            self._not_here()
            return
        base = self.pending if self.pending is not None else self.value()
        self.text = None
        if p.type == "bool":
            self.pending = not base
        elif p.type == "enum":
            choices = list(p.choices or ())
            i = choices.index(base) if base in choices else 0
            self.pending = choices[(i + direction) % len(choices)]
        else:
            lo = p.min if p.min is not None else None
            hi = p.max if p.max is not None else None
            if lo is not None and hi is not None:
                step = (hi - lo) / (FINE_STEPS if fine else COARSE_STEPS)
            else:
                step = max(abs(base) * (0.01 if fine else 0.1), 0.01)
            if p.type == "int":
                step = max(1, round(step))
            value = base + direction * step
            if lo is not None:
                value = max(lo, value)
            if hi is not None:
                value = min(hi, value)
            self.pending = round(value) if p.type == "int" else round(value, 10)

    def type_char(self, ch: str) -> None:
        """Typing a number replaces the pending value."""
        if not self.row.editable:
            self._not_here()
        elif ch and (ch.isdigit() or ch in ".-+e"):
            self.text = (self.text or "") + ch
            self.pending = None

    def backspace(self) -> None:
        """Delete the last typed character."""
        if self.text:
            self.text = self.text[:-1]

    def cancel(self) -> None:
        """Forget the pending edit."""
        self.pending = None
        self.text = None

    def commit(self) -> Change | None:
        """The checked Change for the pending value, or None (message says why)."""
        row = self.row
        self.refused = True  # until the value passes every check
        if row.fixed:
            self.message = f"{row.key} is fixed once the run has started"
            self.cancel()
            return None
        if not row.editable:
            self._not_here()
            return None
        raw: Any = self.pending
        if self.text is not None:
            try:
                raw = float(self.text)
                if raw.is_integer() and row.param.type in ("int", "enum"):
                    raw = int(raw)
            except ValueError:
                self.message = f"{row.key}: {self.text!r} is not a number"
                self.text = None
                return None
        if raw is None:
            self.message = "change the value first (arrows or type a number), then Enter"
            return None
        comp = self.sim.components[row.leaf]
        try:
            value = row.param.coerce(raw)
            # the template's rules between parameters: refused here, the run goes on
            comp.check_params({**comp.p.as_dict(), row.param.name: value})
        except ValueError as exc:
            self.message = f"{row.key}: {exc}"
            self.cancel()
            return None
        self.cancel()
        self.refused = False
        return Change(row.leaf, row.param.name, value)

    def _not_here(self) -> None:
        """Say why the selected row does not change here (a list of points, a text)."""
        row = self.row
        self.message = (
            f"{row.key} is a {row.param.type} parameter: set it in the scenario "
            f"(set: or timeline:), not here"
        )
        self.refused = True
        self.cancel()


def _fmt(value: Any) -> str:
    return value_text(value)  # as the HUD, the replay and the run's table print it
