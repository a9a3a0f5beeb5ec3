"""The compiled write of a component's published floats into the store, when it was built.

``_publish.c`` (an optional extension, ``setup.py``) does what the scalar step's Python
loop does for the usual output — a dict of finite floats for known ports — in one C call,
and declines everything else, which the Python loop then judges (``tasks.py``): the same
values written, the same faults raised, only sooner. ``AMSA_PHYS_PURE=1`` (the switch of
the pure physics step too) or a build without a C compiler runs the Python loop alone.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

#: the pure path's switch, shared with the physics step (``physics/step_path.py``)
PURE_ENV = "AMSA_PHYS_PURE"

Publish = Callable[[dict[str, Any], dict[str, Any], Any], bool]


def compiled() -> Publish | None:
    """``publish(out, targets, values)`` from the extension, or None (not built, or the
    pure path asked for)."""
    if os.environ.get(PURE_ENV, "").strip() not in ("", "0"):
        return None
    try:
        from ._publish import publish
    except ImportError:  # no C compiler at install time: the Python loop runs
        return None
    return publish  # type: ignore[no-any-return]
