"""The physics steps a single run takes in batches (``PhysicsWorld.step_many``, issue 29)
against the same run stepped one physics step at a time.

Between two instants where anything else is due, the engine hands the physics a whole run
of steps in one C call. Everything a user sees must be what the step-by-step loop gives:
the trace row for row, the collision events with their times (a collision callback runs
inside a batch and must find its own step's time), and a safety fault's time and message.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from amsa_phys.engine.runner import Simulation
from amsa_phys.errors import RunFault
from amsa_phys.model.scenario import Change, Scenario, load_scenario
from amsa_phys.physics import compiled
from amsa_phys.physics.space import PhysicsWorld

SCENARIO1 = Path(__file__).resolve().parents[2] / "scenarios" / "scenario1.yaml"

pytestmark = pytest.mark.skipif(not compiled.active(), reason="the batched step is the C step's")


def _ramming(duration: float = 55) -> Scenario:
    """Scenario1 with the follower driving into a leader that wanders: contacts that begin
    and end inside runs of physics-only instants (at 9.42 s and 35.41 s), and the
    controller's delayed outputs arriving inside them too (0.48 s: 48 ticks after a 4 Hz
    instant), where a batch must stop."""
    sets = [
        "MyFollowerController.distanceRef=0",
        "MyFollowerController.latency=0.48",  # its outputs land between log instants
        "Leader.behavior=4",
    ]
    return load_scenario(SCENARIO1, sets, duration=duration)


def _run(scenario: Scenario, batched: bool, monkeypatch: pytest.MonkeyPatch) -> dict:
    """Everything a user sees of a run: trace rows, events, collisions, the end (or fault)."""
    # the step each contact ended at, as each ended; kept with the world that said it: a world
    # of an earlier run, freed by the garbage collector during this one, reports its own
    # contacts' ends then (pymunk calls separate as a Space goes), which are not this run's
    separations: list[tuple[PhysicsWorld, dict]] = []
    separate = PhysicsWorld._on_separate

    def recording(self: PhysicsWorld, *args) -> None:  # type: ignore[no-untyped-def]
        separate(self, *args)
        separations.append((self, dict(self._apart_since)))

    with monkeypatch.context() as m:
        m.setattr(PhysicsWorld, "_on_separate", recording)
        if not batched:
            m.setattr(Simulation, "batch_hook", lambda self, fn, many: None)
        rows: list[tuple[float, ...]] = []
        sim = Simulation.from_scenario(scenario, trace=lambda t, r: rows.append((t, *r)))
        fault = None
        try:
            sim.run()
        except RunFault as exc:
            fault = str(exc)
        physics = sim.shared["physics"]
        return {
            "rows": rows,
            "events": [(e.t, e.kind, e.detail) for e in sim.events],
            "collisions": physics.collisions,
            "steps": physics._steps,
            "separations": [apart for world, apart in separations if world is physics],
            "fault": fault,
            "now": sim.now,
        }


def test_batches_are_taken(monkeypatch: pytest.MonkeyPatch) -> None:
    """The batched path runs at all (else the equality below proves nothing)."""
    taken = []
    original = PhysicsWorld.step_many

    def counting(self: PhysicsWorld, count: int, seek) -> int:  # type: ignore[no-untyped-def]
        done = original(self, count, seek)
        taken.append(done)
        return done

    monkeypatch.setattr(PhysicsWorld, "step_many", counting)
    sim = Simulation.from_scenario(load_scenario(SCENARIO1, duration=5))
    sim.run()
    assert sum(taken) > 300  # of 500 steps, all but those at the 20 Hz log instants


def test_collisions_inside_batches_keep_their_steps(monkeypatch: pytest.MonkeyPatch) -> None:
    """Contacts beginning and ending inside batches: the same trace, events and times."""
    batched = _run(_ramming(), True, monkeypatch)
    alone = _run(_ramming(), False, monkeypatch)
    times = [t for t, kind, _ in batched["events"] if kind == "collision"]
    assert len(times) >= 2, "the scenario no longer collides inside batches"
    assert any(round(t * 20) != t * 20 for t in times), "no collision off a log instant"
    assert batched == alone


def test_a_fault_inside_a_batch_names_its_step(monkeypatch: pytest.MonkeyPatch) -> None:
    """A rover too fast for the world's limit, caught inside a batch: the same fault, at
    the same time, and the run stops at the same instant."""
    scenario = load_scenario(SCENARIO1, duration=20)
    world = dataclasses.replace(
        scenario.world, physics={**scenario.world.physics, "max_speed": 0.2512}
    )
    scenario = dataclasses.replace(scenario, world=world)
    batched = _run(scenario, True, monkeypatch)
    alone = _run(scenario, False, monkeypatch)
    assert batched["fault"] is not None
    assert "exceeds physics.max_speed" in batched["fault"]
    assert round(batched["now"] * 20) != batched["now"] * 20, "not inside a batch"
    assert batched == alone


def test_advancing_in_pieces_stops_where_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    """``advance(until)`` ending inside a run of physics-only instants (the ROS simulator,
    the window): a batch never steps past ``until``, and the physics state read there is
    the step-by-step run's."""
    ticks = [1, 3, 5, 6, 9, 12, 24, 25, 27, 44, 45, 47, 48, 50, 51, 77, 98, 130, 149, 400]

    def pieces(batched: bool) -> list:
        with monkeypatch.context() as m:
            if not batched:
                m.setattr(Simulation, "batch_hook", lambda self, fn, many: None)
            sim = Simulation.from_scenario(load_scenario(SCENARIO1, duration=5))
            sim.initialize()
            seen = []
            for tick in ticks:
                sim.advance(tick)
                state = list(sim.shared["physics"]._model.state)
                seen.append((tick, sim.now, sim._cursor, state))
            return seen

    assert pieces(True) == pieces(False)


class _Wear:
    """An instant source (``engine/instants.py``) that weakens the follower's motors at
    ticks between log instants: the physics must take the change at its own step."""

    def __init__(self, ticks: list[int]) -> None:
        self._ticks = ticks

    def next_tick(self) -> float:
        return self._ticks[0] if self._ticks else math.inf

    def due(self, tick: int) -> list:
        out = []
        while self._ticks and self._ticks[0] <= tick:
            at = self._ticks.pop(0)
            out.append((at, None, [Change("Follower", "stallForce", 8.5 - at / 100)]))
        return out


def test_changes_between_log_instants_land_at_their_step(monkeypatch: pytest.MonkeyPatch) -> None:
    """A parameter change due inside a run of physics-only instants stops the batch there:
    the same trace as step by step."""

    def trace(batched: bool) -> list:
        with monkeypatch.context() as m:
            if not batched:
                m.setattr(Simulation, "batch_hook", lambda self, fn, many: None)
            rows: list = []
            scenario = load_scenario(SCENARIO1, duration=10)
            sim = Simulation.from_scenario(scenario, trace=lambda t, r: rows.append((t, *r)))
            sim.add_instant_source(_Wear([102, 213, 347, 411, 598]))
            sim.run()
            return rows

    assert trace(True) == trace(False)
