"""A run that keeps no log (``Simulation(keep_log=False)``, what a Gymnasium episode without
a trace or a picture runs) is the same run: the same store, events and agent inputs at every
instant, bit for bit, with only the log's instants gone from the schedule."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from amsa_phys.api.source import load
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import Scenario

ROOT = Path(__file__).resolve().parent.parent.parent
FIG6 = ROOT / "scenarios" / "paper_fig6.yaml"


def fig6(**set_: Any) -> Scenario:
    """Fig. 6 for 6 s, with timeline changes between two log rows and two physics steps
    (the runs of physics steps must still stop there)."""
    doc = {
        "world": str(ROOT / "worlds" / "mde_challenge.yaml"),
        "duration": 6,
        "seed": 3,
        "quality": {
            "signal": "MyDistanceMonitor.distanceFollowerToLeader",
            "reference": 15,
            "tolerance": 1.5,
        },
        "set": {"Leader.behavior": 4, "Leader.cruisePower": 9.0, "Follower.x": 2.0, **set_},
        "timeline": [
            {"at": 2.035, "set": {"Leader.cruisePower": 30.0, "Follower.stallForce": 4.0}},
            {"at": 4.07, "set": {"MyNormalizePower.motorCoef": 40}},
        ],
    }
    return load(doc)


def snapshots(sim: Simulation, every: int = 7) -> list[tuple[bytes, list[Any]]]:
    """The store's bytes and the events after every ``every`` ticks up to the end."""
    sim.initialize()
    seen = []
    tick = 0
    while not sim.finished:
        tick += every
        sim.advance(tick)
        seen.append((sim.store.col.tobytes(), list(sim.events)))
    return seen


def test_a_run_without_its_log_is_the_same_run_bit_for_bit() -> None:
    scenario = fig6()
    kept = Simulation.from_scenario(scenario)
    dropped = Simulation.from_scenario(scenario, keep_log=False)
    assert snapshots(dropped) == snapshots(kept)
    assert kept.keeps_log
    assert not dropped.keeps_log
    # nothing is logged: no quality sample (a kept log has one per row)
    assert len(kept.result().samples_t) == 6 * 20 + 1
    assert len(dropped.result().samples_t) == 0
    # the schedule lost the log's instants: fewer table entries, none of them logging
    assert len(dropped._plan) < len(kept._plan)
    assert not any(entry[2] for entry in dropped._plan)


def test_a_collision_without_the_log_happens_at_the_same_instant() -> None:
    # the follower starts against the leader's back at full power: contacts inside what
    # is one batch of physics steps without the log's instants
    scenario = fig6(**{"Follower.x": 14.2, "MyFollowerController.Kv": 3.0})
    kept = Simulation.from_scenario(scenario)
    dropped = Simulation.from_scenario(scenario, keep_log=False)
    seen = snapshots(dropped, every=3)
    assert seen == snapshots(kept, every=3)
    assert any(e.kind == "collision" for e in seen[-1][1])


def test_a_trace_writer_or_an_early_listener_keeps_the_log() -> None:
    scenario = fig6()
    rows: list[float] = []
    traced = Simulation.from_scenario(
        scenario, keep_log=False, trace=lambda t, _row: rows.append(t)
    )
    traced.run()
    assert traced.keeps_log
    assert len(rows) == 6 * 20 + 1
    heard: list[float] = []
    listened = Simulation.from_scenario(scenario, keep_log=False)
    listened.add_log_listener(lambda t, _values: heard.append(t))
    listened.run()
    assert listened.keeps_log
    assert len(heard) == 6 * 20 + 1


def test_a_listener_added_once_a_run_without_log_started_is_refused() -> None:
    sim = Simulation.from_scenario(fig6(), keep_log=False)
    sim.advance(10)
    with pytest.raises(RuntimeError, match="keeps no log"):
        sim.add_log_listener(lambda t, _values: None)
