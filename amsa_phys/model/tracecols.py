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

from collections.abc import Iterable, Sequence
from fnmatch import fnmatchcase

from .suggest import did_you_mean

__all__ = [
    "estimate_trace_bytes",
    "no_match_message",
    "parse_patterns",
    "selected",
    "unmatched",
]

#: Bytes a traced value takes on average, comma included: 16.7 measured on a moving 200-car
#: platoon (3,608 columns, ~60,400-byte rows; the all-zero first row is 5.9) and ~19 on the
#: MDE world (positions and headings with 17 digits). The estimate leans high: a user warned
#: of 1.2 GB that turns out 1.1 is better served than the other way round.
BYTES_PER_VALUE = 18


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


def estimate_trace_bytes(n_columns: int, rate_hz: float, duration_s: float) -> int:
    """A rough size of a trace of ``n_columns`` at ``rate_hz`` for ``duration_s``."""
    rows = int(rate_hz * duration_s) + 1
    return rows * (n_columns + 1) * BYTES_PER_VALUE
