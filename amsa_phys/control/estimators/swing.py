"""SwingMonitor: how far and how fast the follower's distance swings, from the distance alone.

A gain that is right for the context holds the distance with small swings; a gain set for
weaker motors than the rover has (or set while catching up from far behind) makes the loop
overshoot, and the distance swings by metres with the loop's own period. The motor estimate
cannot tell the two apart (both make its window's command cancel out: *unsure*), and the
path speed shows a swing only once it is fast. This monitor watches the loop itself: the
turning points of the measured distance (a turning point is an extreme the distance has
since left by more than ``deadband``: fix noise and the small steady swing of a right gain
do not make one), and from the last few of them

* ``amplitude``: the window's largest half swing (half the distance between two consecutive
  turning points), in metres: it stays up for a window after a swing dies out, so a rule
  reading it below a level waits that long;
* ``period``: twice the mean time between the window's consecutive turning points, in
  seconds;
* ``growth``: the last half swing over the one before (above 1: growing);
* ``valid``: 1 when the last ``window`` seconds hold at least three turning points (two
  complete half swings): a follower closing a gap steadily, or tracking a leader with swings
  inside the deadband, has none, and every output is then 0, so a rule reading
  ``amplitude`` fires only on a swing the window has seen turn twice.

Nothing is held from before the window: once its turning points have left it, a swing that
died out reads 0 again.
"""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from itertools import pairwise
from typing import Any

from ...model.params import Param
from ...model.template import Kind, Port, Template
from .window import Window


class SwingMonitor(Template):
    """Amplitude, period and growth of the distance's swings over the last ``window`` s."""

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.OBSERVER
    uses_random = False
    #: the window is sized once, at initialize
    fixed_once_running = frozenset({"window"})
    inputs = (Port("distance", 0.0, "the measured distance to the leader", "m"),)
    outputs = (
        Port("amplitude", 0.0, "the largest half swing in the window (0: not valid)", "m"),
        Port("period", 0.0, "the swings' period over the window (0: not valid)", "s"),
        Port("growth", 0.0, "the last half swing over the one before (0: not valid)", ""),
        Port("valid", 0.0, "1 when the window holds two complete half swings", ""),
    )
    params = (
        Param(
            "window",
            "float",
            "how far back turning points count (two swings of the loop's period)",
            60.0,
            1.0,
            3600.0,
            "s",
        ),
        Param(
            "deadband",
            "float",
            "how far the distance must leave an extreme for it to be a turning point",
            0.1,
            0.0,
            100.0,
            "m",
        ),
    )

    def initialize(self, ctx: Any) -> None:
        """No sample yet: no direction, no turning point."""
        self.turns: Window[float] = Window(self.p.window)
        #: +1 rising, -1 falling, 0 not yet known
        self.direction = 0
        #: the running extreme since the last turning point (or the first sample's min/max)
        self.high: tuple[float, float] | None = None
        self.low: tuple[float, float] | None = None

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """Find a turning point in this sample, then describe the window's last swings."""
        now = float(t)
        x = float(inp["distance"])
        band = self.p.deadband
        if self.high is None or self.low is None:
            self.high = self.low = (now, x)
        if x > self.high[1]:
            self.high = (now, x)
        if x < self.low[1]:
            self.low = (now, x)
        if self.direction >= 0 and self.high[1] - x > band:
            # the distance has left its highest value by more than the band: a peak
            if self.direction > 0:
                self.turns.add(self.high[0], self.high[1])
            self.direction = -1
            self.low = (now, x)
        elif self.direction <= 0 and x - self.low[1] > band:
            if self.direction < 0:
                self.turns.add(self.low[0], self.low[1])
            self.direction = 1
            self.high = (now, x)
        # turning points older than the window leave it even while none is found
        limit = now - self.p.window
        items = self.turns.items
        while items and items[0][0] < limit:
            items.popleft()
        if len(items) < 3:
            return {"amplitude": 0.0, "period": 0.0, "growth": 0.0, "valid": 0.0}
        values = [v for _, v in items]
        halves = [abs(b - a) / 2.0 for a, b in pairwise(values)]
        last, before = halves[-1], halves[-2]
        period = 2.0 * (items[-1][0] - items[0][0]) / (len(items) - 1)
        return {
            "amplitude": max(halves),
            "period": period,
            "growth": last / before if before > 0 else 0.0,
            "valid": 1.0,
        }
