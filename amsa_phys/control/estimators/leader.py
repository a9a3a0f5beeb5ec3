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

    Every second the course of the last ``spacing`` seconds of track (the bearing from the
    fix then to the fix now) is compared with the course of the ``spacing`` seconds before:
    the difference over ``spacing`` is a course rate (overlapping segments: ~30 rates in a
    30 s window, so the share moves in steps of ~0.03). ``turnRate`` is the mean absolute
    rate over ``window`` seconds; ``turning`` the share of those rates above ``threshold``
    (0 for a straight leader, 1 for one that keeps turning, about 0.2 for the random
    behaviour, which turns to a new heading every ``changePeriod`` s and then drives
    straight). A segment shorter than ``minTravel`` (a stopped leader, or only held fixes)
    gives no course. Fixes are taken at the first step at least a second after the previous
    one: run it at a rate whose period divides 1 s (the MDE world's 4 Hz).

    Noise: a rate's noise is about 2.45 ``fixNoise`` / (L ``spacing``) rad/s for two
    segments of length L (the middle fix counts twice): 0.0104 rad/s for the MDE GPS's 1.5
    cm over 0.88 m (4 s at 0.22 m/s), measured 1.0-1.08 of that on a straight leader. A rate
    counts only when ``noiseFactor`` times its noise is within ``threshold`` (segments of at
    least 0.69 m at the defaults: 0.17 m/s over 4 s; a straight leader at 0.06 m/s read as
    turning 70 % of the time when every segment over ``minTravel`` counted), so
    ``threshold`` is at least 2.25 standard deviations of a counted rate's noise (2.9 at the
    MDE speed): a straight leader's rate exceeds it 0.4-2.4 % of the time (Gaussian noise).
    Both matter because one bad fix enters three rates (weights 1, -2, 1) and moves the
    share in steps of a tenth: at 0.02 rad/s and 1.5 (1.9 deviations at the MDE speed, 5-6 %
    of rates) a straight leader read as turning 0.27 for a window now and then (seeds 1 and
    5 of the MDE world). Measured there (seeds 1-6, from t = 40 s): a straight leader's
    share stays at or below 0.065, the random leader's averages 0.15-0.27 where valid (a run
    of small heading changes looks straight for a while). Until ``window`` seconds have
    passed, both outputs are 0.

    The shares are of counted rates alone. ``valid`` is 1 when at least ``minShare`` of the
    window's seconds gave one, else 0: a leader too slow or stopped to show a course says
    nothing about how it turns (``turning`` is then 0).
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.OBSERVER
    uses_random = False
    #: the windows are sized once, at initialize
    fixed_once_running = frozenset({"window", "spacing"})
    inputs = (
        Port("gpsPosX", 0.0, "the leader's GPS fix, x", "m"),
        Port("gpsPosY", 0.0, "the leader's GPS fix, y", "m"),
    )
    outputs = (
        Port("turning", 0.0, "share of the window spent turning (0..1)", ""),
        Port("turnRate", 0.0, "mean absolute course rate over the window", "rad/s"),
        Port("valid", 0.0, "1 when the window holds enough courses to judge, else 0", ""),
    )
    params = (
        Param("window", "float", "length of the estimate's window", 30.0, 1.0, 3600.0, "s"),
        Param(
            "spacing", "float", "time between the fixes a course is taken on", 4.0, 0.01, 60.0, "s"
        ),
        Param(
            "threshold",
            "float",
            "course rate above which the leader turns",
            0.03,
            0.0,
            10.0,
            "rad/s",
        ),
        Param("minTravel", "float", "shortest segment with a course", 0.2, 0.0, 100.0, "m"),
        Param("fixNoise", "float", "the GPS fixes' noise per axis", 0.015, 0.0, 10.0, "m"),
        Param(
            "noiseFactor",
            "float",
            "a course rate counts when its noise times this is within threshold",
            2.25,
            0.0,
            100.0,
            "",
        ),
        Param(
            "minShare",
            "float",
            "share of the window's seconds with a course for a valid estimate",
            0.25,
            0.0,
            1.0,
            "",
        ),
    )
    estimates = (
        Estimates(
            "turning",
            "behavior",
            ("freeRobot",),
            levels=((1.0, 0.0), (2.0, 1.0), (3.0, 0.0), (4.0, 0.2)),
        ),
    )

    def initialize(self, ctx: Any) -> None:
        """No track yet."""
        self.rates: Window[float] = Window(self.p.window)
        #: fixes kept once a second (the last 2 x ``spacing`` s of them)
        self.track: Window[tuple[float, float]] = Window(2 * self.p.spacing)
        self.started: float | None = None

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: a new course rate every second, then the window's shares."""
        now = float(t)
        p = self.p
        if self.started is None:
            self.started = now
        track = self.track
        if not track.items or now - track.items[-1][0] >= 1.0 - 1e-9:
            track.add(now, (inp["gpsPosX"], inp["gpsPosY"]))
            rate = self._rate(now)
            if rate is not None:
                self.rates.add(now, rate)
        rates = self.rates.items
        if now - self.started < p.window - 1e-9:
            return {"turning": 0.0, "turnRate": 0.0, "valid": 0.0}
        valid = 1.0 if rates and len(rates) >= p.minShare * p.window else 0.0
        if not rates:
            return {"turning": 0.0, "turnRate": 0.0, "valid": valid}
        n = len(rates)
        return {
            "turning": sum(1 for _, r in rates if r > p.threshold) / n,
            "turnRate": sum(r for _, r in rates) / n,
            "valid": valid,
        }

    def _rate(self, now: float) -> float | None:
        """|course change| / ``spacing`` between the last two ``spacing``-s segments (None:
        the track is too short, a segment under ``minTravel``, or too short for its course
        rate's noise to be within ``threshold``)."""
        p = self.p
        points = {round(t - now, 6): xy for t, xy in self.track.items}
        a, b, c = (
            points.get(round(-2 * p.spacing, 6)),
            points.get(round(-p.spacing, 6)),
            points.get(0.0),
        )
        if a is None or b is None or c is None:
            return None
        first_len = math.hypot(b[0] - a[0], b[1] - a[1])
        second_len = math.hypot(c[0] - b[0], c[1] - b[1])
        shortest = min(first_len, second_len)
        if shortest < p.minTravel or shortest == 0.0:
            return None
        noise = math.sqrt(6.0) * p.fixNoise / (shortest * p.spacing)
        if p.noiseFactor * noise > p.threshold:
            return None
        first = math.atan2(b[1] - a[1], b[0] - a[0])
        second = math.atan2(c[1] - b[1], c[0] - b[0])
        turn = (second - first + math.pi) % (2 * math.pi) - math.pi
        return abs(turn) / p.spacing
