"""One objective number from a run's metrics: a plain metric, or a requirement's robustness.

Every place a metric objective is accepted (``tune``, ``adapt``) reads it through
:func:`objective_value`, so the way a requirement's robustness enters (a run's metrics
gain ``requirements: {NAME: {"robustness": ...}}``, and ``robustness.NAME`` is the
objective's name) is decided once. Plain metrics (``rms_error``) are lower-is-better;
robustness is higher-is-better (a larger margin by which the requirement holds).
"""

from __future__ import annotations

import math
from typing import Any

#: Prefix of an objective that is a requirement's robustness.
ROBUSTNESS = "robustness."


def objective_value(metrics: dict[str, Any], name: str) -> tuple[float | None, bool]:
    """``(value, higher_is_better)`` of objective ``name`` in a run's ``metrics``.

    ``value`` is None when the run has no finite value for it (never settled, a fault, an
    unknown requirement). ``name`` is ``robustness.REQ``, a metric of the whole run
    (``rms_error``) or of a phase (``phase1.rms_error``).
    """
    if name.startswith(ROBUSTNESS):
        req = (metrics.get("requirements") or {}).get(name[len(ROBUSTNESS) :]) or {}
        return _finite(req.get("robustness")), True
    block: Any = metrics.get("overall") or {}
    key = name
    if name.startswith("phase") and "." in name:
        head, _, key = name.partition(".")
        try:
            block = (metrics.get("phases") or [])[int(head[len("phase") :])]
        except (ValueError, IndexError):
            return None, False
    return _finite(block.get(key) if isinstance(block, dict) else None), False


def _finite(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None
