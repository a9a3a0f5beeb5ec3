"""Counted nouns in messages: "1 phase", "4 phases" (never "1 phases")."""

from __future__ import annotations


def plural(n: int, noun: str, nouns: str | None = None) -> str:
    """``n`` and ``noun``, plural unless ``n`` is 1 (``nouns`` when not just ``noun + s``)."""
    return f"{n} {noun if n == 1 else (nouns or noun + 's')}"
