"""The seed tree: one independent, reproducible random stream per component.

Each component's stream is keyed by ``zlib.crc32`` of its path (never ``hash()``, which is
salted per process), so adding a component or running in another process or order leaves
every other component's random numbers unchanged.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable, Iterator

import numpy as np


def component_rng(seed: int, path: str) -> np.random.Generator:
    """The Generator for ``path`` under scenario ``seed``."""
    ss = np.random.SeedSequence(entropy=seed, spawn_key=(zlib.crc32(path.encode("utf-8")),))
    return np.random.Generator(np.random.PCG64(ss))


class Drawn:
    """Scalars from one random stream, drawn from numpy in blocks.

    A sensor needs one or two random numbers a step; asking numpy for each costs ~1 µs (a
    call and an array), drawing 64 at once costs ~0.02 µs a number. The sequence is fixed by
    the stream alone, so it is the same whatever else the component does between draws.
    ``draw(n)`` returns the next ``n`` numbers, e.g. ``rng.standard_normal``.
    """

    def __init__(self, draw: Callable[[int], np.ndarray], block: int = 64) -> None:
        self._draw = draw
        self._block = block
        self._it: Iterator[float] = iter(())

    def __call__(self) -> float:
        """The next number."""
        try:
            return next(self._it)
        except StopIteration:
            self._it = iter(self._draw(self._block).tolist())
            return next(self._it)
