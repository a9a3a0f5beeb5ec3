"""``FollowVecEnv``: N episodes as one batched simulation, each the single env's episode."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

import amsa_phys as ap  # noqa: E402
from amsa_phys.gym import FollowEnv  # noqa: E402
from amsa_phys.gym.vector import FollowVecEnv  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO2 = str(ROOT / "scenarios" / "scenario2.yaml")
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")
#: both ways the vector env steps: one batched simulation, or single envs in turn
STEPPINGS = ["batch", "single"]


@pytest.mark.parametrize("stepping", STEPPINGS)
@pytest.mark.parametrize("observation", ["relative", "absolute"])
def test_vector_env_equals_single_envs_step_for_step(observation: str, stepping: str) -> None:
    seeds = [11, 12, 13]
    vec = FollowVecEnv(3, SCENARIO2, duration=6, observation=observation, stepping=stepping)
    obs, info = vec.reset(seed=seeds)
    assert info["seed"].tolist() == seeds
    actions = np.random.default_rng(1).uniform(-1, 1, size=(24, 3, 2))
    v_obs, v_rew, v_trunc = [obs], [], []
    for a in actions:
        obs, reward, terminated, truncated, _ = vec.step(a)
        assert not terminated.any()
        v_obs.append(obs)
        v_rew.append(reward)
        v_trunc.append(truncated)
    vec.close()
    assert v_trunc[-1].all()
    assert not np.array(v_trunc[:-1]).any()  # 6 s at 4 Hz: the 24th step ends it
    for i, seed in enumerate(seeds):
        single = FollowEnv(SCENARIO2, duration=6, observation=observation)
        s_obs, _ = single.reset(seed=seed)
        np.testing.assert_array_equal(v_obs[0][i], s_obs)
        for k, a in enumerate(actions):
            s_obs, s_rew, _, s_trunc, _ = single.step(a[i])
            np.testing.assert_array_equal(v_obs[k + 1][i], s_obs)  # bit for bit
            assert v_rew[k][i] == s_rew
            assert v_trunc[k][i] == s_trunc
        single.close()
    # the random leader: the seeds make different episodes
    assert not np.array_equal(v_obs[-1][0], v_obs[-1][1])


def test_collisions_cost_the_run_that_collides() -> None:
    # full power from 15 m behind a straight leader rams it: the same step as alone
    vec = FollowVecEnv(2, SCENARIO1, duration=60, stepping="batch")
    vec.reset(seed=[1, 2])
    single = FollowEnv(SCENARIO1, duration=60)
    single.reset(seed=1)
    for _ in range(240):
        _, reward, _, _, info = vec.step(np.array([[1.0, 1.0], [0.0, 0.0]]))
        _, s_reward, _, _, s_info = single.step(np.array([1.0, 1.0]))
        assert reward[0] == s_reward
        if s_info["collisions"]:
            break
    assert info["collisions"].tolist() == [s_info["collisions"], 0]
    assert info["collisions"][0] >= 1
    vec.close()
    single.close()


@pytest.mark.parametrize("stepping", STEPPINGS)
def test_next_step_autoreset(stepping: str) -> None:
    vec = FollowVecEnv(2, SCENARIO1, duration=1, stepping=stepping)
    assert vec.metadata["autoreset_mode"] is gymnasium.vector.AutoresetMode.NEXT_STEP
    vec.reset(seed=5)
    truncated = np.zeros(2, dtype=bool)
    steps = 0
    while not truncated.any():
        _, _, _, truncated, info = vec.step(np.zeros((2, 2)))
        steps += 1
    assert steps == 4
    assert truncated.all()
    assert info["t"].tolist() == [1.0, 1.0]
    # the next step starts new episodes: first observations, reward 0, no end, t = 0
    obs, reward, terminated, truncated, info = vec.step(np.ones((2, 2)))
    assert reward.tolist() == [0.0, 0.0]
    assert not terminated.any()
    assert not truncated.any()
    assert info["t"].tolist() == [0.0, 0.0]
    assert vec.observation_space.contains(obs)
    _, _, _, _, info = vec.step(np.zeros((2, 2)))
    assert info["t"].tolist() == [0.25, 0.25]  # and they run on
    vec.close()


def test_make_vec_uses_it_and_an_int_seed_seeds_each_env() -> None:
    import amsa_phys.gym  # noqa: F401  (registration)

    envs = gymnasium.make_vec(
        "amsa_phys/Follow-v0", num_envs=2, vectorization_mode="vector_entry_point", duration=2
    )
    assert isinstance(envs.unwrapped, FollowVecEnv)
    _, info = envs.reset(seed=7)
    assert info["seed"].tolist() == [7, 8]
    assert envs.observation_space.shape == (2, 3)
    envs.close()


def test_bad_arguments() -> None:
    with pytest.raises(ap.ConfigError, match="num_envs"):
        FollowVecEnv(0, SCENARIO1)
    with pytest.raises(ap.ConfigError, match="stepping must be one of auto, batch, single"):
        FollowVecEnv(2, SCENARIO1, stepping="columns")
    vec = FollowVecEnv(2, SCENARIO1, duration=1)
    with pytest.raises(ap.ConfigError, match="expected 2 seeds"):
        vec.reset(seed=[1])
    with pytest.raises(gymnasium.error.ResetNeeded):
        vec.step(np.zeros((2, 2)))


def test_every_component_steps_as_columns_and_the_rovers_are_columns() -> None:
    """The vector env rides the batch's columns: every component, the robots included,
    steps as one group of all runs, its ports slices of the store's array, and the rovers
    of all runs are the column physics' rows (no run's Space is stepped)."""
    vec = FollowVecEnv(3, SCENARIO2, duration=2, stepping="batch")
    vec.reset(seed=5)
    episode = vec._episode
    assert episode is not None
    sim = episode.sim
    grouped = {g.paths[0]: g for gs in sim._groups_of.values() for g in gs}
    assert set(grouped) == set(sim.world.leaves)
    for group in grouped.values():
        assert len(group.tasks) == 3
        assert all(isinstance(at, slice) for _, at in group.inputs)
    for _ in range(8):
        vec.step(np.zeros((3, 2)))
    columns = episode.columns
    assert columns.steps == 200  # 2 s at 100 Hz, for all runs at once
    assert len(columns.rovers) == 6
    assert all(w.space.current_time_step == 0 for w in columns.worlds)  # never stepped
    vec.close()


def _single_episode(seed: int, actions: np.ndarray, **kw: object) -> list[tuple]:
    """The single env's (obs, reward, truncated, info) with ``seed`` and ``actions``."""
    single = FollowEnv(**kw)  # type: ignore[arg-type]
    obs, info = single.reset(seed=seed)
    seen = [(obs, 0.0, False, info)]
    for a in actions:
        obs, reward, _, truncated, info = single.step(a)
        seen.append((obs, reward, truncated, info))
    single.close()
    return seen


def test_runs_that_come_within_reach_continue_alone_exactly_as_the_single_env() -> None:
    """Contacts are not the columns': a run whose rovers come within reach is made alone
    (its single episode replayed with the agent's past outputs). Every run, the ones that
    ram their leader included, is the single env's episode bit for bit, for a whole
    episode of the packaged scenario (random leader, GPS loss): observation, reward, end,
    signal and collisions."""
    n, steps = 4, 160  # 40 s
    rng = np.random.default_rng(7)
    actions = rng.uniform(-1, 1, size=(steps, n, 2))
    actions[:, 0] = 1.0  # full power from the start: rams the leader
    actions[60:, 3] = 1.0  # full power from 15 s on: rams it later
    seeds = [21, 22, 23, 24]
    vec = FollowVecEnv(n, duration=40, stepping="batch")
    obs, _ = vec.reset(seed=seeds)
    seen = [(obs, np.zeros(n), np.zeros(n, dtype=bool), None)]
    for a in actions:
        obs, reward, terminated, truncated, info = vec.step(a)
        assert not terminated.any()
        seen.append((obs, reward, truncated, info))
    episode = vec._episode
    assert episode is not None
    assert {0, 3} <= set(episode.solo)  # the rammers went alone
    assert 2 not in episode.solo  # a random walk stays far behind its leader
    for i, seed in enumerate(seeds):
        single = _single_episode(seed, actions[:, i], duration=40)
        for k, (s_obs, s_rew, s_trunc, s_info) in enumerate(single):
            v_obs, v_rew, v_trunc, v_info = seen[k]
            np.testing.assert_array_equal(v_obs[i], s_obs)  # bit for bit
            assert v_rew[i] == s_rew
            assert v_trunc[i] == s_trunc
            if v_info is not None:
                assert v_info["signal"][i] == s_info["signal"]
                assert v_info["collisions"][i] == s_info["collisions"]
                assert v_info["t"][i] == s_info["t"]
    assert seen[-1][3]["collisions"][0] >= 1  # the rammer did collide
    vec.close()


def test_a_seed_gives_the_same_episode_whatever_the_batch_and_its_order() -> None:
    """Determinism: a run depends on its seed only, not on the number of envs, its place
    in the batch, or which runs went alone beside it."""
    actions = {5: 0.2, 6: 1.0, 7: -0.3}  # seed -> constant action (seed 6 rams its leader)

    def run(seeds: list[int]) -> dict[int, list[np.ndarray]]:
        vec = FollowVecEnv(len(seeds), SCENARIO2, duration=30, stepping="batch")
        obs, _ = vec.reset(seed=seeds)
        rows = {s: [obs[i]] for i, s in enumerate(seeds)}
        a = np.array([[actions[s]] * 2 for s in seeds])
        for _ in range(120):
            obs, reward, _, _, _ = vec.step(a)
            for i, s in enumerate(seeds):
                rows[s] += [obs[i], reward[i : i + 1]]
        vec.close()
        return rows

    three = run([5, 6, 7])
    two = run([7, 6])
    one = run([5])
    for seed, rows in (*two.items(), *one.items()):
        assert all(np.array_equal(a, b) for a, b in zip(rows, three[seed], strict=True))


def test_a_run_within_reach_stops_moving_in_the_columns() -> None:
    """Once a run is found within reach its rows in the columns are no longer used; they
    are frozen, so a follower passing through its leader there (no contacts in columns)
    can never fly off and fault the whole batch (``gym/veccolumns.py``)."""
    vec = FollowVecEnv(2, SCENARIO1, duration=60, stepping="batch")
    vec.reset(seed=[1, 2])
    episode = vec._episode
    assert episode is not None
    full = np.array([[1.0, 1.0], [0.2, 0.2]])
    for _ in range(200):  # the follower reaches its leader in ~25 s
        vec.step(full)
        if episode.solo:
            break
    columns = episode.columns
    frozen = columns._io.state[:2].copy()  # run 0's two rovers
    moving = columns._io.state[2:].copy()
    for _ in range(8):
        vec.step(full)
    np.testing.assert_array_equal(columns._io.state[:2], frozen)
    assert not np.array_equal(columns._io.state[2:], moving)  # run 1 goes on in the columns
    assert set(episode.solo) == {0}
    vec.close()


@pytest.mark.parametrize("stepping", STEPPINGS)
def test_stepping_from_another_thread_is_refused(stepping: str) -> None:
    import threading

    vec = FollowVecEnv(2, SCENARIO1, duration=5, stepping=stepping)
    vec.reset(seed=3)
    caught: list[BaseException] = []

    def other() -> None:
        try:
            vec.step(np.zeros((2, 2)))
        except BaseException as exc:
            caught.append(exc)

    worker = threading.Thread(target=other)
    worker.start()
    worker.join()
    assert isinstance(caught[0], RuntimeError)
    assert str(caught[0]).startswith("step() must be called from the thread that called reset()")
    _, _, _, _, info = vec.step(np.zeros((2, 2)))  # the refused step did not happen
    assert info["t"].tolist() == [0.25, 0.25]
    vec.close()


def test_gymnasiums_vector_wrappers_and_the_checkers_rules() -> None:
    """What ``env_checker`` asks of a single env, asked of the vector env (Gymnasium 1.x has
    no vector checker): observations in the batched space as float64 arrays of their own
    (not reused by the next step), the reset seeds deterministic, Gymnasium's own vector
    wrappers run on it (episode statistics at the autoreset)."""
    from gymnasium.wrappers.vector import RecordEpisodeStatistics

    vec = RecordEpisodeStatistics(FollowVecEnv(3, SCENARIO2, duration=2))
    obs, _ = vec.reset(seed=4)
    again, _ = FollowVecEnv(3, SCENARIO2, duration=2).reset(seed=4)
    np.testing.assert_array_equal(obs, again)
    kept = obs.copy()
    for k in range(10):
        new, reward, terminated, truncated, info = vec.step(vec.action_space.sample())
        assert vec.observation_space.contains(new)
        assert new.dtype == np.float64
        assert reward.dtype == np.float64
        assert terminated.dtype == truncated.dtype == np.bool_
        np.testing.assert_array_equal(obs, kept)  # the previous observation is untouched
        obs, kept = new, new.copy()
        if k == 7:
            assert truncated.all()
            assert info["episode"]["l"].tolist() == [8, 8, 8]  # the wrapper saw the end
    vec.close()


def test_a_world_columns_cannot_hold_runs_each_space_and_still_equals_the_single_env(
    tmp_path: Path,
) -> None:
    """A terrain zone (a mud strip the rovers cross) is what a batched sweep cannot hold
    (its columns have one ground). The vector env then steps each run's own Space (the
    other components still grouped), and each run is still the single env's episode."""
    import yaml

    world = yaml.safe_load((ROOT / "worlds" / "mde_challenge.yaml").read_text())
    world["components"]["Mud"] = {
        "template": "frictionZone",
        "freq": 1,
        "params": {
            "friction": 0.3,
            "rollingResistance": 0.05,
            "polygon": [[2, -10], [30, -10], [30, 10], [2, 10]],
        },
    }
    (tmp_path / "world.yaml").write_text(yaml.safe_dump(world))
    scenario = {
        "world": str(tmp_path / "world.yaml"),
        "duration": 6,
        "quality": {
            "signal": "MyDistanceMonitor.distanceFollowerToLeader",
            "reference": 15,
            "tolerance": 1.5,
        },
    }
    vec = FollowVecEnv(2, scenario, stepping="batch")
    vec.reset(seed=[3, 4])
    episode = vec._episode
    assert episode is not None
    assert episode.columns is None
    assert "terrain zone" in str(episode.why_not_columns)
    actions = np.random.default_rng(2).uniform(0, 1, size=(24, 2, 2))
    seen = [vec.step(a) for a in actions]
    vec.close()
    for i, seed in enumerate([3, 4]):
        single = _single_episode(seed, actions[:, i], scenario=scenario)
        for (obs, reward, *_), (s_obs, s_rew, *_) in zip(seen, single[1:], strict=True):
            np.testing.assert_array_equal(obs[i], s_obs)
            assert reward[i] == s_rew


def test_adapt_rules_are_refused_with_the_way_out() -> None:
    with pytest.raises(ap.ConfigError, match=r"adapt: rules.*FollowEnv"):
        FollowVecEnv(2, str(ROOT / "scenarios" / "adaptive.yaml"))


def test_many_runs_within_reach_at_once_go_alone_together_and_equal_the_single_env() -> None:
    """Five runs driving at full power behind a straight leader reach it at the same
    instant: they go alone as one batch of per-run Spaces (``CHUNK``), replayed together,
    and still equal their single envs, collisions (counted by their Spaces) included."""
    n, steps = 6, 120  # 30 s
    actions = np.ones((steps, n, 2))
    actions[0, :, 0] = np.linspace(0.9, 1.0, n)  # one first step each: their own episodes
    actions[:, 5] = 0.0
    seeds = list(range(30, 36))
    vec = FollowVecEnv(n, SCENARIO1, duration=30, stepping="batch")
    vec.reset(seed=seeds)
    seen = [vec.step(a) for a in actions]
    episode = vec._episode
    assert episode is not None
    assert episode.solo == {0, 1, 2, 3, 4}
    (runs, member), *rest = episode.alone
    assert not rest
    assert runs.tolist() == [0, 1, 2, 3, 4]
    assert member.columns is None  # per-run Spaces  # type: ignore[union-attr]
    assert (seen[-1][4]["collisions"][:5] >= 1).all()
    vec.close()
    for i in (0, 4, 5):
        single = _single_episode(seeds[i], actions[:, i], scenario=SCENARIO1, duration=30)
        for (obs, reward, _, truncated, info), (s_obs, s_rew, s_trunc, s_info) in zip(
            seen, single[1:], strict=True
        ):
            np.testing.assert_array_equal(obs[i], s_obs)
            assert reward[i] == s_rew
            assert truncated[i] == s_trunc
            assert info["collisions"][i] == s_info["collisions"]


@pytest.mark.parametrize("stepping", STEPPINGS)
def test_a_fault_is_raised_by_step_then_reset_is_needed(stepping: str) -> None:
    """A run's fault (a non-finite action, refused by the engine as the single env's)
    is raised by the step that meets it; the batch then needs a reset, like the single env."""
    from amsa_phys.errors import RunFault

    vec = FollowVecEnv(2, SCENARIO1, duration=5, stepping=stepping)
    vec.reset(seed=1)
    vec.step(np.zeros((2, 2)))
    with pytest.raises(RunFault, match="agent"):
        vec.step(np.array([[0.0, 0.0], [np.nan, 0.0]]))
    with pytest.raises(gymnasium.error.ResetNeeded):
        vec.step(np.zeros((2, 2)))
    _, info = vec.reset(seed=1)
    assert info["t"].tolist() == [0.0, 0.0]
    vec.close()


def test_after_the_autoreset_every_run_is_back_in_the_columns() -> None:
    """The runs that went alone in one episode start the next one in the columns, and
    that episode is again the single env's."""
    vec = FollowVecEnv(2, SCENARIO1, duration=30, stepping="batch")
    vec.reset(seed=[8, 9])
    ram = np.array([[1.0, 1.0], [0.0, 0.0]])
    for _ in range(120):
        vec.step(ram)
    assert vec._episode is not None
    assert vec._episode.solo == {0}
    _, _, _, _, info = vec.step(ram)  # the autoreset
    seeds = info["seed"].tolist()
    assert vec._episode.solo == set()
    seen = [vec.step(ram)[0] for _ in range(8)]
    vec.close()
    single = _single_episode(seeds[0], ram[:1].repeat(8, axis=0), scenario=SCENARIO1, duration=30)
    for obs, (s_obs, *_) in zip(seen, single[1:], strict=True):
        np.testing.assert_array_equal(obs[0], s_obs)
