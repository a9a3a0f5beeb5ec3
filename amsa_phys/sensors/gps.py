"""GPS: a noisy, biased, lossy position sensor."""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ..engine.rng import Drawn
from ..model.params import Param
from ..model.template import Kind, Port, Template


class GPS(Template):
    """Noisy, biased, lossy position fix; a lost sample publishes nothing.

    Consumers then keep the stale fix, which is what the paper's degraded context (10 % of the
    leader's fixes lost) relies on. The loss draw and the noise draws happen at every step,
    lost or not, from two separate streams, so a sweep over ``lostDataGPS`` keeps the same
    noise sequence.
    """

    kind = Kind.SENSOR
    inputs = (Port("posX", 0.0, "true x", "m"), Port("posY", 0.0, "true y", "m"))
    outputs = (Port("gpsPosX", 0.0, "measured x", "m"), Port("gpsPosY", 0.0, "measured y", "m"))
    params = (
        Param(
            "noise", "float", "standard deviation of the error on each axis", 0.0, 0.0, 100.0, "m"
        ),
        Param("bias", "float", "constant offset added to both axes", 0.0, -100.0, 100.0, "m"),
        Param("lostDataGPS", "int", "share of samples lost", 0, 0, 100, "%"),
    )

    def initialize(self, ctx: Any) -> None:
        """Split this component's random stream: one for the noise, one for the losses."""
        noise_rng, loss_rng = ctx.rng.spawn(2)
        self.noise = Drawn(noise_rng.standard_normal)
        self.draw_loss = Drawn(loss_rng.random)
        self.lost = 0  # samples lost so far: the renderer marks them

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: sample the position, or lose the sample."""
        ex = self.noise()
        ey = self.noise()
        lost = self.draw_loss() * 100.0 < self.p.lostDataGPS
        if lost:
            self.lost += 1
            return {}
        noise = self.p.noise
        bias = self.p.bias
        return {
            "gpsPosX": inp["posX"] + bias + noise * ex,
            "gpsPosY": inp["posY"] + bias + noise * ey,
        }
