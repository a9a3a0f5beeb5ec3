"""An env reset many times gives, episode for episode, what a fresh env gives.

A reset reuses what it can from the episodes before it (the cycle's layout,
``engine/layout.py``); nothing of an earlier episode may leak into the next: observations,
rewards, terminations, infos and the recorded trace are compared byte for byte with a new
env's, over resets with varied seeds, drawn seeds and per-episode parameter changes.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym import FollowEnv  # noqa: E402

#: (seed, options) of the episodes a single env runs in turn: repeated seeds, a seed drawn by
#: the env (None), parameter changes for one episode and not the next
RESETS: list[tuple[int | None, dict[str, Any] | None]] = [
    (5, None),
    (11, {"set": {"MyNormalizePower.motorCoef": 35, "LeaderGPS.lostDataGPS": 40}}),
    (5, None),
    (None, None),
    (11, None),
    (3, {"set": {"Leader.cruisePower": 4.0}}),
    (2**31 - 2, None),
]


def episode(env: FollowEnv, seed: int | None, options: Any, actions: np.ndarray) -> list[Any]:
    """Everything the agent sees in one episode, as comparable bytes and numbers."""
    obs, info = env.reset(seed=seed, options=options)
    seen: list[Any] = [obs.tobytes(), sorted(info.items())]
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        seen.append((obs.tobytes(), reward, terminated, truncated, sorted(info.items())))
        if terminated or truncated:
            break
    assert terminated or truncated, "the episode did not end: give more actions"
    seen.append(env.trace().tobytes())
    return seen


@pytest.mark.parametrize("observation", ["relative", "absolute"])
def test_episodes_after_many_resets_are_those_of_fresh_envs(observation: str) -> None:
    # mostly full ahead: the follower runs into the leader in some episodes
    actions = np.clip(0.9 + np.random.default_rng(7).uniform(-0.3, 0.3, (200, 2)), -1.0, 1.0)
    kw = {"duration": 40, "observation": observation, "record_trace": True}
    reused = FollowEnv(**kw)
    collided = 0
    for seed, options in RESETS:
        got = episode(reused, seed, options, actions)
        drawn = dict(got[1])["seed"]  # the episode's own (drawn by the env for None)
        want = episode(FollowEnv(**kw), drawn, options, actions)
        assert got == want, f"episode with seed {seed} and options {options} differs"
        collided += dict(got[-2][-1])["collisions"]  # the last step's info
    reused.close()
    assert collided > 0  # the episodes hit something: a collision count left over shows
