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


# -- the column store: one float64 array, positions, columns, views (issue 29) ---------------
def test_a_batch_store_is_one_array_with_a_column_per_buffer_and_a_row_per_run(
    tmp_path: Path,
) -> None:
    w = _world(tmp_path, SCAN)
    store = BufferStore({n: b.initial for n, b in w.buffers.items()}, w.arrays, runs=3)
    names = store.names
    for run in range(3):
        for b, name in enumerate(names):
            assert store.at(name, run) == b * 3 + run  # a column's runs are consecutive
    store.write("S.vals[2]", 7.5, run=1)
    assert list(store.column("S.vals[2]")) == [0.0, 7.5, 0.0]  # that run only
    assert store.read("S.vals[2]", 1) == 7.5
    assert store.row(1)[store.index["S.vals[2]"]] == 7.5
    assert store.row(0)[store.index["S.vals[2]"]] == 0.0
    # the scalar view and the numpy view are one memory: no copy between them
    store.data[store.at("Sum.total", 2)] = 3.25
    assert store.col[store.at("Sum.total", 2)] == 3.25
    store.col[store.at("Sum.total", 0)] = -1.5
    assert store.data[store.at("Sum.total", 0)] == -1.5
    assert type(store.data[0]) is float  # the scalar path hands components Python floats
    assert store.table.shape == (len(names), 3)
    assert store.table.base is not None  # a view of the one array, not a copy
    with pytest.raises(IndexError):
        store.at("Sum.total", 3)
    with pytest.raises(KeyError):
        store.at("Sum.nope")


def test_the_named_view_reads_and_writes_the_array_and_invents_no_buffer(tmp_path: Path) -> None:
    w = _world(tmp_path, SCAN)
    store = BufferStore({n: b.initial for n, b in w.buffers.items()}, w.arrays)
    store.values["Sum.total"] = 4
    assert store.data[store.at("Sum.total")] == 4.0
    assert type(store.values["Sum.total"]) is float
    assert list(store.values) == store.names
    assert len(store.values) == len(store)
    assert "Sum.total" in store.values
    assert "Sum.nope" not in store.values
    with pytest.raises(KeyError):
        store.values["Sum.nope"] = 1.0
    with pytest.raises(KeyError):
        store.values["Sum.nope"]


def test_a_group_port_is_a_slice_when_evenly_spaced_and_an_index_otherwise() -> None:
    from amsa_phys.engine.batch import columns

    assert columns([4, 5, 6, 7]) == slice(4, 8, 1)  # one Leaf across a batch's runs
    assert columns([3, 10, 17]) == slice(3, 24, 7)  # copies of a Composite, one run
    assert columns([9]) == slice(9, 10, 1)
    irregular = columns([2, 10, 17])  # the first copy reads the leader's buffer
    assert isinstance(irregular, np.ndarray)
    assert list(irregular) == [2, 10, 17]
    backwards = columns([5, 4, 3])
    assert isinstance(backwards, np.ndarray)
    data = np.arange(30.0)
    for at in ([4, 5, 6, 7], [3, 10, 17], [2, 10, 17], [5, 4, 3]):
        assert list(data[columns(at)]) == [data[i] for i in at]


def test_groups_write_their_columns_in_place_and_give_the_leaf_by_leaf_values(
    tmp_path: Path,
) -> None:
    w = _world(tmp_path, COPIES)
    grouped = Simulation(w, duration=Fraction(1))
    single = Simulation(w, duration=Fraction(1), grouping=False)
    for sim in (grouped, single):
        sim.run()
    (group,) = {g for gs in grouped._groups_of.values() for g in gs}
    assert isinstance(group.outputs["y"], slice)  # the copies' outputs: one strided slice
    assert np.array_equal(grouped.store.col, single.store.col)  # every buffer, to the bit


BATCH_SCENARIO = """
world: w.yaml
duration: 1
seed: {seed}
set: {{Car2.D.k: {k}}}
timeline:
  - {{at: 0.5, set: {{A.gain: {gain}}}}}
"""


def _scenario(tmp_path: Path, seed: int, k: float, gain: float) -> Any:
    from amsa_phys.model.scenario import load_scenario

    (tmp_path / "w.yaml").write_text(COPIES.replace("count: 40", "count: 2"))
    path = tmp_path / f"s{seed}.yaml"
    path.write_text(BATCH_SCENARIO.format(seed=seed, k=k, gain=gain))
    return load_scenario(path)


def test_a_batch_of_runs_gives_each_run_its_single_runs_values(tmp_path: Path) -> None:
    """Runs on an integer axis: each run its own parameters and timeline, its own row in
    every column, the values of the run made alone; no buffer is renamed."""
    from amsa_phys.engine.multirun import MultiRun

    scenarios = [_scenario(tmp_path, s, k, g) for s, k, g in ((1, 1.0, 2.0), (2, 2.5, -1.0))]
    scenarios.append(scenarios[0])
    batch = MultiRun(scenarios)
    batch.run()
    assert batch.store.runs == 3
    assert set(batch.store.names) == set(scenarios[0].world.buffers)  # names as alone
    for run, sc in enumerate(scenarios):
        alone = Simulation.from_scenario(sc)
        alone.run()
        assert np.array_equal(batch.store.row(run), alone.store.row()), run
    # the Dividers of every run stepped as one group, their port one slice of the array
    groups = {g for gs in batch._groups_of.values() for g in gs}
    assert groups
    assert all(isinstance(g.inputs[0][1], slice) for g in groups)
    assert list(batch.column("A.count")) == [22.0, -11.0, 22.0]  # 11 steps, gain from 0.5 s
