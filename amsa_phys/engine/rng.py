"""The seed tree: one independent, reproducible random stream per component.

Each component's stream is keyed by ``zlib.crc32`` of its path (never ``hash()``, which is
salted per process), so adding a component or running in another process or order leaves
every other component's random numbers unchanged.
"""

from __future__ import annotations

import zlib

import numpy as np


def component_rng(seed: int, path: str) -> np.random.Generator:
    """The Generator for ``path`` under scenario ``seed``."""
    ss = np.random.SeedSequence(entropy=seed, spawn_key=(zlib.crc32(path.encode("utf-8")),))
    return np.random.Generator(np.random.PCG64(ss))
