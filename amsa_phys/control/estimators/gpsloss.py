"""GPSLossMonitor: the share of a GPS receiver's samples that were lost, from its fixes."""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ...model.params import Param
from ...model.template import Kind, Port, Template
from . import Estimates
from .window import Window


class GPSLossMonitor(Template):
    """Share of held (repeated) fixes over the last ``window`` seconds: the GPS loss rate.

    A lost GPS sample publishes nothing, so whoever reads the fix sees the previous one
    again: that is all a robot can observe of a loss, and all this monitor uses. Run it at
    the GPS's rate (a faster monitor counts its own extra reads as losses). Each step counts
    one sample, held if the fix equals the previous one exactly. Noise: with n samples in
    the window and loss share p the estimate's standard deviation is sqrt(p (1 - p) / n),
    0.027 for p = 0.1 over 30 s at 4 Hz (n = 121). A fix repeats without a loss only if the
    antenna moves less than the receiver's resolution between two samples (a rover at
    rest): the monitor then reads a stopped leader as a lossy GPS. Until ``window`` seconds
    of samples are in, it publishes 0 (no evidence of loss).
    """

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.OBSERVER
    uses_random = False
    #: the windows are sized once, at initialize
    fixed_once_running = frozenset({"window"})
    inputs = (
        Port("gpsPosX", 0.0, "the GPS fix, x", "m"),
        Port("gpsPosY", 0.0, "the GPS fix, y", "m"),
    )
    outputs = (Port("lossRate", 0.0, "share of samples lost over the window (0..1)", ""),)
    params = (Param("window", "float", "length of the estimate's window", 30.0, 1.0, 3600.0, "s"),)
    estimates = (Estimates("lossRate", "lostDataGPS", ("GPS",), scale=0.01),)

    def initialize(self, ctx: Any) -> None:
        """No fix seen yet."""
        self.samples: Window[bool] = Window(self.p.window)
        self.last: tuple[float, float] | None = None

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: count this sample as new or held, publish the share held."""
        fix = (inp["gpsPosX"], inp["gpsPosY"])
        if self.last is None:
            self.last = fix
            return {}
        held = fix == self.last
        self.last = fix
        samples = self.samples
        samples.add(float(t), held)
        if samples.covered_s() < self.p.window - 1e-9:
            return {"lossRate": 0.0}
        return {"lossRate": sum(h for _, h in samples.items) / len(samples)}
