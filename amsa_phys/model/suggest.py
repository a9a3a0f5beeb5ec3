""" "Did you mean" hints for misspelt names, used at every depth of a file."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """`` (did you mean X?)`` for the closest candidate, or an empty string.

    A name that differs only in case wins outright (``posx`` is ``posX``, not the
    equally close ``posY``); otherwise the closest by difflib's ratio, compared without
    case so that a wrong capital does not count as a wrong letter.
    """
    pool = [str(c) for c in candidates]
    lowered = {c.lower(): c for c in pool}
    key = str(name).lower()
    if key in lowered:
        return f" (did you mean {lowered[key]}?)"
    close = difflib.get_close_matches(key, list(lowered), n=1, cutoff=0.6)
    return f" (did you mean {lowered[close[0]]}?)" if close else ""
