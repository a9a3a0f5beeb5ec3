"""The vector env's physics: every run's rovers as columns, a run within reach frozen.

A batched sweep (``physics/columns.py``) steps every run's rovers in one force pass and one
integration, and makes a run whose shapes come within reach of each other (or that goes
fast enough to need sub-steps) again alone afterwards: contacts are then exactly a single
run's. An episode cannot be made again afterwards — the agent has acted on what it saw —
so the vector env (``gym/vecepisode.py``) takes such a run out of the batch at the agent's
next instant and continues it on a single episode of its own (``gym/solo.py``). Until then
its rows in the columns are no longer used, and must not do harm: a run within reach may
run into itself in the columns (no contacts there) and fly off, and a rover leaving the
world or going too fast would fault the whole batch. So from the step where a run is found
within reach, its rovers are *frozen*: after every integration their rows are put back to
where they were before it, so they never move, never speed up and never fault.

With the compiled step the freezing is done in C, in the same call as the forces and the
integration, and a run of physics steps between the agent's instants is one call
(``ColumnPhysics.step_many``); the numpy path below is the pure one. Freezing touches only
the frozen rows (the force pass and the integration are per rover),
so the other runs' floats are those of the columns without it, which are their single
runs' (``tests/physics/test_columns.py``, ``tests/gym/test_gym_vector.py``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..physics.columns import ColumnPhysics


class EpisodeColumns(ColumnPhysics):
    """:class:`ColumnPhysics` whose touched runs stop moving (see the module docstring)."""

    def __init__(self, threads: int = 1) -> None:
        super().__init__()
        self.threads = threads
        #: how many runs were touched when :attr:`_frozen` was last rebuilt
        self._seen = 0
        self._frozen: np.ndarray | None = None  # rover rows of the touched runs

    FREEZE = True  # the fused C step holds the touched runs' rows (``advance_many``)

    def _start(self) -> Any:
        """The batch's set-up. The fused C step freezes in C (``_step.Columns.advance_many``
        with ``freeze``: after each step the touched runs' rows are put back, as the numpy
        path puts them back in :meth:`_contacts`); an extension built before that method has
        only the plain step, which would leave the frozen rows moving: then the numpy path
        (the forces stay C's)."""
        model = super()._start()
        if not hasattr(self._fused, "advance_many"):
            self._fused = None
        return model

    def touched_count(self) -> int:
        """How many runs were found within reach so far: one C call, where :attr:`touched`
        builds a set (the vector env asks after every step whether any run is new)."""
        return int(np.count_nonzero(self._touched))

    def _contacts(self, dt: float) -> None:
        """Find the runs within reach before this step (the batch's rule), then put every
        touched run's rovers back where they were before it."""
        super()._contacts(dt)
        touched = self.touched
        if not touched:
            return
        if len(touched) != self._seen:
            self._seen = len(touched)
            self._frozen = np.flatnonzero(np.isin(self._run, np.fromiter(touched, np.intp)))
        rows = self._frozen
        io = self._io
        io.state[rows] = io.before[rows]
