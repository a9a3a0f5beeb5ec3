"""The engine: exact rates, dataflow order, buffers, run-to-completion, loops, timeline."""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path

import pytest
import toys

from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import ConfigError, RunFault
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.world import load_world


def world(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "w.yaml"
    path.write_text(text)
    return path


@pytest.fixture(autouse=True)
def _clear_log() -> None:
    toys.LOG.clear()


def steps(path: str) -> list[Fraction]:
    return [t for p, t, _ in toys.LOG if p == path]


def test_rates_3_and_7_hz_are_exact_over_a_long_run(tmp_path: Path) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  A: {template: "toys:Source", freq: 3}
  B: {template: "toys:Source", freq: 7}
  C: {template: "toys:Source", freq: 0.1}
""",
        )
    )
    sim = Simulation(w, duration=Fraction(50000), log_rate=Fraction(1, 10))
    sim.run()
    a, b, c = steps("A"), steps("B"), steps("C")
    assert sim.grid.tick == Fraction(1, 21)
    assert sim.grid.ticks(Fraction(50000)) == 1_050_000  # over 10^6 ticks
    # both ends included: 3 * 50000 + 1 steps, every one exactly k/3 s, no drift
    assert len(a) == 150_001
    assert len(b) == 350_001
    assert len(c) == 5001
    assert a == [Fraction(k, 3) for k in range(150_001)]
    assert b[-1] == Fraction(50000)
    assert b[7 * 41234] == Fraction(41234)


def test_same_instant_order_follows_dataflow_not_declaration(tmp_path: Path) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  S: {template: "toys:Sink", freq: 1, inputs: {a: R.y, b: Src.count}}
  R: {template: "toys:Relay", freq: 1, inputs: {x: Src.count}}
  Src: {template: "toys:Source", freq: 1}
""",
        )
    )
    assert w.order == ["Src", "R", "S"]
    Simulation(w, duration=Fraction(2)).run()
    first = [p for p, t, _ in toys.LOG if t == 0]
    assert first == ["Src", "R", "S"]
    # run-to-completion with the producer first: the consumer sees this instant's value
    assert [inp for p, t, inp in toys.LOG if p == "S" and t == 1] == [{"a": 2.0, "b": 2.0}]


def test_writes_overwrite_and_reads_do_not_consume(tmp_path: Path) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  Src: {template: "toys:Source", freq: 1}
  S: {template: "toys:Sink", freq: 4, inputs: {a: Src.count, b: Src.count}}
""",
        )
    )
    Simulation(w, duration=Fraction(2)).run()
    seen = [inp["a"] for p, t, inp in toys.LOG if p == "S"]
    # four reads per producer write, all the same value; then the next write replaces it
    assert seen == [1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0, 3.0]


def test_unwritten_buffer_holds_declared_initial_and_silent_producer_keeps_old(
    tmp_path: Path,
) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  Src: {template: "toys:Source", freq: 1, params: {silent: true}}
  R: {template: "toys:Relay", freq: 1, inputs: {x: Src.count}}
""",
        )
    )
    Simulation(w, duration=Fraction(1)).run()
    assert [inp["x"] for p, _, inp in toys.LOG if p == "R"] == [-1.0, -1.0]


def test_consumer_ordered_first_sees_previous_value(tmp_path: Path) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  Src: {template: "toys:Source", freq: 1}
  R: {template: "toys:Relay", freq: 1, inputs: {x: Src.count}}
schedule: [R, Src]
""",
        )
    )
    assert w.order == ["R", "Src"]
    Simulation(w, duration=Fraction(2)).run()
    assert [inp["x"] for p, _, inp in toys.LOG if p == "R"] == [-1.0, 1.0, 2.0]


LOOP = """
components:
  P: {template: "toys:Plant", freq: 2, inputs: {v: A.v}}
  Sn: {template: "toys:Relay", freq: 2, inputs: {x: P.x}}
  C: {template: "toys:Ctl", freq: 2, inputs: {x: Sn.y}}
  A: {template: "toys:Act", freq: 2, inputs: {u: C.u}}
"""


def test_loop_is_refused_with_the_cycle_named(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=re.escape("dataflow loop P -> Sn -> C -> A -> P")):
        load_world(world(tmp_path, LOOP))


def test_loop_is_accepted_with_schedule(tmp_path: Path) -> None:
    w = load_world(world(tmp_path, LOOP + "schedule: [P, A]\n"))
    assert w.order == ["P", "Sn", "C", "A"]
    Simulation(w, duration=Fraction(1)).run()
    # the plant sees at t = 0.5 what the actuator published at t = 0 (0 -> +1 in C)
    assert [inp["v"] for p, _, inp in toys.LOG if p == "P"] == [0.0, 1.0, 2.0]


def test_forbidden_link_is_refused_naming_the_link(tmp_path: Path) -> None:
    path = world(
        tmp_path,
        """
components:
  Src: {template: "toys:Source", freq: 1}
  Sn: {template: "toys:Relay", freq: 1, inputs: {x: Src.count}}
  P: {template: "toys:Plant", freq: 1, inputs: {v: Sn.y}}
""",
    )
    with pytest.raises(ConfigError) as err:
        load_world(path)
    assert str(err.value) == (
        f"{path}:5: components.P.inputs.v: link Sn (sensor) -> P (process) is not allowed: "
        "a sensor may feed only controller, observer"
    )


def test_timeline_changes_apply_exactly_at_their_instant(tmp_path: Path) -> None:
    world(
        tmp_path,
        """
components:
  Src: {template: "toys:Source", freq: 4}
""",
    )
    scen = tmp_path / "s.yaml"
    scen.write_text("""
world: w.yaml
duration: 3
timeline:
  - {at: 1.25, set: {Src.gain: 10}}
  - {at: 2.3, set: {Src.gain: -1}}
""")
    sc = load_scenario(scen)
    sim = Simulation.from_scenario(sc)
    seen: list[tuple[float, float]] = []
    sim.initialize()
    for tick in range(sim.grid.ticks(Fraction(3)) + 1):
        sim.advance(tick)
        seen.append((float(sim.now), sim.values["Src.count"]))
    values = dict(seen)
    assert values[1.0] == 5.0  # 5th step at gain 1
    assert values[1.25] == 60.0  # 6th step already at gain 10: change before the step
    assert values[2.25] == 100.0
    assert values[2.5] == -11.0
    assert [float(at) for at, _ in sim.change_log] == [1.25, 2.3]


def test_nan_output_is_a_run_fault_naming_component_and_time(tmp_path: Path) -> None:
    w = load_world(world(tmp_path, "components:\n  B: {template: 'toys:Bad', freq: 4}\n"))
    message = "run fault at t=1.000 s in B (Bad): output u is nan"
    with pytest.raises(RunFault, match=re.escape(message)):
        Simulation(w, duration=Fraction(3)).run()


def test_exception_in_component_is_a_run_fault(tmp_path: Path) -> None:
    w = load_world(
        world(tmp_path, "components:\n  B: {template: 'toys:Bad', freq: 4, params: {boom: true}}\n")
    )
    with pytest.raises(RunFault, match=re.escape("in B (Bad): do_step raised ZeroDivisionError")):
        Simulation(w, duration=Fraction(3)).run()


def test_composites_nest_and_inputs_resolve_from_the_inside_out(tmp_path: Path) -> None:
    w = load_world(
        world(
            tmp_path,
            """
components:
  Src: {template: "toys:Source", freq: 1}
  Team:
    components:
      Src: {template: "toys:Source", freq: 1, params: {gain: 10}}
      R: {template: "toys:Relay", freq: 1, inputs: {x: Src.count}}
  Outer: {template: "toys:Relay", freq: 1, inputs: {x: Team.Src.count}}
""",
        )
    )
    assert list(w.leaves) == ["Src", "Team.Src", "Team.R", "Outer"]
    assert w.leaves["Team.R"].inputs == {"x": "Team.Src.count"}  # its sibling, not the root's
    assert w.leaves["Outer"].inputs == {"x": "Team.Src.count"}
    Simulation(w, duration=Fraction(0)).run()
    assert [inp for p, _, inp in toys.LOG if p == "Team.R"] == [{"x": 10.0}]


def test_an_instant_with_no_exact_decimal_replays_exactly(tmp_path: Path) -> None:
    """A live change at t = 7/3 (a 3 Hz instant) is written as "7/3", not 2.3333333333333335:
    the float would land just after the 3 Hz step at 7/3 and the replay would differ."""
    import yaml

    from amsa_phys.engine.tracefile import TraceWriter
    from amsa_phys.model.scenario import Change
    from amsa_phys.runs.resolve import resolved_scenario

    world(tmp_path, 'components:\n  Src: {template: "toys:Source", freq: 3}\n')
    scen = tmp_path / "s.yaml"
    scen.write_text("world: w.yaml\nduration: 4\n")

    sc = load_scenario(scen)
    first = TraceWriter(tmp_path / "a.csv", sc.world.buffers)
    live = Simulation.from_scenario(sc, trace=first.write)
    live.initialize()
    live.advance(live.grid.ticks(Fraction(7, 3)) - 1)
    assert live.apply_live(Change("Src", "gain", 10.0)) == Fraction(7, 3)
    live.run()
    resolved = resolved_scenario(sc, extra=live.live_changes, duration=Fraction(10, 3))
    assert resolved["timeline"][0]["at"] == "7/3"
    assert resolved["duration"] == "10/3"
    (tmp_path / "r.yaml").write_text(yaml.safe_dump({**resolved, "duration": 4}))
    again = TraceWriter(tmp_path / "b.csv", sc.world.buffers)
    Simulation.from_scenario(load_scenario(tmp_path / "r.yaml"), trace=again.write).run()
    assert again.close().read_bytes() == first.close().read_bytes()
    # decimals stay numbers
    assert resolved_scenario(sc, duration=Fraction(5, 2))["duration"] == 2.5
