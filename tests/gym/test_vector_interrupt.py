"""A Ctrl-C inside a vector env's step: the step raises KeyboardInterrupt, the next step
says the episode was interrupted (not that a run faulted), and a reset goes on."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest

from amsa_phys.gym.vector import FollowVecEnv
from amsa_phys.physics.columns import ColumnPhysics

SCENARIO1 = str(Path(__file__).resolve().parents[2] / "scenarios" / "scenario1.yaml")


def _raising(monkeypatch: pytest.MonkeyPatch) -> list[BaseException]:
    """ColumnPhysics.step_many raising the exception put in the returned list (a batch binds
    the method when it is built: patched before the reset)."""
    pending: list[BaseException] = []
    real = ColumnPhysics.step_many

    def step_many(self: ColumnPhysics, count: int, seek: Any) -> int:
        if pending:
            raise pending.pop()
        return real(self, count, seek)

    monkeypatch.setattr(ColumnPhysics, "step_many", step_many)
    return pending


def test_an_interrupted_step_is_said_as_such_and_a_reset_goes_on(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    pending = _raising(monkeypatch)
    env = FollowVecEnv(8, SCENARIO1, duration=30, stepping="batch")
    env.reset(seed=1)
    env.step(np.zeros((8, 2)))
    pending.append(KeyboardInterrupt())
    with pytest.raises(KeyboardInterrupt):
        env.step(np.zeros((8, 2)))
    with pytest.raises(gymnasium.error.ResetNeeded, match="a step was interrupted"):
        env.step(np.zeros((8, 2)))
    obs, _ = env.reset(seed=2)
    obs2, reward, *_ = env.step(np.zeros((8, 2)))
    assert obs.shape == obs2.shape == (8, 3)
    assert np.isfinite(reward).all()
    env.close()


def test_a_faulted_run_is_said_as_such(monkeypatch: pytest.MonkeyPatch) -> None:
    pending = _raising(monkeypatch)
    env = FollowVecEnv(8, SCENARIO1, duration=30, stepping="batch")
    env.reset(seed=1)
    pending.append(RuntimeError("a fault"))
    with pytest.raises(RuntimeError, match="a fault"):
        env.step(np.zeros((8, 2)))
    with pytest.raises(gymnasium.error.ResetNeeded, match="a run faulted"):
        env.step(np.zeros((8, 2)))
    env.close()
