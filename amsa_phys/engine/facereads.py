"""The reads and controls ``face.py`` declares that ``Simulation`` does not hold as attributes.

A mixin of ``Simulation`` (``runner.py``), as ``store.ReadAPI`` and ``livechanges`` are: each
is one line over the engine's own state, here so that readers outside the engine never reach
that state (``shared``, ``store``, ``log``) themselves.
"""

from __future__ import annotations

from typing import Any

from .log import RunLog
from .store import BufferStore


class FaceReads:
    """Simulation's side of ``face.SimView`` / ``face.SimDriver`` beyond its attributes."""

    # what ``Simulation`` provides
    shared: dict[str, Any]
    store: BufferStore
    log: RunLog

    def service(self, name: str) -> Any:
        """The run's shared service ``name`` (``"physics"``: the physics world), or None."""
        return self.shared.get(name)

    def at(self, buffer: str, run: int = 0) -> int:
        """A buffer's position in :attr:`data` (a hot reader looks it up once)."""
        return self.store.at(buffer, run)

    @property
    def data(self) -> Any:
        """Every buffer's value now (the store's float64 array, by :meth:`at` position):
        a reader's, never to be written (``write`` is the way in)."""
        return self.store.data

    def hold_quality(self, waiting: bool) -> None:
        """Take no quality sample while ``waiting``: the quality signal holds its port's
        initial value, no measurement (a free-mode ROS node has not published yet)."""
        self.log.quality_waits = waiting

    def close(self) -> None:
        """Release what the run holds outside the process: nothing here (a ROS 2 run
        leaves its graph), so every owner closes every run alike."""
