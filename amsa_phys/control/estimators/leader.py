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
    (0 for a straight leader, 1 for one that keeps turning, about 0.5 for the random
    behaviour, which turns to a new heading every ``changePeriod`` s and then drives
    straight). A segment shorter than ``minTravel`` (a stopped leader, or only held fixes)
    gives no course. Fixes are taken at the first step at least a second after the previous
    one: run it at a rate whose period divides 1 s (the MDE world's 4 Hz).

    Noise: the MDE GPS's 1.5 cm per fix over a 0.9 m segment (4 s at 0.22 m/s) is 0.024 rad
    of course, so a straight leader's rates scatter by ~0.008 rad/s and the default
    threshold (0.02 rad/s) sits at 2.5 of those. Measured on the MDE world (seeds 1-3, from
    t = 40 s): a straight leader's share stays at or below 0.36 (0 once its start is out of
    the window), the random leader's spans 0 to 1 (a run of small heading changes looks
    straight for a while). Until ``window`` seconds have passed, both outputs are 0.

    A slow leader's segments are short, and the same fix noise is a larger course error on
    them (about 2.45 ``fixNoise`` / (L ``spacing``) rad/s of rate for two segments of length L: a
    straight leader at 0.06 m/s read as turning 70 % of the time when every segment over
    ``minTravel`` counted), and a pair of segments gives a course rate only when
    ``noiseFactor`` times that noise is within ``threshold`` (segments of at least 0.69 m at
    the defaults: 0.17 m/s over 4 s); the shares are of those rates alone. ``valid`` is 1
    when at least ``minShare`` of the window's seconds gave one, else 0: a leader too slow or
    stopped to show a course says nothing about how it turns (``turning`` is then 0).
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
            0.02,
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
            1.5,
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
            levels=((1.0, 0.0), (2.0, 1.0), (3.0, 0.0), (4.0, 0.35)),
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
