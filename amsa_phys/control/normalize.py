"""NormalizePower: the actuator stage between the controller and the motors."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..model.params import Param
from ..model.template import Kind, Port, Template


class NormalizePower(Template):
    """Clamp each wheel's power to [powerMin, powerMax], then deliver motorCoef % of it.

    ``motorCoef`` is the paper's context parameter for worn motors: 60 delivers 60 % of the
    (clamped) power the controller asked for.
    """

    kind = Kind.ACTUATOR
    uses_random = False
    inputs = (
        Port("powerL", 0.0, "requested left power", "%"),
        Port("powerR", 0.0, "requested right power", "%"),
    )
    outputs = (
        Port("normalizedPowerL", 0.0, "delivered left power", "%"),
        Port("normalizedPowerR", 0.0, "delivered right power", "%"),
    )
    params = (
        Param("powerMin", "float", "lowest power", -100.0, -100.0, 100.0, "%"),
        Param("powerMax", "float", "highest power", 100.0, -100.0, 100.0, "%"),
        Param("motorCoef", "int", "share of the power actually delivered", 100, 0, 100, "%"),
    )

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """Refuse an empty range (it would silently pin the motors)."""
        if values["powerMin"] > values["powerMax"]:
            raise ValueError(
                f"powerMin {values['powerMin']:g} is above powerMax {values['powerMax']:g}"
            )

    def initialize(self, ctx: Any) -> None:
        """Check the range once more (a world built in code skips the loader)."""
        self.check_params(self.p.as_dict())

    def on_param_change(self, name: str, value: Any) -> None:
        """Keep powerMin <= powerMax."""
        self.check_params(self.p.as_dict())

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: clamp, then scale."""
        p = self.p
        lo, hi = p.powerMin, p.powerMax
        k = p.motorCoef * 0.01
        # min(hi, max(lo, v)) as comparisons (the builtins' calls were most of the step):
        # max(lo, v) is v only if v > lo, min(hi, m) is m only if m < hi; NaN gives lo
        left, right = inp["powerL"], inp["powerR"]
        left = left if left > lo else lo
        right = right if right > lo else lo
        return {
            "normalizedPowerL": (left if left < hi else hi) * k,
            "normalizedPowerR": (right if right < hi else hi) * k,
        }

    @classmethod
    def step_many(
        cls, comps: Sequence[Any], t: Fraction, inp: Mapping[str, Any], p: Any, state: Any
    ) -> tuple[Mapping[str, Any], None]:
        """``do_step`` for many copies at once (``engine/batch.py``)."""
        k = p.motorCoef * 0.01
        lo, hi = p.powerMin, p.powerMax
        return {
            "normalizedPowerL": np.minimum(hi, np.maximum(lo, inp["powerL"])) * k,
            "normalizedPowerR": np.minimum(hi, np.maximum(lo, inp["powerR"])) * k,
        }, None
