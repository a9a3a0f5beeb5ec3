"""The compiled schedule walk (``engine/walk.py``) runs the Python loop's run: the same
traces, events, changes, clock, cursor and faults, whole or advanced piece by piece."""

from __future__ import annotations

import importlib.util
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import amsa_phys as ap
from amsa_phys.api.source import load
from amsa_phys.engine import publish, walk
from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import RunFault
from amsa_phys.gym import FollowEnv
from amsa_phys.model.scenario import Change, load_scenario

ROOT = Path(__file__).resolve().parents[2]
#: built, and not switched off (``AMSA_PHYS_PURE=1``: the Python paths alone run)
BUILT = (
    importlib.util.find_spec("amsa_phys.engine._kernels") is not None
    and publish._extension("_kernels") is not None
)
pytestmark = pytest.mark.skipif(
    not BUILT, reason="the extension was not built (no C compiler), or the pure path was asked for"
)


def _python_loop(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(walk, "prepare", lambda sim: None)


def _jittered(tmp_path: Path) -> dict[str, Any]:
    """The MDE world with a jittered controller and a delayed GPS: deliveries at ticks off
    the components' grid, several in flight."""
    world = yaml.safe_load((ROOT / "worlds" / "mde_challenge.yaml").read_text())
    world["components"]["MyFollowerController"].update(latency=0.3, jitter=0.2)
    world["components"]["LeaderGPS"].update(latency=0.13)
    path = tmp_path / "jittered.yaml"
    path.write_text(yaml.safe_dump(world))
    return {"name": "jittered", "world": str(path), "duration": 40, "seed": 2}


def _run(source: Any) -> tuple[bytes, list[str]]:
    run = ap.run(source)
    return run.trace.tobytes(), [repr(e) for e in run.events]


#: a run with timeline changes at instants of their own (a phase, parameters, a step change)
TIMELINE: dict[str, Any] = {
    "name": "timeline",
    "world": str(ROOT / "worlds" / "mde_challenge.yaml"),
    "duration": 50,
    "seed": 3,
    "set": {"Leader.behavior": 4, "LeaderGPS.lostDataGPS": 10},
    "timeline": [
        {"at": 10.01, "set": {"MyNormalizePower.motorCoef": 60}},
        {"at": 20, "set": {"MyFollowerController.Kv": 0.2}},
        {"at": 33.333, "set": {"Leader.cruisePower": 12.0}},
    ],
}
SOURCES = {
    "scenario1": lambda _: str(ROOT / "scenarios" / "scenario1.yaml"),
    "timeline": lambda _: TIMELINE,
    # the follower starts against the leader's back at full power: contacts, collisions
    "collisions": lambda _: {
        "name": "collide",
        "world": str(ROOT / "worlds" / "mde_challenge.yaml"),
        "duration": 20,
        "seed": 1,
        "set": {"Follower.x": 14.2, "MyFollowerController.Kv": 3.0},
    },
    "jitter": _jittered,
}


@pytest.mark.parametrize("name", list(SOURCES))
def test_runs_are_byte_identical_with_the_python_loop(
    name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    source = SOURCES[name](tmp_path)
    compiled = _run(source)
    if name == "collisions":
        assert any("collision" in e for e in compiled[1])
    _python_loop(monkeypatch)
    assert _run(source) == compiled


def test_the_walk_is_what_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """Else the comparisons above would compare the Python loop with itself."""
    calls = []
    original = walk.Walk.__call__
    monkeypatch.setattr(walk.Walk, "__call__", lambda w, s, u: calls.append(u) or original(w, s, u))
    sim = Simulation.from_scenario(load_scenario(ROOT / "scenarios" / "scenario1.yaml"))
    sim.run()
    assert isinstance(sim._walk, walk.Walk)
    assert calls == [sim._end]


def _stepped(python: bool, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> list[Any]:
    """The jittered world (deliveries inside runs of physics steps) advanced to uneven
    ticks and to the last tick of a run, a live change queued on the way; the engine's
    state after each piece."""
    if python:
        _python_loop(monkeypatch)
    sim = Simulation.from_scenario(load(_jittered(tmp_path)))
    sim.initialize()
    states = []
    rng = np.random.default_rng(5)
    tick = 0
    for k in range(80):
        # every other piece ends on the last physics step before a 4 Hz instant
        tick = tick + int(rng.integers(0, 90)) if k % 2 else (tick // 25 + 2) * 25 - 1
        if k == 20:
            sim.apply_live(Change("MyFollowerController", "Kv", 0.2))
        sim.advance(tick)
        states.append(
            (
                sim._cursor,
                sim._tick,
                sim.now,
                sim._now_cache,
                sim._next_instant_tick,
                bytes(sim.store.data),
                len(sim.change_log),
                sim.finished,
            )
        )
    return states


def test_advancing_piece_by_piece_gives_the_python_loops_states(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    compiled = _stepped(False, monkeypatch, tmp_path)
    assert len(set(c[5] for c in compiled)) > 40  # the store moved between pieces
    assert _stepped(True, monkeypatch, tmp_path) == compiled


def _failing(python: bool, where: str, at: int, monkeypatch: pytest.MonkeyPatch) -> Any:
    """A run whose monitor (``where="task"``) or batched physics step (``"batch"``) fails
    at its ``at``-th call: the fault and where the run stopped."""
    if python:
        _python_loop(monkeypatch)
    sim = Simulation.from_scenario(load_scenario(ROOT / "scenarios" / "scenario1.yaml"))
    sim.initialize()
    calls = []

    def failing_task(step: Any) -> Any:
        def run(task: Any, now: Fraction) -> None:
            calls.append(now)
            if len(calls) == at:
                raise RunFault(task.path, now, "failed on purpose")
            step(task, now)

        return run

    def failing_batch(many: Any) -> Any:
        def batch(count: int, seek: Any) -> int:
            calls.append(count)
            if len(calls) == at:
                seek(count // 2)  # where the fault happened, as the physics step reports it
                raise RunFault("physics", sim.now, "failed on purpose")
            return int(many(count, seek))

        return batch

    plan = []
    for off, tasks, log, hooks, last, spacing, merge in sim._plan:
        if where == "task":
            tasks = tuple(
                (failing_task(r) if t.path == "MyDistanceMonitor" else r, t) for r, t in tasks
            )
        elif merge is not None:
            merge = (merge[0], merge[1], failing_batch(merge[2]))
        plan.append((off, tasks, log, hooks, last, spacing, merge))
    sim._plan = plan
    with pytest.raises(RunFault) as caught:
        sim.advance(10**6)
    return str(caught.value), getattr(caught.value, "run", None), sim._cursor, sim._tick


@pytest.mark.parametrize("where", ["task", "batch"])
@pytest.mark.parametrize("at", [1, 7, 40])
def test_a_fault_stops_the_walk_where_it_stops_the_python_loop(
    where: str, at: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    compiled = _failing(False, where, at, monkeypatch)
    if where == "task":
        assert compiled[1] == 0  # in_run marked it as the single run's
    else:
        assert compiled[3] > compiled[2] - 1  # the clock at the failed step, past the cursor
    assert _failing(True, where, at, monkeypatch) == compiled


def test_episodes_are_byte_identical_with_the_python_loop(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def episode() -> bytes:
        env = FollowEnv(duration=20)
        obs, _ = env.reset(seed=3)
        rows = [obs]
        for a in np.random.default_rng(1).uniform(-1, 1, (90, 2)):
            obs, reward, _, truncated, info = env.step(a)
            rows += [obs, [reward, info["t"]]]
            if truncated:
                break
        env.close()
        return np.concatenate([np.ravel(r) for r in rows]).tobytes()

    compiled = episode()
    _python_loop(monkeypatch)
    assert episode() == compiled


def test_the_pure_path_gives_the_same_run(monkeypatch: pytest.MonkeyPatch) -> None:
    """``AMSA_PHYS_PURE=1`` (no walk, no compiled bodies, the pure physics step): the same
    trace and events as the compiled path, and no walk prepared."""
    from amsa_phys.engine import publish

    source = TIMELINE
    compiled = _run(source)
    monkeypatch.setenv(publish.PURE_ENV, "1")
    sim = Simulation.from_scenario(load(source))
    sim.initialize()
    assert sim._walk is None
    assert _run(source) == compiled
