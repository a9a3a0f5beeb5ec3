"""The buffer store (engine/store.py) and the Simulation's public read API, lock, instant
sources and construction hook."""

from __future__ import annotations

import threading
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import toys

from amsa_phys.engine.runner import Simulation
from amsa_phys.engine.store import BufferStore
from amsa_phys.model.scenario import Change, Phase
from amsa_phys.model.world import load_world


@pytest.fixture(autouse=True)
def _clear_log() -> None:
    toys.LOG.clear()


def _world(tmp_path: Path, text: str) -> Any:
    path = tmp_path / "w.yaml"
    path.write_text(text)
    return load_world(path)


SCAN = """
components:
  S: {template: "toys:Scanner", freq: 10, params: {n: 4}}
  Sum: {template: "toys:Summer", freq: 10, inputs: {vals: S.vals}}
"""

RELAY = """
components:
  A: {template: "toys:Source", freq: 10}
  R: {template: "toys:Relay", freq: 10, inputs: {x: A.count}}
"""


def test_store_indexes_buffers_in_world_order_and_arrays_as_slices(tmp_path: Path) -> None:
    w = _world(tmp_path, SCAN)
    store = BufferStore({n: b.initial for n, b in w.buffers.items()}, w.arrays)
    assert store.names == list(w.buffers)
    assert [store.index[n] for n in store.names] == list(range(len(store)))
    for i in range(4):
        store.write(f"S.vals[{i}]", 10 + i)
    row = store.row()
    assert row.dtype == np.float64
    assert list(row[store.slice("S.vals")]) == [10.0, 11.0, 12.0, 13.0]
    assert list(store.array("S.vals")) == [10.0, 11.0, 12.0, 13.0]
    assert store.elements("S.vals") == tuple(f"S.vals[{i}]" for i in range(4))
    with pytest.raises(KeyError):
        store.write("S.nope", 1.0)  # an outside writer cannot invent a buffer


def test_read_api_sees_what_the_run_published(tmp_path: Path) -> None:
    sim = Simulation(_world(tmp_path, RELAY), duration=Fraction(1))
    assert sim.read("A.count") == -1.0  # the port's initial value before the run
    sim.run()
    assert sim.read("A.count") == 11.0  # 11 steps at 10 Hz over [0, 1]
    assert list(sim.read_many(["R.y", "A.count"])) == [11.0, 11.0]  # R runs after A


def test_an_outside_write_waits_for_the_instant_to_end(tmp_path: Path) -> None:
    slow = RELAY.replace(
        'A: {template: "toys:Source", freq: 10}', 'A: {template: "toys:Source", freq: 5}'
    )
    sim = Simulation(_world(tmp_path, slow), duration=Fraction(1))
    free: list[bool] = []

    def probe() -> None:  # what another thread (a rospy callback) finds
        lock = sim.store.lock
        got = lock.acquire(blocking=False)
        if got:
            lock.release()
        free.append(got)

    class Probe(toys.Source):
        def do_step(self, t: Fraction, inp: Any) -> Any:
            th = threading.Thread(target=probe)
            th.start()
            th.join()
            return super().do_step(t, inp)

    sim.components["A"].__class__ = Probe
    sim.initialize()
    sim.advance(0)  # t = 0: A (which probes), then R
    assert free == [False]  # inside an instant: locked out
    probe()
    assert free[-1]  # between advance calls: free
    sim.write("A.count", 99.0)
    sim.advance(sim.grid.ticks(Fraction(1, 10)))  # R alone (A runs at 5 Hz)
    assert toys.LOG[-1] == ("R", Fraction(1, 10), {"x": 99.0})  # it read the outside value


class AtTick:
    """An instant source: ``changes`` at tick ``tick`` (an adaptation rule's shape)."""

    def __init__(self, tick: int, changes: list[Change]) -> None:
        self.tick, self.changes = tick, changes

    def next_tick(self) -> float:
        return self.tick if self.changes else float("inf")

    def due(self, tick: int) -> list[tuple[int, int | None, list[Change]]]:
        out, self.changes = [(self.tick, None, self.changes)], []
        return out


def test_an_instant_source_lands_like_a_timeline_change_after_the_timelines(
    tmp_path: Path,
) -> None:
    w = _world(tmp_path, RELAY)
    timeline = [Phase(Fraction(0), []), Phase(Fraction(1, 2), [Change("A", "gain", 2.0)])]
    sim = Simulation(w, duration=Fraction(1), phases=timeline)
    sim.initialize()
    at = sim.grid.ticks(Fraction(1, 2))
    sim.add_instant_source(AtTick(at, [Change("A", "gain", 3.0)]))
    sim.run()
    half = Fraction(1, 2)
    assert [(t, c.value) for t, c in sim.change_log] == [(half, 2.0), (half, 3.0)]
    assert sim.phase_index == 1  # the source stays in the timeline's phase
    counts = {t: inp for p, t, inp in toys.LOG if p == "R"}
    # A publishes 6 * 3 at t = 0.5 (R runs after it): the instant saw the rule's value
    assert counts[Fraction(1, 2)] == {"x": 18.0}


def test_the_construction_hook_wraps_components_before_initialize(tmp_path: Path) -> None:
    seen: list[str] = []

    class Twice:
        def __init__(self, comp: Any) -> None:
            self.comp, self.p = comp, comp.p

        def initialize(self, ctx: Any) -> None:
            self.comp.initialize(ctx)

        def do_step(self, t: Fraction, inp: Any) -> Any:
            out = self.comp.do_step(t, inp)
            return {k: 2 * v for k, v in out.items()}

    def wrap(path: str, comp: Any) -> Any:
        seen.append(path)
        return Twice(comp) if path == "A" else comp

    sim = Simulation(_world(tmp_path, RELAY), duration=Fraction(1), wrap=wrap)
    assert seen == ["A", "R"]
    sim.run()
    assert sim.read("A.count") == 22.0


COPIES = """
components:
  A: {template: "toys:Source", freq: 10}
  Car:
    count: 40
    components:
      D: {template: "toys:Divider", freq: 10, inputs: {x: A.count},
          params: {k: {from: 1, step: 0.2}}}
"""


def test_grouping_is_an_argument_and_gives_the_same_values(tmp_path: Path) -> None:
    from amsa_phys.engine import batch

    w = _world(tmp_path, COPIES)
    grouped = Simulation(w, duration=Fraction(1))
    single = Simulation(w, duration=Fraction(1), grouping=False)
    for sim in (grouped, single):
        sim.run()
    assert grouped._groups_of
    assert not single._groups_of
    names = [f"Car{i}.D.y" for i in range(1, 41)]
    assert np.allclose(grouped.read_many(names), single.read_many(names), rtol=1e-12)
    assert grouped.read("Car3.D.y") == pytest.approx(1 / (11 * 1.4))
    assert not hasattr(batch, "ENABLED")  # grouping is an argument, no module switch
