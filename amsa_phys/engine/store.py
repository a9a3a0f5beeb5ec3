"""The buffer store: every Data buffer's current value, and the one way to read it from outside.

A run's buffers (``Component.port``, and one element buffer ``Lidar.ranges[i]`` per element
of an array port) have a fixed order, the world's; the store gives each its index in that
order, so a caller can ask for a whole row as one float64 array (:meth:`BufferStore.row`)
and an array port as the slice of its elements (:meth:`BufferStore.array`).

The hot loop reads and writes :attr:`BufferStore.values`, a plain ``dict`` by buffer name:
in CPython a ``dict`` lookup by an interned string is as fast as indexing a list, and every
writer of the loop (the scalar path, the delivery heap, a group's scatter) already speaks
names. A packed float64 column store (issue 29) can replace the dict behind this class
without touching its readers.

Code outside the loop (the Gymnasium env, the window, rospy callbacks in free mode) uses
:meth:`read`, :meth:`read_many` and :meth:`write`. The store owns the one lock: the
simulation holds it while it executes instants (:meth:`Simulation.advance`), and an outside
writer takes it, so a write from another thread lands between two instants, never inside one.
Readers never take it: the Gymnasium env reads from the agent's thread while the loop's
thread is paused *inside* an instant (holding the lock), and would wait forever. A read is
safe without it — one dict lookup is atomic under the GIL, and the only other writer is the
loop's own thread, which is either paused or between instants when someone reads.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable, Mapping, Sequence

import numpy as np


class BufferStore:
    """Current values of a run's buffers, by name and by index (see the module docstring)."""

    def __init__(self, initial: Mapping[str, float], arrays: Mapping[str, Sequence[str]]) -> None:
        #: the hot loop's view: buffer name -> current value (float)
        self.values: dict[str, float] = {name: float(v) for name, v in initial.items()}
        #: buffer name -> its index in the world's order
        self.index: dict[str, int] = {name: i for i, name in enumerate(self.values)}
        self._arrays: dict[str, tuple[str, ...]] = {k: tuple(v) for k, v in arrays.items()}
        #: held while instants execute; outside writers take it too (one owner: here)
        self.lock = threading.RLock()

    @property
    def names(self) -> list[str]:
        """Every buffer, in index order."""
        return list(self.values)

    def __len__(self) -> int:
        return len(self.values)

    def __contains__(self, name: object) -> bool:
        return name in self.values

    def read(self, name: str) -> float:
        """The current value of buffer ``name`` (KeyError if the world has none)."""
        return self.values[name]

    def read_many(self, names: Iterable[str]) -> np.ndarray:
        """The current values of ``names``, in that order, as one float64 array."""
        values = self.values
        return np.array([values[n] for n in names], dtype=np.float64)

    def row(self) -> np.ndarray:
        """Every buffer's value in index order, as one float64 array (a copy)."""
        return np.fromiter(self.values.values(), dtype=np.float64, count=len(self.values))

    def array(self, name: str) -> np.ndarray:
        """The elements of the array port ``name`` (``Lidar.ranges``), as a float64 array."""
        return self.read_many(self.elements(name))

    def elements(self, name: str) -> tuple[str, ...]:
        """The element buffers of array port ``name``, in order (KeyError if not an array)."""
        return self._arrays[name]

    def slice(self, name: str) -> slice:
        """Where array port ``name``'s elements sit in :meth:`row` (they are consecutive)."""
        elements = self._arrays[name]
        first = self.index[elements[0]]
        return slice(first, first + len(elements))

    def write(self, name: str, value: float) -> None:
        """Set buffer ``name`` from outside the loop (a rospy callback in free mode): the
        value is visible from the next instant; an unknown name is a KeyError."""
        if name not in self.values:
            raise KeyError(name)
        number = float(value)
        with self.lock:
            self.values[name] = number
