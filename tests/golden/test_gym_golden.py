"""The Gymnasium env's episodes, step for step, against ones stored before its fast path.

``FollowEnv.step`` was rewritten for speed (issue 29: no worker thread, the observation
built without numpy per element); an agent must see exactly the observations, rewards and
infos it saw before, in both observation modes, on a scenario with a random leader and GPS
losses. Regenerate after an intended change with
``python tests/golden/test_gym_golden.py --regenerate`` (it prints what moved).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym import FollowEnv  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
STORED = HERE / "gym_episodes.npz"
SCENARIO2 = ROOT / "scenarios" / "scenario2.yaml"
MODES = ("relative", "absolute")


def episode(mode: str) -> dict[str, np.ndarray]:
    """One 40 s episode of scenario2 (seed 3) under random actions, every step's outputs."""
    env = FollowEnv(str(SCENARIO2), duration=40, observation=mode)
    obs, info = env.reset(seed=3)
    seen, rewards, infos, ends = [obs], [], [[info["t"], info["signal"], info["collisions"]]], []
    for a in np.random.default_rng(7).uniform(-1, 1, size=(400, 2)):
        obs, reward, terminated, truncated, info = env.step(a)
        seen.append(obs)
        rewards.append(reward)
        infos.append([info["t"], info["signal"], info["collisions"]])
        ends.append([terminated, truncated])
        if truncated:
            break
    env.close()
    return {
        f"{mode}_obs": np.array(seen),
        f"{mode}_reward": np.array(rewards),
        f"{mode}_info": np.array(infos, dtype=np.float64),
        f"{mode}_end": np.array(ends),
    }


@pytest.mark.parametrize("mode", MODES)
def test_episode_is_the_stored_one_step_for_step(mode: str) -> None:
    stored = np.load(STORED)
    now = episode(mode)
    assert len(now[f"{mode}_reward"]) == 160  # 40 s at the controller's 4 Hz
    for key, value in now.items():
        assert value.dtype == stored[key].dtype, key
        assert value.shape == stored[key].shape, key
        moved = np.flatnonzero(~(value == stored[key]).reshape(len(value), -1).all(axis=1))
        assert moved.size == 0, f"{key}: step {moved[0]} differs: {value[moved[0]]!r}"


if __name__ == "__main__" and sys.argv[1:] == ["--regenerate"]:
    fresh: dict[str, np.ndarray] = {}
    for m in MODES:
        fresh.update(episode(m))
    if STORED.exists():
        old = np.load(STORED)
        for k, v in fresh.items():
            same = k in old and v.shape == old[k].shape and bool(np.all(v == old[k]))
            print(f"{k}: {'unchanged' if same else 'MOVED'}")
    np.savez_compressed(STORED, **fresh)
