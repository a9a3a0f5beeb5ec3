"""A run laid out by a kept layout is the run a fresh compilation gives (engine/layout.py).

The layout of a structure's cycle is kept from one Simulation to the next (a Gymnasium
reset builds one per episode). What a user sees must not depend on whether it was kept:
the table the hot loop walks, the groups, and the trace, byte for byte; and a run whose
structure differs (timer phases drawn per seed, other groups) must be laid out afresh.
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine import batch, layout, schedule
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.world import load_world

ROOT = Path(__file__).resolve().parent.parent.parent

FREE = """
timing: {free_running: true, resolution: 0.01}
components:
  A: {template: "toys:Source", freq: 4}
  B: {template: "toys:Source", freq: 4}
  C: {template: "toys:Source", freq: 4, phase: 0}
"""


def name(fn: Any) -> str:
    return getattr(fn, "__qualname__", type(fn).__name__)


def item(x: Any) -> Any:
    if isinstance(x, batch.Group):
        return ("group", tuple(batch.ident(t) for t in x.tasks))
    return batch.ident(x)


def table(sim: Simulation) -> list[Any]:
    """The compiled table as comparable values: offsets, what steps how, log, hooks."""
    rows = []
    for off, tasks, log, hooks, last, spacing, merge in sim._plan:
        steps = [(name(step), item(x)) for step, x in tasks]
        hook_names = [name(h) for h in hooks]
        rows.append((off, steps, log, hook_names, last, spacing, merge and merge[:2]))
    groups = {k: [item(g) for g in v] for k, v in sim._groups_of.items()}
    return [sim._cycle, rows, groups]


def scenario1(seed: int) -> Simulation:
    sc = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=20)
    return Simulation.from_scenario(dataclasses.replace(sc, seed=seed), trace=Rows(sc))


def platoon(seed: int) -> Simulation:
    sc = load_scenario(ROOT / "scenarios" / "platoon.yaml", duration=10)
    sc = dataclasses.replace(sc, seed=seed)
    # groups of the ten cars' copies (by default only from 32 copies on)
    return Simulation.from_scenario(sc, trace=Rows(sc), grouping=batch.Grouping(min_group=2))


class Rows:
    """A trace callback keeping every row (and, for the test, the latest one made)."""

    made: Rows | None = None

    def __init__(self, _scenario: Any) -> None:
        self.rows: list[tuple[float, bytes]] = []
        Rows.made = self

    def __call__(self, t: float, row: list[float]) -> None:
        self.rows.append((t, np.asarray(row, dtype=np.float64).tobytes()))


@pytest.mark.parametrize("make", [scenario1, platoon], ids=["scenario1", "platoon-grouped"])
def test_a_kept_layout_gives_the_table_and_trace_of_a_fresh_one(
    make: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = []
    fresh_instants = schedule.instants
    monkeypatch.setattr(
        schedule, "instants", lambda *a, **k: calls.append(1) or fresh_instants(*a, **k)
    )
    layout.forget()
    make(1).initialize()  # lays out afresh and keeps the layout
    assert len(calls) == 1
    kept_sim = make(2)
    kept_trace = Rows.made
    kept_sim.initialize()
    assert len(calls) == 1, "the second run of the structure was laid out again"
    layout.forget()
    fresh_sim = make(2)
    fresh_trace = Rows.made
    fresh_sim.initialize()
    assert len(calls) == 2
    assert table(kept_sim) == table(fresh_sim)
    if make is platoon:  # the grouped path is the one exercised
        assert any(isinstance(x, batch.Group) for _, xs, *_ in kept_sim._plan for _, x in xs)
    kept_sim.run()
    fresh_sim.run()
    assert kept_trace is not None
    assert fresh_trace is not None
    assert kept_trace.rows
    assert kept_trace.rows == fresh_trace.rows


def test_phases_drawn_per_seed_are_laid_out_afresh(tmp_path: Path) -> None:
    path = tmp_path / "w.yaml"
    path.write_text(FREE)
    world = load_world(path)
    layout.forget()
    first = Simulation(world, seed=1, duration=Fraction(1))
    first.initialize()
    other = Simulation(world, seed=2, duration=Fraction(1))
    other.initialize()
    layout.forget()
    fresh = Simulation(world, seed=2, duration=Fraction(1))
    fresh.initialize()
    assert table(first) != table(fresh)  # the seeds draw other phases
    assert table(other) == table(fresh)


def test_the_kept_layouts_are_bounded(tmp_path: Path) -> None:
    path = tmp_path / "w.yaml"
    path.write_text(FREE)
    world = load_world(path)
    layout.forget()
    for seed in range(3 * layout.MAX_LAYOUTS):  # most seeds draw other phases
        Simulation(world, seed=seed, duration=Fraction(1)).initialize()
    assert len(layout._kept) == layout.MAX_LAYOUTS
