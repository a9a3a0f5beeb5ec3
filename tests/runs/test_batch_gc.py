"""A batch collects its young garbage less often while it runs, and leaves the process's
garbage-collector settings as it found them (an in-process sweep, a notebook's)."""

from __future__ import annotations

import gc
from pathlib import Path
from typing import Any

import pytest

from amsa_phys.runs import batched
from amsa_phys.runs.sweep import Axis, SweepPlan

ROOT = Path(__file__).resolve().parents[2]


def _jobs() -> list[Any]:
    plan = SweepPlan(
        ROOT / "scenarios" / "scenario1.yaml",
        [Axis("MyFollowerController.Kv", (0.05, 0.2))],
        seeds=1,
        base_seed=3,
        duration=1.0,
    )
    return plan.jobs()


@pytest.fixture
def thresholds() -> Any:
    saved = gc.get_threshold()
    gc.set_threshold(700, 9, 8)  # a user's own, not the default's second and third
    yield
    gc.set_threshold(*saved)


def test_a_batch_runs_with_fewer_young_collections_and_restores_the_settings(
    thresholds: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen: list[tuple[int, int, int]] = []
    real = batched._run_whole

    def watching(sim: Any) -> None:
        seen.append(gc.get_threshold())
        real(sim)

    monkeypatch.setattr(batched, "_run_whole", watching)
    rows = batched.run_batch(_jobs())
    assert [r["error"] for r in rows] == ["", ""]
    assert seen == [(batched.YOUNG_GC, 9, 8)]
    assert gc.get_threshold() == (700, 9, 8)


def test_a_batch_that_raises_restores_the_settings(
    thresholds: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    def interrupted(sim: Any) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(batched, "_run_whole", interrupted)
    with pytest.raises(KeyboardInterrupt):
        batched.run_batch(_jobs())
    assert gc.get_threshold() == (700, 9, 8)


def test_a_higher_threshold_of_the_users_is_kept(thresholds: Any) -> None:
    gc.set_threshold(10 * batched.YOUNG_GC, 9, 8)
    with batched.fewer_collections():
        assert gc.get_threshold() == (10 * batched.YOUNG_GC, 9, 8)
    assert gc.get_threshold() == (10 * batched.YOUNG_GC, 9, 8)


def test_a_batch_freezes_what_it_built_while_it_runs_and_lets_it_go_after(
    thresholds: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The batch's set-up runs with the collector off and what it built is frozen while the
    loop runs (never traversed again); at its end nothing stays frozen, the collector is on,
    also when the set-up faults or the loop is interrupted."""
    seen: list[tuple[bool, int]] = []
    real = batched._run_whole

    def watching(sim: Any) -> None:
        seen.append((gc.isenabled(), gc.get_freeze_count()))
        real(sim)

    monkeypatch.setattr(batched, "_run_whole", watching)
    batched.run_batch(_jobs())
    assert seen[0][0]
    assert seen[0][1] > 0  # the batch's objects frozen during the loop
    assert gc.isenabled()
    assert gc.get_freeze_count() == 0

    def interrupted(sim: Any) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(batched, "_run_whole", interrupted)
    with pytest.raises(KeyboardInterrupt):
        batched.run_batch(_jobs())
    assert gc.isenabled()
    assert gc.get_freeze_count() == 0


def test_objects_the_process_froze_are_left_frozen(thresholds: Any) -> None:
    """A process that froze objects of its own (a forking server): the batch freezes nothing
    (one unfreeze would let the process's go too) and unfreezes nothing."""
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        rows = batched.run_batch(_jobs())
        assert [r["error"] for r in rows] == ["", ""]
        # nothing added, nothing let go (frozen objects freed by reference counting leave)
        assert 0 < gc.get_freeze_count() <= frozen
    finally:
        gc.unfreeze()


def test_a_vector_env_builds_its_episode_uncollected_and_leaves_nothing_frozen(
    thresholds: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The vector env's reset builds its batch with the collector off (what it builds lives
    as long as the episode) and lets it back at once: after the reset and a step the
    collector is on, nothing is frozen and the thresholds are the process's."""
    from amsa_phys.gym import vecepisode
    from amsa_phys.gym.vector import FollowVecEnv

    seen: list[bool] = []
    real = vecepisode.VecEpisode.__init__

    def watching(self: Any, *args: Any, **kwargs: Any) -> None:
        seen.append(gc.isenabled())
        real(self, *args, **kwargs)

    monkeypatch.setattr(vecepisode.VecEpisode, "__init__", watching)
    env = FollowVecEnv(32, stepping="batch")
    env.reset(seed=1)
    env.step(env.action_space.sample())
    assert seen == [False]
    assert gc.isenabled()
    assert gc.get_freeze_count() == 0
    assert gc.get_threshold() == (700, 9, 8)
    env.close()
