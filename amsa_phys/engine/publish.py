"""The compiled read and write between a component and the store, when they were built.

``_publish.c`` (an optional extension, ``setup.py``) does what the scalar step's Python
loops do, in one C call each: ``gather`` builds a component's dict of inputs from the
store, ``publish`` writes the usual output — a dict of finite floats for known ports — and
declines everything else, which the Python loop then judges (``tasks.py``): the same
values written, the same faults raised, only sooner. ``Scalar`` is the scalar step itself
(gather, ``do_step``, publish) as a C callable, so a component's step has no Python frame
of the engine's around it; what ``do_step`` raises and what ``publish`` declines go back to
Python functions that raise the Python step's faults. ``Drawn`` is ``engine/rng.py``'s
block-drawn random stream as a C callable. ``_kernels.c``, a second extension, holds
``Kernel``: the standard components' whole steps as compiled bodies (``kernels.py``).
``AMSA_PHYS_PURE=1`` (the switch of the pure
physics step too) or a build without a C compiler runs the Python loops alone.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import threading
from collections.abc import Callable, Iterator
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
    """The ``Kernel`` step type (a standard component's whole step as a compiled body,
    ``kernels.py``; the ``_kernels`` extension), or None (not built, or the pure path)."""
    module = _extension("_kernels")
    return None if module is None else module.Kernel


def drawn() -> Any:
    """The compiled ``Drawn`` (``engine/rng.py``'s, in C), or None."""
    module = _extension()
    return None if module is None else module.Drawn


#: the extensions once imported (False: not built); the switch is read at every call, so a
#: test or a user may set it between runs (inside :func:`pinned`, once for all the calls)
_modules: dict[str, Any] = {}


class _Pinned(threading.local):
    #: the switch as :func:`pinned` read it in this thread, or None: read it at every call
    pure: bool | None = None


_pinned = _Pinned()


def _pure() -> bool:
    return os.environ.get(PURE_ENV, "").strip() not in ("", "0")


@contextlib.contextmanager
def pinned() -> Iterator[None]:
    """The switch read once for every call inside (in this thread): a Gymnasium reset
    builds a run that asks ~30 times, and reading the environment was a few per cent of
    the reset. Nested: the outermost reading holds."""
    outer = _pinned.pure
    if outer is None:
        _pinned.pure = _pure()
    try:
        yield
    finally:
        _pinned.pure = outer


def _extension(name: str = "_publish") -> Any:
    pure = _pinned.pure
    if pure if pure is not None else _pure():
        return None
    module = _modules.get(name)
    if module is None:  # the import machinery once, not at every ask
        try:
            module = importlib.import_module(f"{__package__}.{name}")
        except ImportError:  # no C compiler at install time: the Python loops run
            module = False
        _modules[name] = module
    return module or None
