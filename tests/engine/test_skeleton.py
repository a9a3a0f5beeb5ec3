"""A run built from a kept skeleton is the run a fresh compilation gives (engine/skeleton.py).

A reset builds a new Simulation of the same world; its tick grid, timer phases and tasks are
taken from the run before it. Nothing of that run may leak into the next: a delayed Leaf's
delay line (its jitter is drawn from the run's seed, its last due tick is the run's) and the
record of its own outputs it reads back are the new run's own. The world here has exactly
those: a controller with latency and jitter reading its own output.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine import skeleton
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.timeline import Phase
from amsa_phys.model.world import load_world

WORLD = """
components:
  C: {template: "toys:Ctl", freq: 10, latency: 0.05, jitter: 0.2, inputs: {x: C.u}}
  A: {template: "toys:Act", freq: 20, inputs: {u: C.u}}
"""

FREE = """
timing: {free_running: true, resolution: 0.01}
components:
  C: {template: "toys:Ctl", freq: 10, latency: 0.05, jitter: 0.2, inputs: {x: C.u}}
  A: {template: "toys:Act", freq: 20, inputs: {u: C.u}}
"""


@pytest.fixture
def world(tmp_path: Path) -> Any:
    path = tmp_path / "w.yaml"
    path.write_text(WORLD)
    return load_world(path)


@pytest.fixture
def compiled(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The paths whose task was compiled afresh (``make_task`` calls), in order."""
    calls: list[str] = []
    fresh = skeleton.make_task
    monkeypatch.setattr(
        skeleton,
        "make_task",
        lambda w, path, *a, **k: calls.append(path) or fresh(w, path, *a, **k),
    )
    skeleton.forget()
    yield calls
    skeleton.forget()


def run(
    world: Any, seed: int, duration: Fraction = Fraction(3), phases: Any = ()
) -> tuple[Simulation, bytes]:
    """A whole run and its trace (every buffer at 100 Hz: a delivery's tick shows)."""
    rows: list[bytes] = []
    sim = Simulation(
        world,
        seed=seed,
        duration=duration,
        phases=phases,
        log_rate=Fraction(100),
        trace=lambda t, row: rows.append(np.asarray([t, *row], dtype=np.float64).tobytes()),
    )
    sim.run()
    return sim, b"".join(rows)


def fields(task: Any) -> dict[str, Any]:
    """A task's fields as comparable values (its delay line by its settings)."""
    out = {k: v for k, v in vars(task).items() if k not in ("comp", "delay")}
    line = task.delay
    out["delay"] = None if line is None else (line.fixed, line.latency, line.jitter, line.tick)
    out["comp"] = type(task.comp)
    return out


def test_a_kept_skeleton_gives_the_tasks_and_trace_of_a_fresh_compilation(
    world: Any, compiled: list[str]
) -> None:
    first, _ = run(world, 1)
    assert compiled == ["C", "A"]
    kept, kept_trace = run(world, 2)
    assert compiled == ["C", "A"], "the second run of the structure compiled its tasks again"
    skeleton.forget()
    fresh, fresh_trace = run(world, 2)
    assert compiled == ["C", "A", "C", "A"]
    assert [fields(t) for t in kept._tasks] == [fields(t) for t in fresh._tasks]
    assert kept.grid.tick == fresh.grid.tick
    assert kept.timer_phases == fresh.timer_phases
    assert kept_trace == fresh_trace
    # each run its own components, delay line and record of its own outputs
    for a, b in zip(first._tasks, kept._tasks, strict=True):
        assert a.comp is not b.comp
        assert a.own is not b.own
        assert a.delay is None or a.delay is not b.delay


def test_a_reused_run_after_another_seed_is_the_fresh_run(world: Any, compiled: list[str]) -> None:
    """Seeds in turn through one skeleton: each run's trace is the fresh run's."""
    seeds = [4, 9, 4, 2**31 - 2]
    reused = [run(world, s)[1] for s in seeds]
    assert compiled == ["C", "A"]
    fresh = []
    for s in seeds:
        skeleton.forget()
        fresh.append(run(world, s)[1])
    assert reused == fresh
    assert len(set(reused)) == 3  # the jitter drawn per seed shows in the trace


def test_another_duration_or_log_rate_is_compiled_afresh(world: Any, compiled: list[str]) -> None:
    run(world, 1)
    run(world, 1, Fraction(2))
    assert compiled == ["C", "A", "C", "A"]
    Simulation(world, seed=1, duration=Fraction(2), log_rate=Fraction(7)).initialize()
    assert compiled == ["C", "A"] * 3


def test_another_timeline_is_compiled_afresh(world: Any, compiled: list[str]) -> None:
    """A phase starting at 1/7 s puts the run on a finer grid than the kept one's."""
    run(world, 1)
    phases = [Phase(Fraction(0), []), Phase(Fraction(1, 7), [])]
    sim, trace = run(world, 1, phases=phases)
    assert compiled == ["C", "A", "C", "A"]
    skeleton.forget()
    fresh, fresh_trace = run(world, 1, phases=phases)
    assert sim.grid.tick == fresh.grid.tick == Fraction(1, 700)
    assert trace == fresh_trace


def test_other_hook_rates_are_compiled_afresh(world: Any, compiled: list[str]) -> None:
    run(world, 1)
    sim = Simulation(world, seed=1, duration=Fraction(3), log_rate=Fraction(100))
    sim.add_hook(Fraction(30), lambda: None, "probe")
    sim.initialize()
    assert compiled == ["C", "A", "C", "A"]
    assert sim.grid.tick == Fraction(1, 300)


def test_timer_phases_drawn_per_seed_are_never_kept(tmp_path: Path, compiled: list[str]) -> None:
    path = tmp_path / "free.yaml"
    path.write_text(FREE)
    world = load_world(path)
    runs = [run(world, s)[0] for s in (1, 2)]
    assert compiled == ["C", "A"] * 2
    assert runs[0].timer_phases != runs[1].timer_phases  # the seeds drew other phases
    assert skeleton.kept(runs[1]) is None


def test_the_kept_skeletons_are_bounded(tmp_path: Path, compiled: list[str]) -> None:
    for k in range(skeleton.MAX_KEPT + 3):
        path = tmp_path / f"w{k}.yaml"
        path.write_text(WORLD)
        run(load_world(path), 1, Fraction(1))
    assert len(skeleton._kept) == skeleton.MAX_KEPT
