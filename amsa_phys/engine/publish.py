"""The compiled read and write between a component and the store, when they were built.

``_publish.c`` (an optional extension, ``setup.py``) does what the scalar step's Python
loops do, in one C call each: ``gather`` builds a component's dict of inputs from the
store, ``publish`` writes the usual output — a dict of finite floats for known ports — and
declines everything else, which the Python loop then judges (``tasks.py``): the same
values written, the same faults raised, only sooner. ``Scalar`` is the scalar step itself
(gather, ``do_step``, publish) as a C callable, so a component's step has no Python frame
of the engine's around it; what ``do_step`` raises and what ``publish`` declines go back to
Python functions that raise the Python step's faults. ``Drawn`` is ``engine/rng.py``'s
block-drawn random stream as a C callable. ``AMSA_PHYS_PURE=1`` (the switch of the pure
physics step too) or a build without a C compiler runs the Python loops alone.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

#: the pure path's switch, shared with the physics step (``physics/step_path.py``)
PURE_ENV = "AMSA_PHYS_PURE"

Publish = Callable[[dict[str, Any], dict[str, Any], Any], bool]
Gather = Callable[[tuple[str, ...], tuple[int, ...], Any, dict[Any, float] | None], dict]


def compiled() -> Publish | None:
    """``publish(out, targets, values)`` from the extension, or None (not built, or the
    pure path asked for)."""
    module = _extension()
    return None if module is None else module.publish  # type: ignore[no-any-return]


def gather() -> Gather | None:
    """``gather(ports, positions, values, own)`` from the extension, or None."""
    module = _extension()
    return None if module is None else module.gather  # type: ignore[no-any-return]


def scalar() -> Any:
    """The ``Scalar`` step type from the extension (a component's whole step in C, its
    faults and declined outputs handed back to Python), or None."""
    module = _extension()
    return None if module is None else module.Scalar


def kernel() -> Any:
    """The ``Kernel`` step type from the extension (an arithmetic component's whole step in
    C, ``kernels.py``), or None."""
    module = _extension()
    return getattr(module, "Kernel", None) if module is not None else None


def drawn() -> Any:
    """The compiled ``Drawn`` (``engine/rng.py``'s, in C), or None."""
    module = _extension()
    return None if module is None else module.Drawn


#: the extension once imported (False: not built); the switch is read at every call, so a
#: test or a user may set it between runs
_module: Any = None


def _extension() -> Any:
    global _module
    if os.environ.get(PURE_ENV, "").strip() not in ("", "0"):
        return None
    if _module is None:  # the import statement's machinery once, not at every ask
        try:
            from . import _publish
        except ImportError:  # no C compiler at install time: the Python loops run
            _module = False
        else:
            _module = _publish
    return _module or None
