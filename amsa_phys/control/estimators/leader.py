"""LeaderMonitor: does the leader drive straight or turn, from its GPS track."""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ...model.params import Param
from ...model.template import Kind, Port, Template
from . import Estimates
from .window import Window


class LeaderMonitor(Template):
    """How much of the time the leader turns: its course rate from GPS fixes.

    Every ``spacing`` seconds the course of the last ``spacing`` seconds of track (the
    bearing from the fix then to the fix now) is compared with the previous one: the
    difference over ``spacing`` is a course rate. ``turnRate`` is the mean absolute rate
    over ``window`` seconds; ``turning`` the share of those rates above ``threshold``
    (0 for a straight leader, near 1 for one that keeps turning). A segment shorter than
    ``minTravel`` (a stopped leader, or only held fixes) gives no course, and the
    comparison restarts after it. Noise: the MDE GPS's 1.5 cm per fix over a 0.9 m segment
    (4 s at 0.22 m/s) is 0.024 rad of course, so a straight leader's rates scatter by about
    0.008 rad/s; the default threshold (0.02 rad/s) sits at 2.5 of those, and a leader on
    the random behaviour (a new heading within ±1.2 rad every 10 s) turns at ~0.06 rad/s.
    Until ``window`` seconds of rates are in, both outputs are 0.
    """

    kind = Kind.OBSERVER
    uses_random = False
    inputs = (
        Port("gpsPosX", 0.0, "the leader's GPS fix, x", "m"),
        Port("gpsPosY", 0.0, "the leader's GPS fix, y", "m"),
    )
    outputs = (
        Port("turning", 0.0, "share of the window spent turning (0..1)", ""),
        Port("turnRate", 0.0, "mean absolute course rate over the window", "rad/s"),
    )
    params = (
        Param("window", "float", "length of the estimate's window", 30.0, 1.0, 3600.0, "s"),
        Param("spacing", "float", "time between the fixes a course is taken on", 4.0, 0.01, 60.0, "s"),
        Param("threshold", "float", "course rate above which the leader turns", 0.02, 0.0, 10.0, "rad/s"),
        Param("minTravel", "float", "shortest segment with a course", 0.2, 0.0, 100.0, "m"),
    )
    estimates = (
        Estimates("turning", "behavior", ("freeRobot",), levels=((1.0, 0.0), (2.0, 1.0), (3.0, 0.0), (4.0, 0.5))),
    )

    def initialize(self, ctx: Any) -> None:
        """No track yet."""
        self.rates: Window[float] = Window(self.p.window)
        self.fix: tuple[float, float, float] | None = None
        self.course: float | None = None
        self.started = 0.0

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: a new course every ``spacing`` s, then the window's shares."""
        now = float(t)
        p = self.p
        x, y = inp["gpsPosX"], inp["gpsPosY"]
        if self.fix is None:
            self.fix = (now, x, y)
            self.started = now
            return {}
        t0, x0, y0 = self.fix
        if now - t0 >= p.spacing - 1e-9:
            self.fix = (now, x, y)
            if math.hypot(x - x0, y - y0) < p.minTravel:
                self.course = None
            else:
                course = math.atan2(y - y0, x - x0)
                if self.course is not None:
                    turn = (course - self.course + math.pi) % (2 * math.pi) - math.pi
                    self.rates.add(now, abs(turn) / (now - t0))
                self.course = course
        rates = self.rates.items
        if not rates or now - self.started < p.window - 1e-9:
            return {"turning": 0.0, "turnRate": 0.0}
        n = len(rates)
        return {
            "turning": sum(1 for _, r in rates if r > p.threshold) / n,
            "turnRate": sum(r for _, r in rates) / n,
        }
