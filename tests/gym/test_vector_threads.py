"""The vector env's ``threads``: the batch's physics step split between threads gives the
same episodes, bit for bit, as one thread (``physics/workers.h``, ``_step.Columns``)."""

from __future__ import annotations

import hashlib
import multiprocessing
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.errors import ConfigError
from amsa_phys.gym.vector import MAX_THREADS, FollowVecEnv
from amsa_phys.physics import compiled

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")

needs_c = pytest.mark.skipif(
    not compiled.columns_compiled(), reason="the compiled step was not built (no C compiler)"
)


def _records(threads: int, actions: np.ndarray, seeds: list[int]) -> tuple[list[bytes], int]:
    """Every vector step's observations, rewards, ends and the columns' state, rims and
    touched runs; and how many helper threads the step ran with."""
    vec = FollowVecEnv(len(seeds), SCENARIO1, duration=30, stepping="batch", threads=threads)
    obs, _ = vec.reset(seed=seeds)
    episode = vec._episode
    assert episode is not None
    assert episode.columns is not None
    columns = episode.columns
    seen = [obs.tobytes()]
    for a in actions:
        obs, reward, term, trunc, info = vec.step(a)
        seen += [obs.tobytes(), reward.tobytes(), term.tobytes(), trunc.tobytes()]
        seen += [info["collisions"].tobytes(), columns._io.state.tobytes()]
        seen += [columns._model.rims.tobytes(), columns._touched.tobytes()]
    workers = columns._fused.workers
    solo = sorted(episode.solo)
    vec.close()
    return [*seen, repr(solo).encode()], workers


@needs_c
@pytest.mark.parametrize("threads", [2, 3])
def test_threads_give_the_bits_of_one_thread(threads: int) -> None:
    """101 envs (202 rovers in three chunks, an odd number of runs: the chunks end at even
    rovers) for a whole 30 s episode, random actions, two envs ramming their leaders (frozen
    in the columns, then made alone): every record equal to one thread's, and the step did
    run with ``threads - 1`` helpers."""
    n, steps = 101, 120
    actions = np.random.default_rng(11).uniform(-1, 1, size=(steps, n, 2))
    actions[:, 3] = 1.0
    actions[10:, 8] = 1.0
    seeds = list(range(60, 60 + n))
    one, none = _records(1, actions, seeds)
    many, helpers = _records(threads, actions, seeds)
    assert (none, helpers) == (0, threads - 1)
    assert one[-1] == many[-1] == b"[3, 8]"  # the rammers went alone in both
    first = next((k for k, (a, b) in enumerate(zip(one, many, strict=True)) if a != b), None)
    assert first is None, f"first difference at record {first}"


@pytest.mark.parametrize("bad", [0, MAX_THREADS + 1, 1.5, True, "2"])
def test_a_wrong_threads_is_refused_naming_it(bad: object) -> None:
    with pytest.raises(ConfigError) as err:
        FollowVecEnv(20, SCENARIO1, duration=1, threads=bad)  # type: ignore[arg-type]
    assert err.value.key == "threads"
    assert f"1 to {MAX_THREADS}" in str(err.value)
    assert "\n" not in str(err.value)


def _digest(vec: FollowVecEnv, actions: np.ndarray) -> str:
    h = hashlib.sha256()
    for a in actions:
        obs, reward, *_ = vec.step(a)
        h.update(obs.tobytes() + reward.tobytes())
    return h.hexdigest()


def _child(vec: FollowVecEnv, actions: np.ndarray, conn: object) -> None:
    conn.send(_digest(vec, actions))  # type: ignore[attr-defined]


@needs_c
@pytest.mark.skipif(
    "fork" not in multiprocessing.get_all_start_methods(), reason="no fork on this platform"
)
def test_a_forked_child_steps_with_workers_of_its_own() -> None:
    """A process forked after the helpers started has none of them (fork copies one
    thread): its steps start their own and give the parent's bits, where waiting for the
    parent's helpers would hang it."""
    actions = np.random.default_rng(2).uniform(-1, 1, size=(6, 64, 2))
    vec = FollowVecEnv(64, SCENARIO1, duration=30, stepping="batch", threads=2)
    vec.reset(seed=3)
    vec.step(actions[0])  # the helpers start
    episode = vec._episode
    assert episode is not None
    assert episode.columns is not None
    assert episode.columns._fused.workers == 1
    ctx = multiprocessing.get_context("fork")
    ours, theirs = ctx.Pipe()
    child = ctx.Process(target=_child, args=(vec, actions[1:], theirs))
    child.start()
    try:
        assert ours.poll(300), "the forked child's steps did not finish"
        digest = ours.recv()
    finally:
        child.kill()
        child.join()
    assert digest == _digest(vec, actions[1:])
    vec.close()


def test_threads_given_to_a_single_env_is_said_to_be_the_vector_envs() -> None:
    """``make_vec(..., vectorization_mode="sync", threads=2)`` hands it to every FollowEnv:
    a one-line ConfigError naming the vector env's way, not a bare TypeError."""
    import gymnasium

    import amsa_phys  # noqa: F401  (registers the env)

    with pytest.raises(ConfigError) as err:
        gymnasium.make_vec("amsa_phys/Follow-v0", num_envs=2, vectorization_mode="sync", threads=2)
    assert err.value.key == "threads"
    assert 'vectorization_mode="vector_entry_point"' in str(err.value)
