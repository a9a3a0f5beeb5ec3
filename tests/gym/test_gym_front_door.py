"""Gymnasium as RL users expect (issue 30 item 4): registered by ``import amsa_phys``, a
packaged default scenario, robot-relative normalised observations, pickling, a window."""

from __future__ import annotations

import math
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.gym import FollowEnv  # noqa: E402
from amsa_phys.gym.follow import DEFAULT_SCENARIO  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO2 = str(ROOT / "scenarios" / "scenario2.yaml")


def _python(code: str) -> str:
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    )
    return out.stdout.strip()


@pytest.mark.parametrize(
    "imports", ["import amsa_phys\nimport gymnasium", "import gymnasium\nimport amsa_phys"]
)
def test_make_with_no_arguments_after_import_amsa_phys(imports: str) -> None:
    code = (
        f"{imports}\n"
        "env = gymnasium.make('amsa_phys/Follow-v0')\n"
        "obs, info = env.reset(seed=0)\n"
        "print(obs.shape, info['t'], env.unwrapped.observer.names)\n"
    )
    assert _python(code) == ("(3,) 0.0 ['Leader.forward', 'Leader.left', 'distanceLeaderFollower']")


def test_import_amsa_phys_stays_light_and_registers_lazily() -> None:
    code = (
        "import sys, amsa_phys\n"
        "print(sorted(m for m in ('numpy', 'gymnasium', 'amsa_phys.gym') if m in sys.modules))\n"
        "import gymnasium\n"
        "print('amsa_phys/Follow-v0' in gymnasium.registry, 'amsa_phys.gym' in sys.modules)\n"
    )
    assert _python(code).splitlines() == ["[]", "True False"]


def test_the_packaged_world_is_the_repositorys() -> None:
    packaged = DEFAULT_SCENARIO.with_name("mde_challenge.yaml").read_bytes()
    assert packaged == (ROOT / "worlds" / "mde_challenge.yaml").read_bytes()


def test_default_env_passes_check_env_without_any_warning() -> None:
    from gymnasium.utils.env_checker import check_env

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")  # from make on: its passive checker warns too
        env = gymnasium.make("amsa_phys/Follow-v0", duration=10)
        check_env(env.unwrapped)
        env.reset(seed=1)
        env.step(env.action_space.sample())  # through the wrappers make adds
    env.close()
    assert [str(w.message) for w in caught] == []
    box = env.observation_space
    assert np.isfinite(box.low).all()
    assert np.isfinite(box.high).all()


def test_relative_observation_is_the_leader_in_the_followers_frame_normalised() -> None:
    # the same episode seen both ways: the relative view is computed from the absolute one
    rel = FollowEnv(SCENARIO2, duration=20)
    ab = FollowEnv(SCENARIO2, duration=20, observation="absolute")
    actions = np.random.default_rng(2).uniform(-1, 1, size=(60, 2))
    o_rel, _ = rel.reset(seed=4)
    o_ab, _ = ab.reset(seed=4)
    scale = rel.observer.range_m
    for a in [None, *actions]:
        if a is not None:
            o_rel, *_ = rel.step(a)
            o_ab, *_ = ab.step(a)
        x_l, y_l, x_f, y_f, heading, dist = o_ab
        dx, dy = x_l - x_f, y_l - y_f
        forward = (math.cos(heading) * dx + math.sin(heading) * dy) / scale
        left = (-math.sin(heading) * dx + math.cos(heading) * dy) / scale
        expected = np.clip([forward, left, dist / scale], -1, 1)
        np.testing.assert_allclose(o_rel, expected, rtol=0, atol=1e-12)
        assert rel.observation_space.contains(o_rel)
    # the leader starts 15 m straight ahead of the follower: forward, not left
    assert rel.reset(seed=4)[0][0] == pytest.approx(15 / scale, abs=0.01)
    rel.close()
    ab.close()


def test_pickled_env_is_a_fresh_env_with_the_same_arguments() -> None:
    env = FollowEnv(SCENARIO2, duration=5)
    obs, _ = env.reset(seed=7)
    first, *_ = env.step(np.array([0.3, 0.2]))
    clone = pickle.loads(pickle.dumps(env))  # mid-episode: the worker thread is not copied
    assert isinstance(clone, FollowEnv)
    assert clone.observer.names == env.observer.names
    again, _ = clone.reset(seed=7)
    np.testing.assert_array_equal(again, obs)
    step, *_ = clone.step(np.array([0.3, 0.2]))
    np.testing.assert_array_equal(step, first)
    env.close()
    clone.close()


def test_an_env_from_make_pickles_with_its_wrappers() -> None:
    """What vector envs and multiprocessing send to workers: ``gym.make``'s env, wrapped."""
    env = gymnasium.make("amsa_phys/Follow-v0", duration=5)
    obs, _ = env.reset(seed=3)
    clone = pickle.loads(pickle.dumps(env))
    again, _ = clone.reset(seed=3)
    np.testing.assert_array_equal(again, obs)
    assert clone.spec is not None
    assert clone.spec.id == "amsa_phys/Follow-v0"
    env.close()
    clone.close()


def test_human_render_mode_opens_a_window_and_draws_each_step(monkeypatch) -> None:
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")  # a window with no display
    from amsa_phys.view.pg import pygame

    env = FollowEnv(duration=2, render_mode="human", render_size=(320, 200))
    env.metadata = {**env.metadata, "render_fps": 1000}  # pace fast in the test
    env.reset(seed=1)
    screen = pygame.display.get_surface()
    assert screen is not None
    assert screen.get_size() == (320, 200)
    for _ in range(3):
        env.step(np.array([0.5, 0.5]))
    assert env.render() is None  # "human" draws in step(), as Gymnasium's envs do
    pixels = pygame.surfarray.array3d(screen)
    assert len(np.unique(pixels.reshape(-1, 3), axis=0)) > 3  # ground, rovers, text
    env.close()
    assert not pygame.display.get_init()
