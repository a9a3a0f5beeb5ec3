"""The samples an STL requirement reads, kept in memory at every logged instant.

A requirement reads a few signals (``Component.output``) of every logged instant; the trace
file has them too, but a sweep or a falsification writes no trace, and the batched engine's
runs share one store. This listener copies the named buffers of every run out of the store
at each logged instant (one fancy-indexed copy, appended to one flat array of doubles), so a
requirement is judged the same way whatever the executor.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Sequence
from fractions import Fraction
from typing import Any

import numpy as np


class SignalSampler:
    """``names`` of each of ``runs`` runs, sampled at every logged instant of a simulation."""

    def __init__(self, names: Sequence[str], runs: int, at: Callable[[str, int], int]) -> None:
        self.names = list(names)
        self.runs = runs
        self._where = np.array([at(n, r) for n in self.names for r in range(runs)], dtype=np.intp)
        self._t = array("d")
        #: every sample, flat: ``len(names) * runs`` doubles per logged instant. A numpy
        #: array per instant cost ~100 bytes of object header for a few doubles of data,
        #: and was what grew with a run's length (a 1-hour run's peak memory)
        self._flat = array("d")

    def listener(self, col: np.ndarray) -> Callable[[float, Any], None]:
        """The log listener reading ``col`` (the store's array)."""
        take = col.take
        where = self._where
        extend = self._flat.frombytes
        times = self._t

        def sample(t_s: float, _values: Any) -> None:
            extend(take(where).tobytes())  # the same doubles, appended as they are
            times.append(t_s)

        return sample

    def count(self) -> int:
        """How many instants were sampled so far (whole ones: see :meth:`table`)."""
        width = len(self._where)
        n = len(self._t)
        return min(n, len(self._flat) // width) if width else n

    def table(self) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """The logged instants and each signal as a ``(samples, runs)`` array."""
        width = len(self._where)
        n = len(self._t)
        if width:  # equal even if Ctrl-C fell between the two appends
            n = min(n, len(self._flat) // width)
        t = np.frombuffer(self._t, dtype=np.float64, count=n).copy()
        shape = (n, len(self.names), self.runs)
        # one copy out of the samples' buffer (slicing the ``array`` first made two)
        data = np.frombuffer(self._flat, dtype=np.float64, count=n * width).copy()
        data = data.reshape(shape)
        return t, {name: data[:, k, :] for k, name in enumerate(self.names)}


class RequirementWatch:
    """A simulation's STL requirements and the sampler of their signals."""

    def __init__(
        self, requirements: Sequence[Any], sampler: SignalSampler, period: Fraction, runs: int
    ) -> None:
        self.requirements = list(requirements)
        self.sampler = sampler
        self.period = period
        self.runs = runs

    @classmethod
    def of(cls, scenario: Any, sim: Any) -> RequirementWatch | None:
        """Watch ``scenario``'s requirements in ``sim`` (every run of a batch: they share
        the scenario's requirements); None if it has none."""
        from ..model.scenariospec import requirements
        from ..stl.requirement import signals_of

        reqs = requirements(scenario)
        if not reqs:
            return None
        runs = len(sim.timelines)
        names = signals_of(reqs)
        sampler = SignalSampler(names, runs, sim.store.at)  # no names: still the instants
        sim.add_log_listener(sampler.listener(sim.store.col))
        return cls(reqs, sampler, 1 / Fraction(sim.log_rate), runs)

    def judged(self) -> list[dict[str, Any]]:
        """Every run's requirements judged in one pass, one column per run."""
        from ..stl.requirement import judge

        t, cols = self.sampler.table()
        return judge(self.requirements, t, cols, self.period, self.runs)
