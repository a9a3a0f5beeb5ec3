"""What the vector env says to a wrong seed, a wrong action shape and a Ctrl-C, whichever
way it steps (one batch, or single envs in turn): the manual's promises, held."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

import amsa_phys as ap  # noqa: E402
from amsa_phys.gym import episode as episode_module  # noqa: E402
from amsa_phys.gym.vector import FollowVecEnv  # noqa: E402
from amsa_phys.model.schema import MAX_SEED  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")
STEPPINGS = ["batch", "single"]


@pytest.mark.parametrize("stepping", STEPPINGS)
def test_a_seed_whose_last_env_is_past_the_largest_is_refused_before_any_reset(
    stepping: str,
) -> None:
    """Env ``i`` gets ``seed + i``: the batch took seeds past 2**63 - 1 (not the seeds its
    runs used, and ``info["seed"]`` turned to floats), the single envs refused one midway,
    naming a seed nobody passed and leaving the episodes half reset."""
    vec = FollowVecEnv(4, SCENARIO1, duration=2, stepping=stepping)
    vec.reset(seed=1)
    with pytest.raises(ap.ConfigError) as refused:
        vec.reset(seed=MAX_SEED - 2)
    said = str(refused.value)
    assert said.startswith(f"seed: must be an integer from 0 to {MAX_SEED - 3} ")
    assert said.endswith(f"got {MAX_SEED - 2}")
    assert "\n" not in said
    # nothing was reset: the episode in progress goes on
    _, reward, *_ = vec.step(np.zeros((4, 2)))
    assert np.isfinite(reward).all()
    _, info = vec.reset(seed=MAX_SEED - 3)  # the largest that fits: the last env's is 2**63 - 1
    assert info["seed"].dtype == np.int64
    assert info["seed"].tolist() == [MAX_SEED - 3, MAX_SEED - 2, MAX_SEED - 1, MAX_SEED]
    vec.close()


@pytest.mark.parametrize("stepping", STEPPINGS)
def test_one_seed_each_may_be_a_numpy_array(stepping: str) -> None:
    """``SyncVectorEnv`` takes an array of seeds; so does the vector env, as the list."""
    vec = FollowVecEnv(3, SCENARIO1, duration=2, stepping=stepping)
    listed, _ = vec.reset(seed=[4, 9, 2])
    arrayed, info2 = vec.reset(seed=np.array([4, 9, 2]))
    assert info2["seed"].tolist() == [4, 9, 2]
    assert arrayed.tobytes() == listed.tobytes()
    vec.close()


@pytest.mark.parametrize("stepping", STEPPINGS)
@pytest.mark.parametrize("shape", [(3, 2, 1), (1, 3, 2), (2, 3), (3,)])
def test_an_action_array_of_another_shape_is_refused(stepping: str, shape: Any) -> None:
    """Only ``(N, k)``, or ``N * k`` values flat: an extra axis of the right size (a
    policy's batch of one) was taken as it came."""
    vec = FollowVecEnv(3, SCENARIO1, duration=2, stepping=stepping)
    vec.reset(seed=1)
    said = f"expected actions of shape (3, 2), got {shape}"
    with pytest.raises(ValueError, match=re.escape(said)):
        vec.step(np.zeros(shape))
    _, reward, *_ = vec.step(np.zeros(6))  # flat, row by row: taken
    assert reward.shape == (3,)
    vec.close()


@pytest.mark.parametrize("stepping", STEPPINGS)
def test_a_ctrl_c_inside_a_step_is_said_as_such_whichever_way_it_steps(
    stepping: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The single envs' stepping said "a run faulted" after a Ctrl-C."""
    pending: list[BaseException] = []
    real = episode_module.Episode.step

    def step(self: Any, outputs: Any) -> None:
        if pending:
            raise pending.pop()
        real(self, outputs)

    monkeypatch.setattr(episode_module.Episode, "step", step)
    if stepping == "batch":  # the batch's run is not an Episode: interrupt its physics
        from amsa_phys.physics.columns import ColumnPhysics

        real_many = ColumnPhysics.step_many

        def step_many(self: ColumnPhysics, count: int, seek: Any) -> int:
            if pending:
                raise pending.pop()
            return real_many(self, count, seek)

        monkeypatch.setattr(ColumnPhysics, "step_many", step_many)
    vec = FollowVecEnv(2, SCENARIO1, duration=5, stepping=stepping)
    vec.reset(seed=1)
    vec.step(np.zeros((2, 2)))
    pending.append(KeyboardInterrupt())
    with pytest.raises(KeyboardInterrupt):
        vec.step(np.zeros((2, 2)))
    with pytest.raises(gymnasium.error.ResetNeeded, match="a step was interrupted"):
        vec.step(np.zeros((2, 2)))
    vec.reset(seed=2)  # and a reset goes on
    _, reward, *_ = vec.step(np.zeros((2, 2)))
    assert np.isfinite(reward).all()
    vec.close()


@pytest.mark.parametrize("stepping", STEPPINGS)
def test_a_step_after_close_says_to_reset_and_a_reset_goes_on(stepping: str) -> None:
    """A closed vector env said "a run faulted" to the next step: nothing had."""
    vec = FollowVecEnv(2, SCENARIO1, duration=2, stepping=stepping)
    vec.reset(seed=1)
    vec.step(np.zeros((2, 2)))
    vec.close()
    with pytest.raises(gymnasium.error.ResetNeeded) as refused:
        vec.step(np.zeros((2, 2)))
    assert str(refused.value) == "call reset() before step()"
    obs, _ = vec.reset(seed=1)
    assert obs.shape == (2, 3)
    vec.close()
