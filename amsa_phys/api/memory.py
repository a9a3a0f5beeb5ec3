"""How large the trace a run keeps in memory will be: a warning, or a refusal.

``amsa-phys run`` streams its trace to a file and says so above ~1 GB. ``amsa_phys.run``
(and a Gymnasium env with ``record_trace=True``) keeps every row in memory instead, so
``ap.run(duration=1e9)`` would grow until the machine swaps or the kernel kills Python, hours
in. Before the run starts:

* above :data:`~amsa_phys.model.tracecols.LARGE_TRACE_BYTES` (1 GB), a
  :class:`TraceSizeWarning` says how large, as the CLI's note does;
* above the machine's physical memory, the run is refused with a one-line
  :class:`~amsa_phys.errors.ConfigError`: it could not finish anyway, and failing at once
  beats failing after hours. The estimate is the most the run can keep (a run that faults
  or is interrupted keeps less), so ``duration=`` is what to shorten, or ``log_rate=`` and
  ``trace_columns=`` what to narrow, or the CLI what to use (it streams to disk).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence

from ..errors import ConfigError, one_line
from ..model.scenario import Scenario, traced_columns
from ..model.tracecols import LARGE_TRACE_BYTES, estimate_trace_bytes, size_text
from .source import api_errors

#: Bytes a traced value takes in memory (``engine/tracemem.py``: packed doubles).
BYTES_IN_MEMORY = 8


class TraceSizeWarning(UserWarning):
    """The trace a run keeps in memory will pass ~1 GB (shown once per call site)."""


def physical_memory_bytes() -> int | None:
    """This machine's RAM, or None where the system does not say."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):  # pragma: no cover - not on Linux/macOS
        return None


@api_errors
def check_trace_memory(
    scenario: Scenario,
    columns: Sequence[str] | None = None,
    *,
    limit_bytes: float | None = None,
    stacklevel: int = 3,
) -> float:
    """Warn about (or refuse) the in-memory trace of ``scenario``; returns its estimate.

    ``columns`` are the traced buffers (default: what ``amsa_phys.run`` keeps);
    ``limit_bytes`` the refusal threshold (default: :func:`physical_memory_bytes`).
    """
    cols = list(columns) if columns is not None else traced_columns(scenario)
    rate, duration = float(scenario.log_rate), float(scenario.duration)
    size = estimate_trace_bytes(len(cols), rate, duration, BYTES_IN_MEMORY)
    what = f"{len(cols):,} columns at {rate:g} Hz for {duration:g} s"
    limit = limit_bytes if limit_bytes is not None else physical_memory_bytes()
    if limit is not None and size > limit:
        raise ConfigError(
            f"the trace kept in memory would be {size_text(size)} ({what}), more than this "
            f"machine's memory ({size_text(limit)}); shorten duration=, lower log_rate= or "
            "narrow trace_columns=, or use `amsa-phys run`, which streams the trace to a file",
            key="--duration",
        )
    if size >= LARGE_TRACE_BYTES:
        warnings.warn(
            one_line(
                f"the trace kept in memory will be {size_text(size)} ({what}); "
                "trace_columns= or log_rate= make it smaller"
            ),
            TraceSizeWarning,
            stacklevel=stacklevel,
        )
    return size
