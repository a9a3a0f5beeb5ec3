"""A reset reuses the structure the episode before it compiled, and only its own.

Each reset of an env makes the same world with the agent in place (``gym/episode.py``), so
the run takes its tick grid, timer phases and tasks from the last episode's
(``engine/skeleton.py``) instead of compiling them again. Envs of other worlds, reset in
turn, must each get their own: their episodes are the episodes of fresh envs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from test_gym_reset_reuse import episode as reuse_episode  # noqa: E402

from amsa_phys.engine import skeleton  # noqa: E402
from amsa_phys.gym import FollowEnv  # noqa: E402
from amsa_phys.gym.follow import DEFAULT_SCENARIO  # noqa: E402

ACTIONS = np.clip(0.8 + np.random.default_rng(3).uniform(-0.4, 0.4, (100, 2)), -1.0, 1.0)


def episode(env: FollowEnv, seed: int) -> list[Any]:
    """What the agent sees in one episode (``test_gym_reset_reuse``'s, these actions)."""
    return reuse_episode(env, seed, None, ACTIONS)


def moved_leader(tmp_path: Path) -> Path:
    """The packaged scenario on a copy of its world whose leader starts 3 m closer."""
    data = DEFAULT_SCENARIO.parent
    world = (data / "mde_challenge.yaml").read_text()
    assert "x: 15.0" in world
    (tmp_path / "mde_challenge.yaml").write_text(world.replace("x: 15.0", "x: 12.0", 1))
    scenario = tmp_path / "follow.yaml"
    scenario.write_text(DEFAULT_SCENARIO.read_text())
    return scenario


def test_a_reset_compiles_no_task_again_and_keeps_the_agent_world(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    compiled: list[str] = []
    fresh = skeleton.make_task
    monkeypatch.setattr(
        skeleton,
        "make_task",
        lambda w, path, *a, **k: compiled.append(path) or fresh(w, path, *a, **k),
    )
    skeleton.forget()
    env = FollowEnv(duration=5)
    env.reset(seed=1)
    world = env._episode.sim.world
    assert compiled, "the first episode compiled its tasks"
    compiled.clear()
    env.reset(seed=2)
    assert env._episode.sim.world is world
    assert compiled == []
    env.close()


def test_envs_of_other_worlds_reset_in_turn_give_the_episodes_of_fresh_envs(
    tmp_path: Path,
) -> None:
    kw: dict[str, Any] = {"duration": 20, "record_trace": True}
    moved = moved_leader(tmp_path)
    envs = [(FollowEnv(**kw), None), (FollowEnv(moved, **kw), moved)]
    seen = []
    for seed in (4, 9):
        for env, source in envs:
            got = episode(env, seed)
            want = episode(FollowEnv(source, **kw), seed)
            assert got == want, f"seed {seed}, scenario {source or 'packaged'}"
            seen.append(got)
    assert seen[0] != seen[1]  # the two worlds' episodes differ: a mix-up would show
    for env, _ in envs:
        env.close()
