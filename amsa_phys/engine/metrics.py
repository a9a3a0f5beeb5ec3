"""Quality-of-control metrics: pure functions over the sampled quality signal.

The signal is sampled at the trace's log rate. ``mean_error`` is signed (signal − reference:
positive means the follower is too far behind); ``settling_time`` is the time from the
block's start to the first sample after which |error| stays within tolerance to the block's
end (None if the last sample is outside).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np


def block_metrics(
    t: np.ndarray,
    s: np.ndarray,
    start: float,
    end: float,
    reference: float,
    tolerance: float,
    event_times: Sequence[float],
    include_end: bool = False,
) -> dict[str, Any]:
    """Metrics of the samples with ``start <= t < end`` (``<= end`` when ``include_end``).

    Blocks are half-open so that a sample at a phase boundary belongs to the new phase; the
    last block (and the overall block) includes the final instant.
    """
    mask = (t >= start) & ((t <= end) if include_end else (t < end))
    tt, ss = t[mask], s[mask]
    collisions = sum(
        1 for e in event_times if start <= e and (e <= end if include_end else e < end)
    )
    if ss.size == 0:
        return {
            "max_distance": None,
            "min_distance": None,
            "mean_error": None,
            "rms_error": None,
            "settling_time": None,
            "final_distance": None,
            "collisions": collisions,
        }
    err = ss - reference
    outside = np.flatnonzero(np.abs(err) > tolerance)
    if outside.size == 0:
        settling: float | None = 0.0
    elif outside[-1] == ss.size - 1:
        settling = None
    else:
        settling = float(tt[outside[-1] + 1] - start)
    return {
        "max_distance": float(ss.max()),
        "min_distance": float(ss.min()),
        "mean_error": float(err.mean()),
        "rms_error": float(np.sqrt(np.mean(err * err))),
        "settling_time": settling,
        "final_distance": float(ss[-1]),
        "collisions": collisions,
    }
