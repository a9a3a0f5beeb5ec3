"""``amsa_phys/Follow-v0``: the agent in place of the controller, checked against the engine."""

from __future__ import annotations

import subprocess
import sys
import warnings
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

import amsa_phys as ap  # noqa: E402
import amsa_phys.gym  # noqa: E402  registers amsa_phys/Follow-v0
from amsa_phys.control.follower import FollowerController  # noqa: E402
from amsa_phys.gym import FollowEnv  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")
SCENARIO2 = str(ROOT / "scenarios" / "scenario2.yaml")


def test_passes_gymnasiums_env_checker() -> None:
    from gymnasium.utils.env_checker import check_env

    env = gymnasium.make("amsa_phys/Follow-v0", scenario=SCENARIO2, duration=30)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)  # also makes it with render_mode="rgb_array" and renders
    env.close()
    # relative observations have finite bounds: not even Gymnasium's "unbounded" warning
    assert [str(w.message) for w in caught] == []


def test_spaces_are_the_controllers_ports() -> None:
    env = FollowEnv(SCENARIO1, duration=10, observation="absolute")
    assert env.path == "MyFollowerController"  # the world's only controller
    assert env.observed == [
        "xLeader",
        "yLeader",
        "xFollower",
        "yFollower",
        "headingFollower",
        "distanceLeaderFollower",
    ]
    assert env.acted == ["LeftPower", "RightPower"]  # leaderSpeed is read by no component
    assert env.observation_space.shape == (6,)
    assert (env.action_space.low.tolist(), env.action_space.high.tolist()) == ([-1, -1], [1, 1])
    assert env.metadata["render_fps"] == 4.0
    _, info = env.reset(seed=1)
    # the monitor runs before the controller (dataflow order): the agent first sees 15 m
    assert info == {"t": 0.0, "signal": 15.0, "collisions": 0, "seed": 1}
    _, _, _, _, info = env.step(np.array([0.5, 0.5]))
    assert info["t"] == 0.25  # one step is one period of the 4 Hz controller
    env.close()


def rollout(env: FollowEnv, seed: int, steps: int) -> tuple[list[np.ndarray], list[float]]:
    obs, _ = env.reset(seed=seed)
    actions = np.random.default_rng(0).uniform(-1, 1, size=(steps, 2))
    seen, rewards = [obs], []
    for a in actions:
        obs, reward, _, _, _ = env.step(a)
        seen.append(obs)
        rewards.append(reward)
    return seen, rewards


def test_reset_with_a_seed_is_deterministic_and_seeds_differ() -> None:
    env = FollowEnv(SCENARIO2, duration=30)
    a = rollout(env, 5, 40)
    b = rollout(env, 5, 40)
    c = rollout(FollowEnv(SCENARIO2, duration=30), 6, 40)
    assert all(np.array_equal(x, y) for x, y in zip(a[0], b[0], strict=True))
    assert a[1] == b[1]
    assert not np.array_equal(a[0][-1], c[0][-1])  # a random leader: the seed matters
    env.close()


def test_the_agent_acting_as_the_controller_reproduces_the_run_bit_for_bit() -> None:
    # an agent that computes the paper's law itself must give the engine's own run: the
    # agent acts exactly where the component would, instant for instant
    scenario = ap.load(SCENARIO1, duration=60)
    leaf = scenario.world.leaves["MyFollowerController"]
    params = dict(leaf.params)
    params.update({c.param: c.value for c in scenario.timeline.initial if c.leaf == leaf.path})
    law = FollowerController(leaf.path, params)
    law.initialize(None)
    env = FollowEnv(
        SCENARIO1,
        duration=60,
        actions=["LeftPower", "RightPower", "leaderSpeed"],
        action_scale=1.0,
        record_trace=True,
        observation="absolute",
    )
    obs, info = env.reset(seed=scenario.seed)
    steps = 0
    while True:
        out = law.do_step(Fraction(info["t"]), dict(zip(env.observed, obs.tolist(), strict=True)))
        obs, _, terminated, truncated, info = env.step([out[k] for k in env.acted])
        steps += 1
        assert not terminated
        if truncated:
            break
    assert steps == 240  # 60 s at 4 Hz; at t = 60 the episode is over
    ours = env.trace()
    ref = ap.run(SCENARIO1, duration=60)
    assert ours.dtype == ref.trace.dtype
    # the final instant: the agent is not asked, its outputs keep the last action, and the
    # controller's outputs reach their readers (and the trace) only after its 0.75 s
    # latency: neither run's final step shows, so the traces are equal to the last row
    assert scenario.world.leaves["MyFollowerController"].timing.latency == Fraction(3, 4)
    assert ours.tobytes() == ref.trace.tobytes()
    env.close()


def test_reward_is_the_scaled_error_minus_collisions() -> None:
    # full power from 15 m behind a straight-driving leader: the follower rams it
    env = FollowEnv(SCENARIO1, duration=60, collision_penalty=10.0)
    env.reset(seed=1)
    rewards, infos = [], []
    for _ in range(200):
        _, reward, _, truncated, info = env.step(np.array([1.0, 1.0]))
        rewards.append(reward)
        infos.append(info)
        if info["collisions"] or truncated:
            break
    assert infos[-1]["collisions"] >= 1
    expected = [-abs(i["signal"] - 15) / 1.5 for i in infos]
    expected[-1] -= 10.0 * infos[-1]["collisions"]
    assert rewards == pytest.approx(expected, abs=1e-12)
    assert rewards[0] == pytest.approx(-abs(infos[0]["signal"] - 15) / 1.5)
    assert rewards[-1] < -10
    env.close()


def test_vector_env_over_seeds_matches_single_envs() -> None:
    envs = gymnasium.make_vec(
        "amsa_phys/Follow-v0",
        num_envs=2,
        vectorization_mode="sync",
        scenario=SCENARIO2,
        duration=20,
    )
    assert type(envs).__name__ == "SyncVectorEnv"
    obs, _ = envs.reset(seed=[11, 12])
    actions = np.random.default_rng(1).uniform(-1, 1, size=(30, 2, 2))
    for a in actions:
        obs, _, _, _, _ = envs.step(a)
    envs.close()
    for i, seed in enumerate((11, 12)):
        single = FollowEnv(SCENARIO2, duration=20)
        single_obs, _ = single.reset(seed=seed)
        for a in actions[:, i]:
            single_obs, _, _, _, _ = single.step(a)
        np.testing.assert_array_equal(obs[i], single_obs)
        single.close()


def test_renders_with_the_projects_renderer() -> None:
    env = FollowEnv(SCENARIO1, duration=30, render_mode="rgb_array", render_size=(320, 240))
    env.reset(seed=1)
    for _ in range(20):
        env.step(np.array([0.6, 0.6]))
    frame = env.render()
    assert frame is not None
    assert (frame.shape, frame.dtype) == ((240, 320, 3), np.uint8)
    colours = {tuple(c) for c in frame.reshape(-1, 3)}
    assert (230, 120, 30) in colours  # the leader, orange as in the window and the video
    assert (31, 119, 180) in colours  # the follower, blue
    env.close()
    assert FollowEnv(SCENARIO1, duration=5).render() is None  # render_mode=None


def test_a_small_frame_shows_the_rovers_under_its_text_boxes() -> None:
    """At 320x200 the status box (``agent: ...``) goes under the HUD, over the middle of
    the frame, where the camera put the rovers: the leader was drawn behind it. The rovers
    are framed in the room the boxes leave, as in the window."""
    env = FollowEnv(render_mode="rgb_array", render_size=(320, 200))
    env.reset(seed=1)
    for _ in range(30):
        env.step(np.array([0.5, 0.5]))
    frame = env.render()
    assert frame is not None
    source = env.unwrapped._frames
    below = max(box.bottom for box in source.renderer.boxes.values())
    assert below > 200 // 3  # the boxes do reach the middle at this size
    for rover in source.frame.rovers:
        _, y = source.camera.to_screen(rover.x, rover.y)
        assert below < y < 200, (rover.name, y, below)
    colours = {tuple(c) for c in frame.reshape(-1, 3)}
    assert (230, 120, 30) in colours  # the leader is seen
    env.close()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (
            {"controller": "MyFollowerControler"},
            "controller: unknown component 'MyFollowerControler' "
            "(did you mean MyFollowerController?)",
        ),
        (
            {"controller": "Nope"},
            "controller: unknown component 'Nope' (the world's controllers: MyFollowerController)",
        ),
        ({"actions": ["Left"]}, "actions: MyFollowerController has no output 'Left'"),
        ({"render_mode": "ansi"}, "render_mode: unknown render mode 'ansi'"),
        ({"observation": "polar"}, "observation: unknown observation 'polar'"),
        (
            {"set": {"MyFollowerController.Kvv": 1}},
            'set={"MyFollowerController.Kvv": ...}: unknown parameter',
        ),
    ],
    ids=["controller", "controller-far", "actions", "render-mode", "observation", "set"],
)
def test_bad_arguments_are_one_line_errors(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(ap.ConfigError) as err:
        FollowEnv(SCENARIO1, **kwargs)  # type: ignore[arg-type]
    assert str(err.value).startswith(message), str(err.value)


def test_a_world_with_many_controllers_asks_which() -> None:
    with pytest.raises(ap.ConfigError) as err:
        FollowEnv(str(ROOT / "scenarios" / "platoon.yaml"), duration=5)
    assert str(err.value).startswith("controller: the world has 10 controllers (Car1.Pilot, ")
    env = FollowEnv(str(ROOT / "scenarios" / "platoon.yaml"), duration=5, controller="Car3.Pilot")
    obs, _ = env.reset(seed=0)
    assert obs.shape == env.observation_space.shape
    env.close()


def test_step_after_the_end_asks_for_reset_and_reset_options_set_parameters() -> None:
    env = FollowEnv(SCENARIO1, duration=1)
    env.reset(seed=1, options={"set": {"MyNormalizePower.motorCoef": 50}})
    truncated = False
    while not truncated:
        _, _, _, truncated, info = env.step(np.zeros(2))
    assert info["t"] == 1.0
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(np.zeros(2))
    with pytest.raises(ap.ConfigError, match="unknown reset option 'sett'"):
        env.reset(options={"sett": {}})
    env.close()
    env.close()  # twice is fine


def test_gymnasium_finds_the_env_without_an_explicit_import() -> None:
    code = (
        "import gymnasium\n"
        "env = gymnasium.make('amsa_phys.gym:amsa_phys/Follow-v0', "
        f"scenario={SCENARIO1!r}, duration=2)\n"
        "obs, info = env.reset(seed=0)\n"
        "print(obs.shape, info['t'])\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    )
    assert out.stdout.strip() == "(3,) 0.0"


def test_a_component_reading_an_array_is_refused_in_one_line() -> None:
    """The obstacle course's avoider reads the lidar's ranges (an array port): the env
    used to fail at the first observation with numpy's "truth value of an array"."""
    with pytest.raises(ap.ConfigError, match="array input 'ranges'"):
        FollowEnv(str(ROOT / "scenarios" / "obstacle_course.yaml"))
