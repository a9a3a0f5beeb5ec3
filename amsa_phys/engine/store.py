"""The buffer store: every Data buffer's current value, in one float64 array.

A run's buffers (``Component.port``, and one element buffer ``Lidar.ranges[i]`` per element
of an array port) have a fixed order, the world's; buffer ``b`` is *column* ``b`` of the
store. A batch of ``runs`` runs of one world (``engine/multirun.py``) has one row per run in
every column: the value of buffer ``b`` in run ``r`` sits at ``b * runs + r`` of one flat
float64 array, so a column (one buffer across every run) is a contiguous slice and a run's
row is a strided one. A single run is the batch of one (``runs = 1``, position = column).

Two views share that one array, and nothing is ever copied between them:

* :attr:`BufferStore.data`, an ``array('d')``: what the scalar path (a component's step,
  a delayed delivery, a trace row) indexes by integer position. Measured on CPython 3.11,
  ns per access: ``array('d')[i]`` read 18, write 31; ``dict[name]`` read 23, write 45;
  ``ndarray[i]`` read 65 (and it returns an ``np.float64``, whose arithmetic is slower and
  whose division by zero warns instead of raising). So the scalar path keeps its speed
  without a dict, and components still receive Python floats;
* :attr:`BufferStore.col`, a numpy view of the same memory: what grouped and batched
  components (``engine/batch.py``) read and write in place, a whole port of a group in one
  C call (a slice when the members' buffers are evenly spaced, as copies of a Composite or
  the runs of a batch are; a fancy index otherwise).

Names are for the world outside the loop: :attr:`index` gives each buffer's column, and
:attr:`values` is a ``MutableMapping`` by name over run 0 (a single run's buffers) for the
log listeners, adaptation rules and tests that speak names.

Code outside the loop (the Gymnasium env, the window, rospy callbacks in free mode) uses
:meth:`read`, :meth:`read_many` and :meth:`write`. The store owns the one lock: the
simulation holds it while it executes instants (:meth:`Simulation.advance`), and an outside
writer takes it, so a write from another thread lands between two instants, never inside one.
Readers never take it: the Gymnasium env reads from the agent's thread while the loop's
thread is paused *inside* an instant (holding the lock), and would wait forever. A read is
safe without it — one element read is atomic under the GIL, and the only other writer is the
loop's own thread, which is either paused or between instants when someone reads.
"""

from __future__ import annotations

import threading
from array import array
from collections.abc import Iterable, Iterator, Mapping, MutableMapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..model.world import WorldSpec


class BufferStore:
    """Current values of a run's (or a batch's) buffers (see the module docstring)."""

    def __init__(
        self,
        initial: Mapping[str, float],
        arrays: Mapping[str, Sequence[str]],
        runs: int = 1,
    ) -> None:
        if runs < 1:
            raise ValueError(f"a store holds at least one run, not {runs}")
        #: rows per column: the runs of a batch (1 for a single run)
        self.runs = runs
        #: buffer name -> its column (the world's order)
        self.index: dict[str, int] = {name: b for b, name in enumerate(initial)}
        #: the one float64 array, column-major: buffer ``b`` of run ``r`` at ``b * runs + r``
        self.data = array("d", [float(v) for v in initial.values() for _ in range(runs)])
        #: the same memory as a numpy array (grouped components read and write it in place)
        self.col: np.ndarray = np.frombuffer(self.data, dtype=np.float64)
        #: the same memory as a (buffers, runs) table
        self.table: np.ndarray = self.col.reshape(len(self.index), runs)
        self._arrays: dict[str, tuple[str, ...]] = {k: tuple(v) for k, v in arrays.items()}
        #: run 0's buffers by name (a single run's), for readers that speak names
        self.values = NamedValues(self, 0)
        #: held while instants execute; outside writers take it too (one owner: here)
        self.lock = threading.RLock()

    @classmethod
    def of_worlds(cls, worlds: Sequence[WorldSpec], extra: Sequence[str] = ()) -> BufferStore:
        """The store of a batch of runs of ``worlds`` (one world per run, one structure),
        each buffer at its world's initial value; ``extra`` buffers (the rule column of
        ``adapt:``) start at 0 in every run."""
        first = worlds[0]
        initial = {n: b.initial for n, b in first.buffers.items()}
        initial.update((name, 0.0) for name in extra)
        store = cls(initial, first.arrays, runs=len(worlds))
        for run, world in enumerate(worlds[1:], 1):
            for name, buf in world.buffers.items():
                store.data[store.at(name, run)] = float(buf.initial)
        return store

    @property
    def names(self) -> list[str]:
        """Every buffer, in column order."""
        return list(self.index)

    def __len__(self) -> int:
        return len(self.index)

    def __contains__(self, name: object) -> bool:
        return name in self.index

    def at(self, name: str, run: int = 0) -> int:
        """The position of buffer ``name`` of run ``run`` in :attr:`data` (KeyError if the
        world has no such buffer, IndexError if the batch no such run)."""
        if not 0 <= run < self.runs:
            raise IndexError(f"run {run} of a batch of {self.runs}")
        return self.index[name] * self.runs + run

    def read(self, name: str, run: int = 0) -> float:
        """The current value of buffer ``name`` (KeyError if the world has none)."""
        return self.data[self.at(name, run)]

    def read_many(self, names: Iterable[str], run: int = 0) -> np.ndarray:
        """The current values of ``names`` in run ``run``, in that order, as a float64 array."""
        at = self.at
        return self.col[[at(n, run) for n in names]]

    def column(self, name: str) -> np.ndarray:
        """Buffer ``name`` in every run, in run order (a copy: one float64 per run)."""
        return self.table[self.index[name]].copy()

    def row(self, run: int = 0) -> np.ndarray:
        """Every buffer's value in run ``run``, in column order (a copy)."""
        if not 0 <= run < self.runs:
            raise IndexError(f"run {run} of a batch of {self.runs}")
        return self.table[:, run].copy()

    def array(self, name: str, run: int = 0) -> np.ndarray:
        """The elements of the array port ``name`` (``Lidar.ranges``), as a float64 array."""
        return self.read_many(self.elements(name), run)

    def elements(self, name: str) -> tuple[str, ...]:
        """The element buffers of array port ``name``, in order (KeyError if not an array)."""
        return self._arrays[name]

    def slice(self, name: str) -> slice:
        """Where array port ``name``'s elements sit in :meth:`row` (they are consecutive)."""
        elements = self._arrays[name]
        first = self.index[elements[0]]
        return slice(first, first + len(elements))

    def write(self, name: str, value: float, run: int = 0) -> None:
        """Set buffer ``name`` from outside the loop (a rospy callback in free mode): the
        value is visible from the next instant; an unknown name is a KeyError."""
        at = self.at(name, run)
        number = float(value)
        with self.lock:
            self.data[at] = number


class NamedValues(MutableMapping[str, float]):
    """One run's buffers by name, over the store's array (no copy): reads give floats,
    writes land in the array. Buffers are the world's: a new name is a KeyError."""

    def __init__(self, store: BufferStore, run: int) -> None:
        self._index = store.index
        self._data = store.data
        self._runs = store.runs
        self._run = run

    def __getitem__(self, name: str) -> float:
        return self._data[self._index[name] * self._runs + self._run]

    def __setitem__(self, name: str, value: float) -> None:
        self._data[self._index[name] * self._runs + self._run] = float(value)

    def __delitem__(self, name: str) -> None:
        raise TypeError("a run's buffers are fixed by its world")

    def __iter__(self) -> Iterator[str]:
        return iter(self._index)

    def __len__(self) -> int:
        return len(self._index)

    def __contains__(self, name: object) -> bool:
        return name in self._index


class ReadAPI:
    """The public read API of a simulation over its :attr:`store` (``Simulation``'s)."""

    store: BufferStore

    def read(self, buffer: str, run: int = 0) -> float:
        """The current value of Data ``buffer`` (``Component.port``) in run ``run``; safe
        from any thread, and never waits (the module docstring says why)."""
        return self.store.read(buffer, run)

    def read_many(self, buffers: Sequence[str], run: int = 0) -> np.ndarray:
        """The current values of ``buffers`` as one float64 array, read together."""
        return self.store.read_many(buffers, run)

    def column(self, buffer: str) -> np.ndarray:
        """Data ``buffer`` in every run of a batch, in run order (a copy)."""
        return self.store.column(buffer)

    def write(self, buffer: str, value: float) -> None:
        """Set Data ``buffer`` from outside the loop (another thread); visible from the next
        instant, never in the middle of one."""
        self.store.write(buffer, value)
