"""Quality-of-control metrics: their names and their computation, in one module.

:data:`METRICS` are the names an ``expect`` entry may give and the columns of a sweep's
``results.csv``; :func:`block_metrics` computes them, each a pure function of the sampled
quality signal. (Issue 32: the names used to live in three places.)

The signal is sampled at the trace's log rate. ``mean_error`` is signed (signal − reference:
positive means the follower is too far behind); ``settling_time`` is the time from the
block's start to the first sample after which |error| stays within tolerance to the block's
end, provided it stays there for at least ``dwell`` seconds (None otherwise: a signal back in
the band only for its last samples has not settled); ``max_after_approach`` is the paper's
quality figure, the largest value once the signal has first come within tolerance (the
follower's first approach; None if it never does), so a start far from the reference does
not count.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

#: Metrics an ``expect`` entry may name, in the order of the columns of a sweep's
#: ``results.csv``; :func:`block_metrics` returns each of them.
METRICS = (
    "max_distance",
    "min_distance",
    "mean_error",
    "rms_error",
    "settling_time",
    "max_after_approach",
    "final_distance",
    "collisions",
)

#: Metrics that count events rather than measure the signal (plotted as counts).
COUNT_METRICS = frozenset({"collisions"})


def block_metrics(
    t: np.ndarray,
    s: np.ndarray,
    start: float,
    end: float,
    reference: float,
    tolerance: float,
    event_times: Sequence[float],
    include_end: bool = False,
    dwell: float | None = None,
) -> dict[str, Any]:
    """Metrics of the samples with ``start <= t < end`` (``<= end`` when ``include_end``).

    Blocks are half-open so that a sample at a phase boundary belongs to the new phase; the
    last block (and the overall block) includes the final instant. ``dwell`` is how long the
    signal must stay in the band to count as settled: :func:`default_dwell` of the block
    when None.
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
            "max_after_approach": None,
            "final_distance": None,
            "collisions": collisions,
        }
    if dwell is None:
        dwell = default_dwell(end - start)
    err = ss - reference
    inside = np.abs(err) <= tolerance
    outside = np.flatnonzero(~inside)
    settled_from = float(tt[0]) if outside.size == 0 else None
    if outside.size and outside[-1] < ss.size - 1:
        settled_from = float(tt[outside[-1] + 1])
    settling: float | None = None
    # the samples are on an exact grid but their times are floats: a hair of slack so a
    # stay of exactly ``dwell`` seconds counts
    if settled_from is not None and float(tt[-1]) - settled_from >= dwell - 1e-9:
        settling = settled_from - start
    first_in = int(np.argmax(inside)) if inside.any() else None
    return {
        "max_distance": float(ss.max()),
        "min_distance": float(ss.min()),
        "mean_error": float(err.mean()),
        "rms_error": float(np.sqrt(np.mean(err * err))),
        "settling_time": settling,
        "max_after_approach": None if first_in is None else float(ss[first_in:].max()),
        "final_distance": float(ss[-1]),
        "collisions": collisions,
    }


#: Default dwell of ``settling_time``: 10 s, or a tenth of a block shorter than 100 s.
DEFAULT_DWELL_S = 10.0


def default_dwell(length: float) -> float:
    """How long a block's signal must stay in the band to have settled, by default."""
    return min(DEFAULT_DWELL_S, 0.1 * max(length, 0.0))
