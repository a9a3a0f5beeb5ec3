"""Which physics step runs: the compiled one (``_step.c``) or the pure-Python one, and why.

Kept free of numpy and pymunk so that ``amsa-phys --version`` and ``describe`` can say it
without paying for them (``compiled.py`` holds the step itself).
"""

from __future__ import annotations

import os
from types import ModuleType

#: Set to 1 (anything but empty or 0) to run the pure-Python step even where the C one is built.
PURE_ENV = "AMSA_PHYS_PURE"


def extension() -> ModuleType | None:
    """The compiled ``_step`` module, or None where it was not built."""
    try:
        from . import _step
    except ImportError:  # no C compiler at install time: the pure path runs
        return None
    return _step


def forced_pure() -> bool:
    """Whether ``AMSA_PHYS_PURE`` asks for the pure-Python step."""
    return os.environ.get(PURE_ENV, "").strip() not in ("", "0")


def describe() -> tuple[bool, str]:
    """(whether the compiled step is selected, a phrase saying which step and why)."""
    if extension() is None:
        return False, "pure Python (the compiled step was not built: no C compiler at install)"
    if forced_pure():
        return False, f"pure Python ({PURE_ENV} is set)"
    return True, "compiled (C)"
