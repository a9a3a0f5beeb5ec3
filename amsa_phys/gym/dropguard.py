"""An env dropped without ``close()`` still ends its episode, so the episode is freed.

A paused episode's run is a greenlet suspended in the middle of an instant, and its frames
hold the episode that holds the greenlet: a cycle the garbage collector cannot see into
(greenlet's documentation: cycles through a suspended greenlet's frames are not detected).
An env dropped in the middle of an episode would keep that episode, its run and, in a
vector env, its batch and the batch's helper threads, for the life of the process. The env
itself is not in the cycle, so it is freed as soon as it is dropped: a finalizer on it
closes the episode it held then (switching into the run to end it, as ``close()`` does),
and the episode is freed by reference counting.
"""

from __future__ import annotations

import weakref
from typing import Any


class DropGuard:
    """Closes what its owner :meth:`hold` s when the owner is collected.

    The finalizer holds a one-item list, never the owner (which would keep it alive); it
    does not run at interpreter exit (nothing is left to free then).
    """

    def __init__(self, owner: object) -> None:
        self._held: list[Any] = [None]
        weakref.finalize(owner, _close, self._held).atexit = False

    def hold(self, thing: Any) -> None:
        """What to close if the owner is dropped (None: nothing)."""
        self._held[0] = thing


def _close(held: list[Any]) -> None:
    thing, held[0] = held[0], None
    if thing is not None:
        thing.close()
