"""GPS: a noisy, biased, lossy position sensor."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..engine.rng import Drawn, DrawnMany
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

    @classmethod
    def step_many(
        cls, comps: Sequence[Any], t: Fraction, inp: Mapping[str, Any], p: Any, state: Any
    ) -> tuple[Mapping[str, Any], np.ndarray]:
        """``do_step`` for many copies at once (``engine/batch.py``).

        Each copy draws from its own streams in the scalar order (x noise, y noise, loss);
        the lost copies publish nothing (the mask returned).
        """
        if "noise" not in state:
            state["noise"] = DrawnMany([c.noise for c in comps])
            state["loss"] = DrawnMany([c.draw_loss for c in comps])
        ex = state["noise"]()
        ey = state["noise"]()
        lost = state["loss"]() * 100.0 < p.lostDataGPS
        for k in np.flatnonzero(lost).tolist():
            comps[k].lost += 1
        noise, bias = p.noise, p.bias
        return {
            "gpsPosX": inp["posX"] + bias + noise * ex,
            "gpsPosY": inp["posY"] + bias + noise * ey,
        }, ~lost
