"""Which Data buffers the trace keeps (``trace_columns:`` / ``--trace-columns``).

A 200-car platoon traces ~3,600 buffers: ~4.3 GB per simulated hour at 20 Hz, most of it
sensor noise nobody reads afterwards. ``trace_columns`` keeps only the buffers matching its
glob patterns (``Car*.Gap.*``, ``Leader.pos?``, matched with :func:`fnmatch.fnmatchcase`
against the buffer's full name). Whatever the scenario itself reads back from the trace is
always kept, so a selection can never silently disable a check: the quality signal and every
``expect: {trace: ...}`` column. Rovers whose ``posX``/``posY`` are not kept are simply left
out of the trajectory plot. Columns stay in the world's order whatever the patterns' order,
so the same selection always gives the same file.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from fnmatch import fnmatchcase

from .suggest import did_you_mean

__all__ = [
    "LARGE_TRACE_BYTES",
    "estimate_trace_bytes",
    "no_match_message",
    "parse_patterns",
    "selected",
    "size_text",
    "unmatched",
]

#: Bytes a traced value takes on average, comma included: 16.7 measured on a moving 200-car
#: platoon (3,608 columns, ~60,400-byte rows; the all-zero first row is 5.9) and ~19 on the
#: MDE world (positions and headings with 17 digits). The estimate leans high: a user warned
#: of 1.2 GB that turns out 1.1 is better served than the other way round.
BYTES_PER_VALUE = 18

#: Above this estimated size a run says how large its trace will be before it starts (the
#: CLI for ``trace.csv``, ``amsa_phys.run`` for the trace it keeps in memory).
LARGE_TRACE_BYTES = 1_000_000_000


def parse_patterns(text: str) -> list[str]:
    """``--trace-columns``' comma-separated patterns (empty items dropped)."""
    return [p.strip() for p in text.split(",") if p.strip()]


def unmatched(patterns: Iterable[str], columns: Sequence[str]) -> list[str]:
    """The patterns that match no column (each is a mistake the user wants to hear about)."""
    return [p for p in patterns if not any(fnmatchcase(c, p) for c in columns)]


def selected(
    patterns: Sequence[str] | None, columns: Sequence[str], required: Iterable[str] = ()
) -> list[str]:
    """The columns kept: those matching a pattern, plus ``required``, in world order.

    ``patterns`` None keeps every column.
    """
    if patterns is None:
        return list(columns)
    keep = set(required)
    return [c for c in columns if c in keep or any(fnmatchcase(c, p) for p in patterns)]


def no_match_message(pattern: str, columns: Sequence[str]) -> str:
    """The one-line complaint for a pattern that keeps nothing (with the buffer it would
    keep if case did not matter: ``car*.gap.*`` is a likely slip for ``Car*.Gap.*``)."""
    folded = pattern.lower()
    near = next((c for c in columns if fnmatchcase(c.lower(), folded)), None)
    if near is not None:
        return (
            f"{pattern!r} matches no Data buffer: patterns are case-sensitive "
            f"(it would match {near} ignoring case)"
        )
    return f"{pattern!r} matches no Data buffer" + did_you_mean(pattern, columns)


def estimate_trace_bytes(
    n_columns: int, rate_hz: float, duration_s: float, bytes_per_value: float = BYTES_PER_VALUE
) -> float:
    """A rough size of a trace of ``n_columns`` at ``rate_hz`` for ``duration_s``.

    A float, computed in floats: the schema accepts any finite duration (``--duration
    1e308``), whose row count no longer fits a float, and an estimate must never be the
    thing that fails. Beyond the float range the answer is ``inf``, which
    compares and prints (:func:`size_text`) like any other size.
    """
    rows = float(rate_hz) * float(duration_s) + 1.0
    return rows * (n_columns + 1) * bytes_per_value


def size_text(n_bytes: float) -> str:
    """A size for a person: ``about 1.2 GB``, ``about 3.7e+12 GB``, ``over 1e+299 GB``."""
    if not math.isfinite(n_bytes):
        return "over 1e+299 GB"
    gb = n_bytes / 1e9
    return f"about {gb:.1f} GB" if gb < 1e6 else f"about {gb:.2g} GB"
