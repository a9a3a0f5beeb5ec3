"""Context estimators: Monitors that tell the context from what the robot measures.

Each is an ordinary observer template (``GPSLossMonitor``, ``MotorMonitor``,
``LeaderMonitor``) fed only by Data a real rover has: GPS fixes, the power its controller
commands. None reads a context parameter or a true pose, so a rule written on their outputs
(``adapt:``, ``engine/adapt.py``) could run on the robot. Each declares which context
parameter it estimates (:class:`Estimates`), so ``amsa-phys adapt`` can map a context sweep's
cells to ranges of its outputs.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Estimates:
    """What an estimator's output says about a context parameter.

    ``output`` of the estimator is about ``scale * value + offset`` when the context
    parameter ``param`` (of a Leaf of one of ``templates``, found on the estimator's
    dataflow) holds ``value``; ``levels`` maps a parameter whose values are names or codes
    (a leader's behaviour) to the output level instead.
    """

    output: str
    param: str
    templates: tuple[str, ...]
    scale: float = 1.0
    offset: float = 0.0
    levels: tuple[tuple[float, float], ...] = ()

    def expected(self, value: float) -> float | None:
        """The output the estimator settles to in a context where the parameter is ``value``
        (None: a value this estimator cannot tell, such as an unmapped behaviour)."""
        if self.levels:
            return dict(self.levels).get(float(value))
        return self.scale * float(value) + self.offset
