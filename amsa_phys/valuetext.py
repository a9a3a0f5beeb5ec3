"""How a parameter value is printed for a reader: one spelling in every picture and table.

The run's table, the live window's HUD, the replay's HUD, ``distance.png``'s phase notes and
``describe`` each had their own (``cruisePower=9.0`` in the table and the replay, ``9`` in the
live HUD, ``0.123457`` for 0.1234567 from ``:g``): the same value looked like two values
depending on where it was read. Files keep their exact values; this is only for people.
"""

from __future__ import annotations

import math
from typing import Any


def value_text(value: Any) -> str:
    """``9`` for 9.0, ``0.35``, ``0.1234567`` (every digit: never rounded, so a live value
    differing in its 7th digit shows), ``1e+308``, ``true``, ``[4 points]`` for a polygon.

    A float is spelt as Python's shortest exact round trip (``repr``, what ``trace.csv``
    and ``metrics.json`` hold) without a trailing ``.0``: ``cruisePower=9`` whether the
    file wrote ``9`` or ``9.0``, or the value came back from ``metrics.json``.
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) or type(value).__name__.startswith("float"):
        number = float(value)
        if not math.isfinite(number):
            return str(number)
        text = repr(number)
        return text[:-2] if text.endswith(".0") else text
    if isinstance(value, (tuple, list)):
        return f"[{len(value)} points]"
    return str(value)
