"""The vector env's rewards on columns: before any run goes alone no run can collide, so
the penalty term is skipped; once one has, each run's new collisions cost it the penalty.
Either way each env's reward is its single env's, whatever the penalty."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym import FollowEnv
from amsa_phys.gym.vector import FollowVecEnv

SCENARIO1 = str(Path(__file__).resolve().parents[2] / "scenarios" / "scenario1.yaml")


@pytest.mark.parametrize("penalty", [10.0, 0.0, 2.5])
def test_rewards_before_and_after_a_collision_are_the_single_envs(penalty: float) -> None:
    # env 0 rams its leader at full power (goes alone, then collides); env 1 stands still
    actions = np.array([[1.0, 1.0], [0.0, 0.0]])
    vec = FollowVecEnv(2, SCENARIO1, duration=60, stepping="batch", collision_penalty=penalty)
    vec.reset(seed=[1, 2])
    singles = [FollowEnv(SCENARIO1, duration=60, collision_penalty=penalty) for _ in range(2)]
    for env, seed in zip(singles, [1, 2], strict=True):
        env.reset(seed=seed)
    hits = 0
    for k in range(240):
        _, reward, _, _, info = vec.step(actions)
        for i, env in enumerate(singles):
            _, s_reward, _, _, s_info = env.step(actions[i])
            assert reward[i] == s_reward, (k, i)
            assert info["collisions"][i] == s_info["collisions"], (k, i)
        assert not np.signbit(reward[reward == 0]).any()  # + 0.0: never a -0.0 reward
        if info["collisions"][0] and (hits := hits + 1) > 8:
            break  # collided, and stepped on a while alone
    assert info["collisions"][0] >= 1
    assert vec._episode is not None
    assert 0 in vec._episode.solo
    assert 1 not in vec._episode.solo
    vec.close()
    for env in singles:
        env.close()
