"""Loop timing: latency, jitter and timer phases (model/timing.py, engine/timing.py)."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import toys

from amsa_phys.engine.rng import component_rng, named_rng
from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import ConfigError
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.world import load_world


def world(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "w.yaml"
    path.write_text(text)
    return path


@pytest.fixture(autouse=True)
def _clear_log() -> None:
    toys.LOG.clear()


def seen(path: str, port: str = "a") -> list[tuple[Fraction, float]]:
    return [(t, inp[port]) for p, t, inp in toys.LOG if p == path]


def steps(path: str) -> list[Fraction]:
    return [t for p, t, _ in toys.LOG if p == path]


def test_latency_delays_what_readers_see_not_when_the_producer_runs(tmp_path: Path) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  Src: {template: "toys:Source", freq: 1, latency: 0.3}
  S: {template: "toys:Sink", freq: 4, inputs: {a: Src.count, b: Src.count}}
""",
        )
    )
    Simulation(w, duration=Fraction(2)).run()
    assert steps("Src") == [0, 1, 2]
    got = dict(seen("S"))
    # published at 0 (count 1), visible from 0.3: the reader at 4 Hz first sees it at 0.5,
    # and at 1 s it still sees 1 (count 2, published at 1 s, arrives at 1.3 s)
    assert [got[Fraction(k, 4)] for k in range(8)] == [-1, -1, 1, 1, 1, 1, 2, 2]


def test_a_delayed_output_is_never_seen_in_the_instant_it_is_published(tmp_path: Path) -> None:
    text = """
components:
  Src: {template: "toys:Source", freq: 1%s}
  R: {template: "toys:Relay", freq: 1, inputs: {x: Src.count}}
"""
    Simulation(load_world(world(tmp_path, text % "")), duration=Fraction(1)).run()
    assert seen("R", "x") == [(0, 1.0), (1, 2.0)]  # producer before consumer, same instant
    toys.LOG.clear()
    # latency 0 with jitter: at least the next tick, however small the draw
    w = load_world(world(tmp_path, text % ", jitter: 0.000001"))
    Simulation(w, duration=Fraction(1)).run()
    assert seen("R", "x") == [(0, -1.0), (1, 1.0)]


def test_explicit_zero_latency_is_the_engine_without_timing(tmp_path: Path) -> None:
    base = """
components:
  Src: {template: "toys:Source", freq: 3%s}
  S: {template: "toys:Sink", freq: 7, inputs: {a: Src.count, b: Src.count}}
"""
    runs = []
    for extra in ("", ", latency: 0, jitter: 0, phase: 0"):
        toys.LOG.clear()
        w = load_world(world(tmp_path, base % extra))
        sim = Simulation(w, duration=Fraction(3))
        sim.run()
        assert all(t.delay is None for t in sim._tasks)
        runs.append(list(toys.LOG))
    assert runs[0] == runs[1]


def test_a_phase_shifts_a_leafs_instants(tmp_path: Path) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  Src: {template: "toys:Source", freq: 2, phase: 0.1}
  S: {template: "toys:Sink", freq: 10, inputs: {a: Src.count, b: Src.count}}
""",
        )
    )
    Simulation(w, duration=Fraction(2)).run()
    assert steps("Src") == [Fraction(1, 10), Fraction(6, 10), Fraction(11, 10), Fraction(16, 10)]
    got = dict(seen("S"))
    assert [got[Fraction(0)], got[Fraction(1, 10)]] == [-1.0, 1.0]  # same instant, dataflow


def test_free_running_phases_are_drawn_per_seed_on_the_resolution_grid(tmp_path: Path) -> None:
    path = world(
        tmp_path,
        """
timing: {free_running: true, resolution: 0.01}
components:
  A: {template: "toys:Source", freq: 4}
  B: {template: "toys:Source", freq: 4}
  C: {template: "toys:Source", freq: 4, phase: 0}
""",
    )
    drawn = {}
    for seed in (1, 2):
        for _ in range(2):  # the same seed draws the same phases
            toys.LOG.clear()
            sim = Simulation(load_world(path), seed=seed, duration=Fraction(1))
            sim.run()
            phases = {p: steps(p)[0] for p in "ABC"}
            assert drawn.setdefault(seed, phases) == phases
        assert phases["C"] == 0  # an explicit phase is kept
        for p in "AB":
            assert 0 <= phases[p] < Fraction(1, 4)
            assert (phases[p] / Fraction(1, 100)).denominator == 1
            due = [phases[p] + Fraction(k, 4) for k in range(5)]
            assert steps(p) == [t for t in due if t <= 1]
    assert drawn[1] != drawn[2]
    assert drawn[1]["A"] != drawn[1]["B"]


def test_jitter_delays_within_bounds_and_keeps_messages_in_order(tmp_path: Path) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  Src: {template: "toys:Source", freq: 10, latency: 0.05, jitter: 0.3}
  S: {template: "toys:Sink", freq: 100, inputs: {a: Src.count, b: Src.count}}
""",
        )
    )
    Simulation(w, seed=4, duration=Fraction(20)).run()
    got = seen("S")
    values = [v for _, v in got]
    assert values == sorted(values)  # FIFO: a later message never shows before an earlier one
    first_seen = {}
    for t, v in got:
        first_seen.setdefault(v, t)
    delays = np.array([float(t - Fraction(int(v) - 1, 10)) for v, t in first_seen.items() if v > 0])
    # published at (k-1)/10, seen at the first 100 Hz instant at or after 0.05 + u 0.3 (and
    # not before the previous message): delays in [0.05, 0.35 + 0.01], spread over the range
    assert delays.min() >= 0.05 - 1e-12
    assert delays.max() <= 0.36 + 1e-12
    assert delays.std() > 0.05
    assert len(first_seen) > 150  # most of the 200 messages seen (none lost, some overtaken)


def test_timing_streams_are_not_any_components_own() -> None:
    """Adding jitter or a random phase must not change a sensor's noise: the timing streams
    are keyed apart from the component's stream and every child it spawns."""
    own = component_rng(7, "FollowerGPS")
    children = [g.random(4) for g in own.spawn(8)]
    for name in ("phase", "jitter"):
        timing = named_rng(7, "FollowerGPS", name).random(4)
        assert not any(np.array_equal(timing, c) for c in children)
        assert not np.array_equal(timing, component_rng(7, "FollowerGPS").random(4))
    assert not np.array_equal(
        named_rng(7, "FollowerGPS", "phase").random(4),
        named_rng(7, "FollowerGPS", "jitter").random(4),
    )


def test_jitter_elsewhere_leaves_a_sensors_noise_unchanged() -> None:
    root = Path(__file__).resolve().parents[2]
    cols = ["LeaderGPS.gpsPosX", "FollowerCompass.compassHeading"]
    traces = []
    for extra in ([], ["MyDistanceMonitor.jitter=0.2", "MyNormalizePower.phase=random"]):
        sc = load_scenario(root / "scenarios" / "paper_fig6.yaml", overrides=extra, duration=20)
        rows: list[list[float]] = []
        sim = Simulation.from_scenario(sc, trace=lambda t, r, rows=rows: rows.append(list(r)))
        sim.run()
        idx = [sim.columns.index(c) for c in cols]
        traces.append([[r[i] for i in idx] for r in rows])
    # the leader does not depend on the follower: its GPS fixes are the same numbers; the
    # compass reads the follower, whose path the timing changed, so compare its noise only
    # through the leader's fixes
    assert [r[0] for r in traces[0]] == [r[0] for r in traces[1]]


@pytest.mark.parametrize(
    ("body", "key", "message"),
    [
        ("latency: -0.1", "latency", "a latency must be >= 0, got -0.1"),
        ("latency: 61", "latency", "a latency must be <= 60 s, got 61"),
        ("jitter: soon", "jitter", "expected a jitter in seconds, got 'soon'"),
        ("phase: 0.5", "phase", "a phase must be below the period (1/2 Hz = 0.5 s), got 0.5"),
        ("phase: [1]", "phase", "expected a number or a string, got list [1]"),
    ],
)
def test_bad_timing_is_one_line_naming_file_line_and_key(
    tmp_path: Path, body: str, key: str, message: str
) -> None:
    path = world(tmp_path, f'components:\n  Src: {{template: "toys:Source", freq: 2, {body}}}\n')
    with pytest.raises(ConfigError) as err:
        load_world(path)
    text = str(err.value)
    assert text == f"{path}:2: components.Src.{key}: {message}"


def test_timing_holds_for_the_whole_run_set_not_timeline(tmp_path: Path) -> None:
    w = world(tmp_path, 'components:\n  Src: {template: "toys:Source", freq: 2}\n')
    sc = tmp_path / "s.yaml"
    sc.write_text(
        f"world: {w}\nduration: 4\nset: {{Src.latency: 0.25, Src.phase: '1/3'}}\n"
        "timeline:\n  - {at: 1, set: {Src.jitter: 0.1}}\n"
    )
    with pytest.raises(ConfigError) as err:
        load_scenario(sc)
    assert str(err.value) == (
        f"{sc}:5: timeline[0].set.Src.jitter: a Leaf's jitter holds for the whole run: "
        "set it in set:, not in the timeline"
    )
    sc.write_text(f"world: {w}\nduration: 4\nset: {{Src.latency: 0.25, Src.phase: '1/3'}}\n")
    s = load_scenario(sc, overrides=["Src.jitter=0.1"])
    t = s.world.leaves["Src"].timing
    assert (t.latency, t.jitter, t.phase) == (Fraction(1, 4), Fraction(1, 10), Fraction(1, 3))
    with pytest.raises(ConfigError) as err:
        load_scenario(sc, overrides=["Src.freq=4"])
    assert "phase 1/3 s is not below the period of 4 Hz (0.25 s)" in str(err.value)
