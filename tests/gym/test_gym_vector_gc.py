"""The vector env builds each batch of episodes with the garbage collector's youngest
generation collected less often (``runs/batched.fewer_collections``), and leaves the
process's own settings as they were, at reset and at the autoreset alike."""

from __future__ import annotations

import gc
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym import vecepisode
from amsa_phys.gym.vector import FollowVecEnv
from amsa_phys.runs.batched import YOUNG_GC

SCENARIO1 = str(Path(__file__).resolve().parents[2] / "scenarios" / "scenario1.yaml")


def test_the_build_collects_less_often_and_the_settings_come_back(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    during: list[int] = []
    real = vecepisode.VecEpisode.__init__

    def spied(self: object, *args: object, **kwargs: object) -> None:
        during.append(gc.get_threshold()[0])
        real(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(vecepisode.VecEpisode, "__init__", spied)
    old = gc.get_threshold()
    try:
        gc.set_threshold(123, 7, 9)  # the user's own settings
        env = FollowVecEnv(2, SCENARIO1, duration=1, stepping="batch")
        env.reset(seed=0)
        assert gc.get_threshold() == (123, 7, 9)
        for _ in range(5):  # 1 s at 4 Hz, then the autoreset builds a new batch
            env.step(np.zeros((2, 2)))
        assert gc.get_threshold() == (123, 7, 9)
        env.close()
    finally:
        gc.set_threshold(*old)
    assert during == [YOUNG_GC, YOUNG_GC]


def _alive(name: str) -> int:
    return sum(1 for o in gc.get_objects() if type(o).__name__ == name)


def test_an_ended_batch_is_freed_without_the_cyclic_collector() -> None:
    """A reset (and the autoreset) lets the previous batch go by reference counting
    (``MultiRun.release``): with the cyclic collector off, the old runs' components, physics
    worlds and rovers are gone as soon as the new batch stands, so a 1,000-env reset does
    not hold two batches until a full collection (peak memory) nor leave one for it to walk."""
    kinds = ("GPS", "PhysicsWorld", "DiffDriveRover")
    gc.collect()
    before = [_alive(k) for k in kinds]  # what other tests of this process still hold

    def alive() -> tuple[int, ...]:
        return tuple(_alive(k) - b for k, b in zip(kinds, before, strict=True))

    was = gc.isenabled()
    gc.disable()
    try:
        env = FollowVecEnv(6, SCENARIO1, duration=1, stepping="batch")
        seen = []
        for seed in range(3):
            env.reset(seed=seed)
            env.step(np.zeros((6, 2)))
            seen.append(alive())
        for _ in range(4):  # through the autoreset's new batch
            env.step(np.zeros((6, 2)))
        seen.append(alive())
        env.close()
    finally:
        if was:
            gc.enable()
    # each batch: 6 runs of two GPS, one world and two rovers (the single env beside it
    # holds none before its first reset)
    assert seen == [(12, 6, 12)] * 4
