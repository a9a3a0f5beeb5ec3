"""How the engine judges a component: what its code may raise, and what it may publish.

One set of refusals and one message for every way a task steps (``tasks.py``,
``delayedstep.py``, ``engine/batch.py``'s groups): the copies this replaced had drifted
apart. ``tasks.py`` re-exports these names, where the rest of the engine has always found
them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from ..errors import RunFault
from ..model.params import short_repr

#: What a component's code may raise that is its fault, not the engine's: any exception,
#: and ``sys.exit()`` (SystemExit), which would otherwise end the whole program with its
#: code and no message. KeyboardInterrupt is the user's and stays one.
COMPONENT_ERRORS = (Exception, SystemExit)

#: What judging a published output may raise: not a mapping (AttributeError: no ``items``),
#: an unknown port (KeyError), not a number (TypeError, ValueError), too large for a float
#: (OverflowError), or not finite (ValueError, raised here).
OUTPUT_ERRORS = (KeyError, TypeError, ValueError, OverflowError, AttributeError)


def as_number(value: Any) -> float:
    """An output's value as a float: a number (bool and numpy's too), never text (``float``
    alone would take ``"10"`` and ``b"nan"``: the documented contract is a mapping of numbers)."""
    if isinstance(value, str | bytes | bytearray):
        raise TypeError("text is not a number")
    return float(value)


def own_interrupt(who: str, now: Fraction) -> RunFault:
    """The fault for a KeyboardInterrupt a component raised itself. One out of a step is the
    user's only if :mod:`.interrupt` noted a Ctrl-C or SIGTERM (or nobody defers them, so it
    cannot tell); otherwise it is the component's, a fault like any exception it raises."""
    return RunFault(who, now, "raised KeyboardInterrupt() itself (not a Ctrl-C: a fault)")


def in_run(fault: RunFault, run: int | None) -> RunFault:
    """``fault`` marked as run ``run``'s, unless already marked: a batch (``multirun.py``)
    makes that run alone, which says what went wrong; unmarked, no one run is to blame."""
    if getattr(fault, "run", None) is None:
        fault.run = run  # type: ignore[attr-defined]
    return fault


def bad_output(who: str, now: Fraction, targets: Mapping[str, Any], out: Any) -> RunFault:
    """The fault for the first output :func:`checked_writes` refused (a slow path)."""
    if not isinstance(out, Mapping):
        return RunFault(
            who, now, f"do_step must return a mapping of outputs, got {short_repr(out)}"
        )
    for key, value in out.items():
        if key not in targets:
            return RunFault(who, now, f"published unknown output {short_repr(key)}")
        try:
            number = as_number(value)
        except OverflowError:
            return RunFault(who, now, f"output {key} is too large for a float")
        except (TypeError, ValueError):
            return RunFault(who, now, f"output {key} is not a number: {short_repr(value)}")
        if not math.isfinite(number):
            return RunFault(who, now, f"output {key} is {number}")
    return RunFault(who, now, f"published invalid outputs {dict(out)!r}")
