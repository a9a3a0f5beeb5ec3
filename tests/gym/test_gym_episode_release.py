"""A reset or a close frees the episode it ends at once, by reference counting.

An episode's run is hundreds of objects that refer to one another; left in reference
cycles they wait for the cyclic garbage collector, which an env reset every few hundred
steps then keeps busy. These tests run with the collector switched off, so anything an
ended episode still holds in a cycle stays alive and shows, on the compiled path and on the
pure one (``AMSA_PHYS_PURE=1``).
"""

from __future__ import annotations

import gc
import weakref
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the gym extra is not installed")

from amsa_phys.engine.runner import Simulation  # noqa: E402
from amsa_phys.gym import FollowEnv  # noqa: E402

HALF = np.array([0.5, 0.5])


@pytest.fixture(params=["compiled", "pure"])
def path(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Both paths: the switch is read when a run is built."""
    if request.param == "pure":
        monkeypatch.setenv("AMSA_PHYS_PURE", "1")
    else:
        monkeypatch.delenv("AMSA_PHYS_PURE", raising=False)
    return str(request.param)


@pytest.fixture
def no_collector() -> Iterator[None]:
    gc.collect()
    gc.disable()
    try:
        yield
    finally:
        gc.enable()


def held(env: FollowEnv) -> list[weakref.ref[Any]]:
    """Weak references to the episode's components, its physics world and its store (the
    env's episode keeps the released run's empty shell, :attr:`Simulation.released`)."""
    sim = env._episode.sim  # type: ignore[union-attr]
    refs: list[weakref.ref[Any]] = [weakref.ref(c) for c in sim.components.values()]
    refs.append(weakref.ref(sim.store))
    refs += [weakref.ref(v) for v in sim.shared.values()]
    return refs


def alive(refs: list[weakref.ref[Any]]) -> list[str]:
    return [type(obj).__name__ for obj in (r() for r in refs) if obj is not None]


def _module(obj: object) -> str:
    module = getattr(type(obj), "__module__", "")
    return module if isinstance(module, str) else ""


def live_simulations() -> int:
    """Simulations not released: the env's ended ones must all be."""
    return sum(1 for obj in gc.get_objects() if isinstance(obj, Simulation) and not obj.released)


@pytest.mark.usefixtures("no_collector")
def test_a_reset_midway_frees_the_episode_it_ends(path: str) -> None:
    env = FollowEnv(duration=20)
    env.reset(seed=1)
    for _ in range(5):
        env.step(HALF)
    first = held(env)
    shell = weakref.ref(env._episode.sim)  # type: ignore[union-attr]
    env.reset(seed=2)
    assert alive(first) == []
    assert shell() is None
    env.close()


@pytest.mark.usefixtures("no_collector")
def test_an_ended_episode_is_freed_at_the_next_reset_and_at_close(path: str) -> None:
    env = FollowEnv(duration=5)  # 20 agent steps
    before = live_simulations()
    for seed in range(3):
        env.reset(seed=seed)
        refs = held(env)
        done = False
        while not done:
            _, _, terminated, truncated, _ = env.step(HALF)
            done = terminated or truncated
        assert alive(refs) != []  # the ended episode still answers (its final observation)
        env.close()
        assert alive(refs) == []
    assert live_simulations() == before
    env.close()  # twice is fine


@pytest.mark.usefixtures("no_collector")
def test_many_resets_leave_none_of_the_package_s_objects_behind(path: str) -> None:
    before = live_simulations()  # other tests' (the collector is off)
    env = FollowEnv(duration=5)
    env.reset(seed=0)
    env.step(HALF)

    def ours() -> int:
        """Objects of the package's own classes (a module of ``amsa_phys``)."""
        return sum(1 for o in gc.get_objects() if _module(o).startswith("amsa_phys"))

    env.reset(seed=1)
    for _ in range(3):  # the current episode as far on as the last one below will be
        env.step(HALF)
    start = ours()
    for seed in range(2, 12):
        env.reset(seed=seed)
        for _ in range(3):
            env.step(HALF)
    assert ours() == start
    env.close()
    assert live_simulations() == before


def test_a_released_run_says_so_and_releasing_twice_is_fine() -> None:
    env = FollowEnv(duration=5)
    env.reset(seed=0)
    sim = env._episode.sim  # type: ignore[union-attr]
    assert not sim.released
    env.close()
    assert sim.released
    sim.release()
    assert sim.released


def test_a_reset_sets_off_no_collection_and_frees_the_old_episode_after_the_new(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The new episode is built with the youngest generation collected less often, and the
    ended one freed after it: no collection runs inside the build or the close, and the
    collector's count of new objects goes up by the new episode's objects and back down by
    the old one's. Freed first, the old episode would take the count down to its floor of
    zero and the new one's objects would then count in full: a collection every reset or
    two, moving the new episode's objects on to the older generations, whose growth sets
    off the full collections that walk every object of the process."""
    from amsa_phys.gym import episode as episode_module

    inside = [False]
    during: list[int] = []
    order: list[str] = []
    real_init, real_close = episode_module.Episode.__init__, episode_module.Episode.close

    def watched(real: Any, name: str) -> Any:
        def call(self: Any, *args: Any, **kwargs: Any) -> Any:
            inside[0] = True
            order.append(f"{name} {id(self)}")
            try:
                return real(self, *args, **kwargs)
            finally:
                inside[0] = False
                order.append(f"{name} done")

        return call

    monkeypatch.setattr(episode_module.Episode, "__init__", watched(real_init, "build"))
    monkeypatch.setattr(episode_module.Episode, "close", watched(real_close, "close"))

    def noted(phase: str, info: dict[str, int]) -> None:
        if phase == "start" and inside[0]:
            during.append(info["generation"])

    env = FollowEnv(duration=5)
    env.reset(seed=0)
    gc.callbacks.append(noted)
    try:
        for seed in range(1, 21):
            for _ in range(3):
                env.step(HALF)
            old = id(env._episode)
            del order[:]
            env.reset(seed=seed)
            new = id(env._episode)
            assert order == [f"build {new}", "build done", f"close {old}", "close done"]
    finally:
        gc.callbacks.remove(noted)
    env.close()
    assert during == []
