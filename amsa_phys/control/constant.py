"""ConstantPower: open-loop wheel powers, for physics tests and demonstrations."""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ..model.params import Param
from ..model.template import Kind, Port, Template


class ConstantPower(Template):
    """Publishes fixed left/right powers (change them with the timeline)."""

    batchable = True  # each run's copy steps alone in a batch (no step_many needed)

    kind = Kind.CONTROLLER
    uses_random = False
    outputs = (
        Port("LeftPower", 0.0, "left power", "%"),
        Port("RightPower", 0.0, "right power", "%"),
    )
    params = (
        Param("left", "float", "left wheel power", 0.0, -100.0, 100.0, "%"),
        Param("right", "float", "right wheel power", 0.0, -100.0, 100.0, "%"),
    )

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: the same powers every step."""
        return {"LeftPower": self.p.left, "RightPower": self.p.right}
