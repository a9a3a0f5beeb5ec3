"""An episode after many resets is a fresh env's, on the compiled path and the pure one.

A reset builds the next episode before it frees the one ending, and frees it by breaking
its reference cycles (``Simulation.release``); none of that may reach the next episode.
Each episode below, after several others (ended ones, ones dropped midway, one with its
own parameters, collisions among them), is compared byte for byte with a fresh env's with
the same seed, and the pure path's (``AMSA_PHYS_PURE=1``) with the compiled path's.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym import FollowEnv  # noqa: E402

KW: dict[str, Any] = {"duration": 30, "record_trace": True}
#: mostly full ahead: the follower runs into the leader in some episodes
ACTIONS = np.clip(0.9 + np.random.default_rng(3).uniform(-0.3, 0.3, (150, 2)), -1.0, 1.0)
#: (seed, options, steps before the next reset: None to the episode's end)
BEFORE: list[tuple[int, dict[str, Any] | None, int | None]] = [
    (4, None, None),
    (9, None, 7),
    (4, {"set": {"MyNormalizePower.motorCoef": 35}}, None),
    (12, None, 1),
    (7, None, None),
]


def episode(env: FollowEnv, seed: int, steps: int | None = None, **reset: Any) -> list[Any]:
    """What the agent sees, as bytes and numbers, and the trace (to the end)."""
    obs, info = env.reset(seed=seed, **reset)
    seen: list[Any] = [obs.tobytes(), sorted(info.items())]
    for k, action in enumerate(ACTIONS):
        if steps is not None and k == steps:
            return seen
        obs, reward, terminated, truncated, info = env.step(action)
        seen.append((obs.tobytes(), reward, terminated, truncated, sorted(info.items())))
        if terminated or truncated:
            break
    assert terminated or truncated, "give more actions"
    seen.append(env.trace().tobytes())
    return seen


def after_resets(seed: int) -> tuple[list[Any], int, bool]:
    """The episode of ``seed`` from an env reset through :data:`BEFORE` first, the
    collisions met on the way, and whether it ran on the pure path."""
    env = FollowEnv(**KW)
    collided = 0
    for before, options, steps in BEFORE:
        seen = episode(env, before, steps, options=options)
        if steps is None:
            collided += dict(seen[-2][-1])["collisions"]
    got = episode(env, seed)
    pure = env._episode.sim._walk is None  # type: ignore[union-attr]  (the Python loop)
    env.close()
    return got, collided, pure


@pytest.mark.parametrize("seed", [4, 21])
def test_an_episode_after_resets_is_a_fresh_env_s_on_both_paths(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("AMSA_PHYS_PURE", raising=False)
    fresh = episode(FollowEnv(**KW), seed)
    compiled, collided, on_pure = after_resets(seed)
    monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    pure, _, was_pure = after_resets(seed)
    assert (on_pure, was_pure) == (False, True)
    assert collided > 0  # a collision count left over from an episode would show
    assert compiled == fresh
    assert pure == compiled
