"""What the envs say to the code that drives them, found trying them as a user: the vector
env importable from the package, a wrong action shape said as the single env says it,
Gymnasium's info masks in every vectorization mode, and why a faulted episode refuses a
step."""

from __future__ import annotations

from pathlib import Path

import gymnasium
import numpy as np
import pytest

from amsa_phys.errors import RunFault
from amsa_phys.gym import FollowEnv, FollowVecEnv

ROOT = Path(__file__).resolve().parents[2]
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")


def test_the_vector_env_is_importable_from_the_package() -> None:
    import amsa_phys.gym

    assert "FollowVecEnv" in amsa_phys.gym.__all__
    assert FollowVecEnv.__module__ == "amsa_phys.gym.vector"


@pytest.mark.parametrize("stepping", ["batch", "single"])
@pytest.mark.parametrize("shape", [(15, 2), (2,), (2, 16), (16, 3)])
def test_a_wrong_action_shape_is_said_with_the_shape_expected(
    stepping: str, shape: tuple[int, ...]
) -> None:
    env = FollowVecEnv(16, SCENARIO1, duration=5, stepping=stepping)
    env.reset(seed=1)
    try:
        with pytest.raises(ValueError, match="expected actions of shape") as caught:
            env.step(np.zeros(shape))
        assert str(caught.value) == f"expected actions of shape (16, 2), got {shape}"
        env.step(np.zeros((16, 2)))  # refused before anything stepped: the episode goes on
    finally:
        env.close()


@pytest.mark.parametrize("mode", ["sync", "vector_entry_point"])
def test_info_carries_gymnasiums_masks_in_every_mode(mode: str) -> None:
    """``info["_t"]`` and the rest, as SyncVectorEnv gives them: code written for one mode
    works in the other."""
    env = gymnasium.make_vec("amsa_phys/Follow-v0", num_envs=3, vectorization_mode=mode)
    try:
        _, info = env.reset(seed=1)
        assert {"_t", "_signal", "_collisions", "_seed"} <= set(info)
        _, _, _, _, info = env.step(env.action_space.sample())
        for key in ("t", "signal", "collisions"):
            mask = info["_" + key]
            assert mask.dtype == np.bool_
            assert mask.tolist() == [True, True, True]
    finally:
        env.close()


def test_a_faulted_single_episode_says_why_it_refuses_the_next_step() -> None:
    env = FollowEnv(SCENARIO1, duration=10)
    env.reset(seed=1)
    with pytest.raises(RunFault):
        env.step(np.array([np.nan, 0.0]))
    with pytest.raises(gymnasium.error.ResetNeeded) as caught:
        env.step(np.zeros(2))
    assert str(caught.value) == "call reset() before step(): its run faulted"
    env.reset(seed=1)  # a new episode steps again
    env.step(np.zeros(2))
    env.close()


def test_a_step_before_any_reset_says_only_to_reset() -> None:
    """A fresh env, or one unpickled from a stepped one (its wrappers think it was reset),
    said "the episode has ended" of an episode that never began."""
    import pickle

    env = gymnasium.make("amsa_phys/Follow-v0", scenario=SCENARIO1, duration=5)
    env.reset(seed=1)
    env.step(np.zeros(2))
    copy = pickle.loads(pickle.dumps(env))
    for fresh in (FollowEnv(SCENARIO1, duration=5), copy):
        with pytest.raises(gymnasium.error.ResetNeeded) as caught:
            fresh.step(np.zeros(2))
        assert str(caught.value) == "call reset() before step()"
        fresh.close()
    env.close()


def test_a_refused_first_reset_and_the_way_out_the_manual_gives() -> None:
    """Gymnasium's passive checker breaks every step of a made env whose first reset
    raised; the manual says so and gives the way out. When Gymnasium fixes it, the first
    half fails: drop the manual's paragraph then."""
    import amsa_phys as ap

    env = gymnasium.make("amsa_phys/Follow-v0", scenario=SCENARIO1, duration=5)
    with pytest.raises(ap.ConfigError):
        env.reset(seed=-1)
    env.reset(seed=1)
    with pytest.raises(TypeError, match="cannot unpack non-iterable NoneType"):
        env.step(np.zeros(2))
    env.close()
    kept = gymnasium.make(
        "amsa_phys/Follow-v0", scenario=SCENARIO1, duration=5, disable_env_checker=True
    )
    with pytest.raises(ap.ConfigError):
        kept.reset(seed=-1)
    kept.reset(seed=1)
    _, reward, *_ = kept.step(np.zeros(2))
    assert np.isfinite(reward)
    kept.close()
