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

from ..requirements.objective import ROBUSTNESS_PREFIX
from ..requirements.objective import objective_value as shared_objective_value

#: Prefix of an objective that is a requirement's robustness.
ROBUSTNESS = ROBUSTNESS_PREFIX


def objective_value(metrics: dict[str, Any], name: str) -> tuple[float | None, bool]:
    """``(value, higher_is_better)`` of objective ``name`` in a run's ``metrics``.

    The one reading shared with ``falsify`` (:func:`amsa_phys.requirements.objective.
    objective_value`), with what tuning needs on top: ``value`` is None when the run has no
    finite value for it (never settled, a fault, an unknown requirement or metric), which
    tuning scores as the worst there is.
    """
    try:
        value, higher = shared_objective_value(metrics, name)
    except (KeyError, TypeError, ValueError):
        return None, name.startswith(ROBUSTNESS)
    return _finite(value), higher


def _finite(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None
