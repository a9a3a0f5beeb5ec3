"""MotorMonitor: the share of the commanded power the motors deliver, from GPS and commands."""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ...model.params import Param
from ...model.template import Kind, Port, Template
from . import Estimates
from .window import Window


class MotorMonitor(Template):
    """Delivered fraction of power: what the speed shows against what was commanded.

    The rover's known power–speed curve (the controller's own model, ``frictionPower`` +
    100 · v / ``maxSpeed`` % holds speed v on flat ground) turns the speed the robot's GPS
    fixes show into the power that reached the wheels; divided by the mean power the
    controller commanded (the mean of ``powerL`` and ``powerR``: turning cancels out) over
    the same ``window`` seconds, it is the motors' delivered fraction (1 for healthy
    motors, 0.6 for the paper's worn ones, ``motorCoef`` 60).

    The speed is the path length over the window from fixes taken ``spacing`` s apart
    (0.22 m at the MDE leader's speed against 2 cm of fix noise: a bias under 1 %), so a
    turning rover's speed is not mistaken for a slower one. The ratio of window means is
    exact in steady state and biased in a transient by about (speed change) x (the rover's
    speed time constant, ~10 s) / ``window``: a 30 s window keeps a follower's usual
    oscillations within ~0.1. Below ``minPower`` % of mean command the ratio is noise, and
    the estimate is held; it starts at 1 (healthy motors) until ``window`` seconds of
    samples are in.

    ``valid`` says whether the window's estimate can be trusted (1) or not (0): the model
    above holds for a rover driving forward, so a window whose commands largely cancel out
    (a follower oscillating about its reference, reversing to back off) says nothing about
    the motors -- its path length counts backward travel as forward and its mean command
    shrinks towards 0, which read as delivered shares of 2 to 10 with healthy motors. A few
    brief reversals do not move a rover whose speed has a 10 s time constant backward, and
    the ratio stays right; so the window is judged by how much of its command cancels out
    (1 - mean / mean magnitude, at most ``maxReverse``), not by whether any command
    reversed: a high gain on worn motors reverses now and then, and refusing every such
    window blinded the estimate exactly where the gain it chose was running. A share above
    ``maxShare`` is physically impossible (motors deliver at most what is commanded), so it
    is invalid too. While invalid, ``delivered`` holds the last valid estimate; a valid one
    between 1 and ``maxShare`` (noise about healthy motors) is published as 1.

    A window that cancels out is not evidence against the last valid estimate: a follower
    whose leader stops backs off for a few seconds whatever its motors, and a right gain
    does so as often as a wrong one. With ``validHold`` > 0 the confidence in the held
    estimate decays, from 1 to 0 over ``validHold`` seconds since the last valid window,
    instead of dropping to 0 at once (a rule waiting for ``valid`` below 0.5 fires half the
    hold later). A loop that oscillates for good never yields a valid window again, so its
    confidence still runs out; 0 (the default) drops it at once. How much cancels out tells
    the two apart sooner, though not cleanly: in the held-out runs of docs/adaptation.md a
    right gain backing off after its leader stops cancelled up to 0.37 of a 30 s window's
    command, a wrong one oscillating 0.15 to 1. A window where more than ``holdReverse``
    cancels out ends the hold at once (the confidence is 0 until the next valid window).

    With ``forwardPower`` > 0 the window is judged over its forward seconds only: a path
    segment counts when every command in it is at least ``forwardPower`` % and has been
    for ``settle`` s (a rover that was reversing is still moving backward when the command
    turns forward, and the path counts that as forward), the command is taken as the
    actuator delivers it (each wheel within ``powerMax``: a saturated loop's 150 % moves
    the rover as 100 % does), and the power that went into changing speed is taken per
    run of counted segments. A window with less than ``minForward`` of its time counted is
    unsure, unless its mean command magnitude is below ``quietPower`` % (a follower
    waiting for a stopped leader says nothing about its motors: the last estimate and
    confidence stand), or, with ``wholeWindow`` 1, judged as a whole as without
    ``forwardPower`` (a right high gain reversing briefly and often leaves too few seconds
    after its settling, yet little of its command cancels out). ``maxReverse`` applies
    only to a window judged whole. Off by default: measured on
    held-out sequences (docs/adaptation.md), it makes a right gain that backs off after a
    leader's stop sure and keeps an oscillating wrong one unsure, but it also leaves a
    very worn motor's high gain unsure more often, and no setting was better everywhere.
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.OBSERVER
    uses_random = False
    #: the windows are sized once, at initialize
    fixed_once_running = frozenset({"window", "speedWindow", "recentWindow"})
    inputs = (
        Port("powerL", 0.0, "commanded left power", "%"),
        Port("powerR", 0.0, "commanded right power", "%"),
        Port("posX", 0.0, "the rover's GPS fix, x", "m"),
        Port("posY", 0.0, "the rover's GPS fix, y", "m"),
    )
    outputs = (
        Port("delivered", 1.0, "share of commanded power delivered (0..1)", ""),
        Port("valid", 0.0, "1 when the window's estimate can be trusted, else 0", ""),
        Port("pathSpeed", 0.0, "mean path speed over speedWindow (0 until full)", "m/s"),
        Port(
            "recent",
            0.0,
            "share over the last recentWindow s, 0 when that window cannot judge (0..1)",
            "",
        ),
    )
    params = (
        Param("window", "float", "length of the estimate's window", 30.0, 1.0, 3600.0, "s"),
        Param(
            "spacing",
            "float",
            "time between the fixes the path is measured on",
            1.0,
            0.01,
            60.0,
            "s",
        ),
        Param(
            "maxSpeed",
            "float",
            "speed gained per 100 % of power (rover model)",
            5.5,
            0.01,
            100.0,
            "m/s",
        ),
        Param(
            "frictionPower",
            "float",
            "power that overcomes rolling resistance (rover model)",
            2.9,
            0.0,
            100.0,
            "%",
        ),
        Param("minPower", "float", "least mean command for an estimate", 3.0, 0.01, 100.0, "%"),
        Param(
            "timeConstant",
            "float",
            "the rover's speed time constant (rover model)",
            10.0,
            0.0,
            600.0,
            "s",
        ),
        Param(
            "edge",
            "float",
            "time over which the window's first and last speeds are taken",
            4.0,
            0.01,
            60.0,
            "s",
        ),
        Param(
            "maxReverse",
            "float",
            "largest share of the window's command that may cancel out (reversals)",
            0.1,
            0.0,
            1.0,
            "",
        ),
        Param(
            "maxShare",
            "float",
            "largest plausible share (noise above 1); a larger one is invalid",
            1.15,
            1.0,
            10.0,
            "",
        ),
        Param(
            "validHold",
            "float",
            "time over which the confidence in the last valid estimate decays to 0",
            0.0,
            0.0,
            600.0,
            "s",
        ),
        Param(
            "forwardPower",
            "float",
            "least command for a second to count in the estimate (0: every second counts)",
            0.0,
            0.0,
            100.0,
            "%",
        ),
        Param(
            "powerMax",
            "float",
            "the actuator's limit on each wheel's command (with forwardPower)",
            100.0,
            0.01,
            1000.0,
            "%",
        ),
        Param(
            "settle",
            "float",
            "time the command must have been forward before a second counts (with forwardPower)",
            5.0,
            0.0,
            600.0,
            "s",
        ),
        Param(
            "quietPower",
            "float",
            "mean command magnitude below which a window without enough forward time keeps "
            "the last estimate and confidence (with forwardPower)",
            0.0,
            0.0,
            100.0,
            "%",
        ),
        Param(
            "wholeWindow",
            "float",
            "1: a window with too few forward seconds is judged whole (with forwardPower)",
            0.0,
            0.0,
            1.0,
            "",
        ),
        Param(
            "minForward",
            "float",
            "least share of the window that must count for an estimate (with forwardPower)",
            0.5,
            0.0,
            1.0,
            "",
        ),
        Param(
            "speedWindow",
            "float",
            "window of pathSpeed (0: the estimate's window)",
            0.0,
            0.0,
            3600.0,
            "s",
        ),
        Param(
            "recentWindow",
            "float",
            "window of the recent share (0: off, recent stays 0)",
            0.0,
            0.0,
            3600.0,
            "s",
        ),
        Param(
            "holdReverse",
            "float",
            "cancelling-out share of the window's command that ends validHold at once (1: never)",
            1.0,
            0.0,
            1.0,
            "",
        ),
    )
    estimates = (Estimates("delivered", "motorCoef", ("NormalizePower",), scale=0.01),)

    def initialize(self, ctx: Any) -> None:
        """Healthy motors until shown otherwise."""
        self.power: Window[float] = Window(self.p.window)
        self.path: Window[float] = Window(self.p.window)
        self.speed_path: Window[float] = Window(self.p.speedWindow or self.p.window)
        self.path_speed = 0.0
        self.recent_power: Window[float] = Window(self.p.recentWindow)
        self.recent_path: Window[float] = Window(self.p.recentWindow)
        self.recent = 0.0
        self.fix: tuple[float, float, float] | None = None
        #: each path segment as (duration, length, command sum, command count, counts), where
        #: it counts when its every command was forward and had been for ``settle`` s
        self.segments: Window[tuple[float, float, float, int, bool]] = Window(self.p.window)
        self.seg_sum, self.seg_count, self.seg_low = 0.0, 0, math.inf
        self.forward_since: float | None = None  # the start of the forward run, if any
        self.estimate = 1.0
        self.valid = 0.0
        self.valid_at: float | None = None  # when the last valid window ended

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: add the command and (every ``spacing`` s) the path, estimate."""
        now = float(t)
        p = self.p
        self.power.add(now, 0.5 * (inp["powerL"] + inp["powerR"]))
        if p.recentWindow > 0:
            self.recent_power.add(now, 0.5 * (inp["powerL"] + inp["powerR"]))
        x, y = inp["posX"], inp["posY"]
        if self.fix is None:
            self.fix = (now, x, y)
        elif now - self.fix[0] >= p.spacing - 1e-9:
            step = math.hypot(x - self.fix[1], y - self.fix[2])
            self.path.add(now, step)
            self.speed_path.add(now, step)
            self.path_speed = self._path_speed()
            if p.recentWindow > 0:
                self.recent_path.add(now, step)
            # the segment's commands are those from its first fix up to (not with) this one
            counts = (
                self.seg_count > 0
                and self.seg_low >= p.forwardPower
                and self.forward_since is not None
                and self.fix[0] - self.forward_since >= p.settle - 1e-9
            )
            segment = (now - self.fix[0], step, self.seg_sum, self.seg_count, counts)
            self.segments.add(now, segment)
            self.seg_sum, self.seg_count, self.seg_low = 0.0, 0, math.inf
            self.fix = (now, x, y)
        # what reaches the motors: each wheel's command within the actuator's limit
        hi = p.powerMax
        power = 0.5 * (min(hi, max(-hi, inp["powerL"])) + min(hi, max(-hi, inp["powerR"])))
        if power < p.forwardPower:
            self.forward_since = None
        elif self.forward_since is None:
            self.forward_since = now
        self.seg_sum += power
        self.seg_count += 1
        self.seg_low = min(self.seg_low, power)
        if p.forwardPower > 0:
            if self.power.covered_s() >= p.window - 1e-9 and self.path.covered_s() > 0:
                self._forward_estimate(now)
        elif self.power.covered_s() >= p.window - 1e-9 and self.path.covered_s() > 0:
            self._window_estimate(now)
        if p.recentWindow > 0:
            self.recent = self._recent_share()
        return {
            "delivered": self.estimate,
            "valid": self.valid,
            "pathSpeed": self.path_speed,
            "recent": self.recent,
        }

    def _path_speed(self) -> float:
        """Path length over the speed window's span, once it is full (else 0).

        The path counts backward travel as forward, so a follower swinging about its
        reference shows a high path speed whatever its mean progress: what tells a loop
        swinging on strong motors (0.46-0.88 m/s in docs/adaptation.md's runs) from a high
        gain reversing now and then on weak ones (0.18-0.31 m/s), which the share's
        confidence cannot (both make the window's command cancel out).
        """
        window = self.speed_path
        if window.covered_s() < window.span_s - 1e-9:
            return 0.0
        steps = window.items
        # the first segment ends at the window's start: it lies before the span
        return (sum(d for _, d in steps) - steps[0][1]) / (steps[-1][0] - steps[0][0])

    def _recent_share(self) -> float:
        """The share over the last ``recentWindow`` s, judged as the whole window is (0 when
        that window is not full, its command is too small or cancels out, or the share is
        impossible); its speeds at the edges are taken over a quarter of it (at most ``edge``).

        Why a second, short window: a high gain set for very worn motors stays in force on
        motors that recover until the 30 s estimate turns unsure, and by then the loop swings.
        Over a few seconds the follower, pushed by a worn motors' command on strong motors,
        accelerates as those motors do: the short window shows the share going up before
        the command reverses (docs/adaptation.md). It is not held: an unsure short window
        says nothing, and a rule reading it fires only on a window that judged.
        """
        p = self.p
        steps = self.recent_path.items
        if self.recent_power.covered_s() < p.recentWindow - 1e-9 or len(steps) < 2:
            return 0.0
        span = steps[-1][0] - steps[0][0]
        length = sum(d for _, d in steps) - steps[0][1]
        edge = min(p.edge, 0.25 * p.recentWindow)
        first = self._speed_over(list(steps), edge, True)
        last = self._speed_over(list(reversed(steps)), edge, False)
        speed = length / span + p.timeConstant * (last - first) / span
        power = self.recent_power.items
        command = sum(v for _, v in power) / len(power)
        magnitude = sum(abs(v) for _, v in power) / len(power)
        # the least command scales as the window shortens: ``minPower`` is the whole
        # window's, and a path speed over a window k times shorter is k times noisier
        least = max(p.minPower, p.minPower * p.window / p.recentWindow)
        if command < least or command < (1.0 - p.maxReverse) * magnitude:
            return 0.0
        share = (p.frictionPower + 100.0 * speed / p.maxSpeed) / command
        return min(share, 1.0) if share <= p.maxShare else 0.0

    def _speed_over(self, steps: list[tuple[float, float]], edge: float, first: bool) -> float:
        """Mean speed over ``edge`` s from ``steps[0]`` (oldest first when ``first``)."""
        t_edge = steps[0][0]
        total = count = 0.0
        for i, (t, d) in enumerate(steps):
            if i == 0 and first:
                continue  # the first segment ends at the window's start
            if abs(t - t_edge) > edge + 1e-9:
                break
            total += d
            count += 1
        return total / (count * self.p.spacing) if count else 0.0

    def _window_estimate(self, now: float) -> None:
        """The share over the whole window (the default; see the class docstring)."""
        p = self.p
        steps = self.path.items
        span = steps[-1][0] - steps[0][0]
        # the first segment ends at steps[0]: it lies before the span, leave it out
        length = sum(d for _, d in steps) - steps[0][1]
        speed = length / span
        # power also went into changing speed: tau * (v_last - v_first) / span on top of
        # the speed's own share (first-order rover: P ~ v + tau dv/dt)
        speed += p.timeConstant * (self._edge_speed(-1) - self._edge_speed(0)) / span
        command = sum(v for _, v in self.power.items) / len(self.power)
        magnitude = sum(abs(v) for _, v in self.power.items) / len(self.power)
        # forward enough: at most maxReverse of the command cancels out (0: none reversed)
        forward = command >= (1.0 - p.maxReverse) * magnitude
        self.valid = 0.0
        if command >= p.minPower and forward:
            share = (p.frictionPower + 100.0 * speed / p.maxSpeed) / command
            if share <= p.maxShare:
                self.estimate = min(share, 1.0)
                self.valid = 1.0
                self.valid_at = now
        if p.holdReverse < 1.0 and command < (1.0 - p.holdReverse) * magnitude:
            self.valid_at = None  # oscillating: the held estimate is not to be trusted
        if self.valid == 0.0 and self.valid_at is not None and p.validHold > 0:
            self.valid = max(0.0, 1.0 - (now - self.valid_at) / p.validHold)

    def _forward_estimate(self, now: float) -> None:
        """The share over the window's forward seconds only (``forwardPower`` > 0).

        A segment counts when every command in it is at least ``forwardPower``: a leader's
        stop (the follower backing off, or idling at the reference distance) is left out of
        both the command and the path, so it neither corrupts the estimate nor makes it
        unsure, and an oscillating loop's forward strokes still show the motors' share. The
        power that went into changing speed is taken per forward stretch (a run of counted
        segments), since the speed jumps across the gaps between them.
        """
        p = self.p
        seconds = length = command = change = 0.0
        count = 0
        stretch: list[tuple[float, float]] = []
        steps = list(self.segments.items)[1:]  # the first began before the window
        for _, (span, step, total, n, counts) in steps:
            if counts:
                stretch.append((span, step))
                seconds += span
                length += step
                command += total
                count += n
            else:
                change += self._stretch_change(stretch)
                stretch = []
        change += self._stretch_change(stretch)
        magnitude = sum(abs(v) for _, v in self.power.items) / len(self.power)
        enough = count > 0 and seconds >= p.minForward * p.window - 1e-9
        if not enough and magnitude < p.quietPower:
            return  # a quiet window (a leader stopped, the follower waiting): nothing new
        if not enough and p.wholeWindow > 0:
            self._window_estimate(now)  # too few forward seconds: judged as a whole
            return
        self.valid = 0.0
        if enough:
            mean = command / count
            speed = (length + p.timeConstant * change) / seconds
            share = (p.frictionPower + 100.0 * speed / p.maxSpeed) / mean
            if mean >= p.minPower and share <= p.maxShare:
                self.estimate = min(share, 1.0)
                self.valid = 1.0
                self.valid_at = now
        mean_all = sum(v for _, v in self.power.items) / len(self.power)
        if p.holdReverse < 1.0 and mean_all < (1.0 - p.holdReverse) * magnitude:
            self.valid_at = None
        if self.valid == 0.0 and self.valid_at is not None and p.validHold > 0:
            self.valid = max(0.0, 1.0 - (now - self.valid_at) / p.validHold)

    def _stretch_change(self, stretch: list[tuple[float, float]]) -> float:
        """Speed over a stretch's last ``edge`` s less over its first (0 if it is empty)."""
        if not stretch:
            return 0.0

        def edge(segments: list[tuple[float, float]]) -> float:
            time = way = 0.0
            for span, step in segments:
                if time >= self.p.edge - 1e-9:
                    break
                time += span
                way += step
            return way / time

        return edge(stretch[::-1]) - edge(stretch)

    def _edge_speed(self, end: int) -> float:
        """Mean speed over the first (``end`` 0) or last (-1) ``edge`` s of the window."""
        steps = list(self.path.items) if end == 0 else list(reversed(self.path.items))
        t_edge = steps[0][0]
        total = count = 0.0
        for i, (t, d) in enumerate(steps):
            if i == 0 and end == 0:
                continue  # the first segment ends at the window's start
            if abs(t - t_edge) > self.p.edge + 1e-9:
                break
            total += d
            count += 1
        spacing = self.p.spacing
        return total / (count * spacing) if count else 0.0
