"""An env dropped in the middle of an episode, without ``close()``, leaves nothing behind
(``gym/dropguard.py``): its paused run is ended and freed, and a vector env's helper threads
stop. A vector env's helper threads do not pile up across resets either."""

from __future__ import annotations

import gc
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym.follow import FollowEnv
from amsa_phys.gym.vector import FollowVecEnv
from amsa_phys.physics import compiled

SCENARIO1 = str(Path(__file__).resolve().parents[2] / "scenarios" / "scenario1.yaml")


def _gps() -> int:
    return sum(1 for o in gc.get_objects() if type(o).__name__ == "GPS")


def _threads() -> int:
    return len(os.listdir("/proc/self/task"))


@contextmanager
def _no_cyclic_collector() -> Iterator[None]:
    """Only reference counting frees anything inside (what the cyclic collector would find
    later is what a dropped env must not leave)."""
    gc.collect()
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def test_a_dropped_single_env_frees_its_episode() -> None:
    with _no_cyclic_collector():
        before = _gps()
        for seed in range(3):
            env = FollowEnv(SCENARIO1, duration=30)
            env.reset(seed=seed)
            env.step(np.zeros(2))
            assert _gps() == before + 2
            del env
            assert _gps() == before


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="needs /proc")
@pytest.mark.skipif(
    not compiled.columns_compiled(), reason="the compiled step was not built (no C compiler)"
)
def test_a_dropped_vector_env_frees_its_batch_and_stops_its_helpers() -> None:
    with _no_cyclic_collector():
        before, threads = _gps(), _threads()
        env = FollowVecEnv(64, SCENARIO1, duration=30, stepping="batch", threads=2)
        env.reset(seed=1)
        env.step(np.zeros((64, 2)))
        assert (_gps(), _threads()) == (before + 2 * 64, threads + 1)
        del env
        assert (_gps(), _threads()) == (before, threads)


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="needs /proc")
@pytest.mark.skipif(
    not compiled.columns_compiled(), reason="the compiled step was not built (no C compiler)"
)
def test_helpers_do_not_pile_up_across_resets_and_close_stops_them() -> None:
    with _no_cyclic_collector():
        threads = _threads()
        env = FollowVecEnv(64, SCENARIO1, duration=1, stepping="batch", threads=2)
        seen = []
        for seed in range(3):
            env.reset(seed=seed)
            env.step(np.zeros((64, 2)))
            seen.append(_threads() - threads)
        for _ in range(5):  # the episode's end, the autoreset's new batch, its first step
            env.step(np.zeros((64, 2)))
        seen.append(_threads() - threads)
        env.close()
        seen.append(_threads() - threads)
    assert seen == [1, 1, 1, 1, 0]
