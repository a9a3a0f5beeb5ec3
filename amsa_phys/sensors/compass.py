"""Compass: a noisy, biased heading sensor."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

from ..engine.rng import Drawn, DrawnMany
from ..model.params import Param
from ..model.template import Kind, Port, Template


class Compass(Template):
    """Measured heading = true heading + bias + Gaussian noise, wrapped to [-pi, pi)."""

    kind = Kind.SENSOR
    inputs = (Port("heading", 0.0, "true heading", "rad"),)
    outputs = (Port("compassHeading", 0.0, "measured heading in [-pi, pi)", "rad"),)
    params = (
        Param("noise", "float", "standard deviation of the error", 0.0, 0.0, math.pi, "rad"),
        Param("bias", "float", "constant offset", 0.0, -math.pi, math.pi, "rad"),
    )

    def initialize(self, ctx: Any) -> None:
        """Take this component's own random stream (drawn in blocks)."""
        self.noise = Drawn(ctx.rng.standard_normal)

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: one heading sample."""
        value = inp["heading"] + self.p.bias + self.p.noise * self.noise()
        return {"compassHeading": (value + math.pi) % (2 * math.pi) - math.pi}

    @classmethod
    def step_many(
        cls, comps: Sequence[Any], t: Fraction, inp: Mapping[str, Any], p: Any, state: Any
    ) -> tuple[Mapping[str, Any], None]:
        """``do_step`` for many copies at once, each from its own stream (``engine/batch.py``)."""
        if "noise" not in state:
            state["noise"] = DrawnMany([c.noise for c in comps])
        draws = state["noise"]()
        value = inp["heading"] + p.bias + p.noise * draws
        return {"compassHeading": (value + math.pi) % (2 * math.pi) - math.pi}, None
