"""A finished run let go at once: its cycles broken, so reference counting frees it.

A run's objects refer to one another: the schedule's hooks and the delivery of delayed
outputs are methods of the run, a delayed Leaf's step on the pure path is a method of the
steppers that keep it, the physics world and its Space call each other, and every component
reaches the run through its context. Left alone, a finished run waits for the cyclic
garbage collector, and a Gymnasium env that resets every few hundred steps keeps it walking
each ended episode's hundreds of objects (``gym/episode.py`` releases an episode's run when
the episode is closed).
"""

from __future__ import annotations

from typing import Any


class Release:
    """:meth:`release` (a mixin of the Simulation)."""

    #: whether :meth:`release` dropped the run (nothing of it can be used then)
    released = False

    _steppers: Any
    shared: dict[str, Any]

    def release(self) -> None:
        """Drop everything the run holds, so that what only it held is freed at once.

        Call it once nothing will step or read the run again; the Simulation is unusable
        afterwards (:attr:`released` says so). The steppers forget the steps they made, a
        shared service with a ``release_run`` method (the physics world) lets go of its
        own cycles, and the run's attributes are dropped. Twice is fine.
        """
        if self.released:
            return
        self._steppers.release()
        for value in self.shared.values():
            release = getattr(value, "release_run", None)
            if release is not None:
                release()
        self.__dict__.clear()
        self.released = True
