"""The scenario's Timeline is the one owner of its phases, duration and plan: held, not rebuilt.

A Scenario used to rebuild a Timeline on every read and the Simulation built its own copy
without the planned bounds of a run cut short; now both hold the very same object.
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction
from pathlib import Path

from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import Change, load_scenario, shortened

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def test_a_scenario_holds_one_timeline_and_the_simulation_runs_that_one() -> None:
    scenario = load_scenario(SCENARIO1)
    assert scenario.timeline is scenario.timeline
    assert scenario.duration == scenario.timeline.duration == 500
    cut = shortened(scenario, Fraction(200))
    sim = Simulation.from_scenario(cut)
    assert sim.timeline is cut.timeline
    # the plan survives into the engine: the phase the run stops in is known to be partial
    assert sim.timeline.is_cut
    assert sim.timeline.bounds() == (0, 125, 250, 375, 500)
    assert sim.duration == 200


def test_the_phases_a_cut_run_enters_and_the_values_at_the_start() -> None:
    timeline = load_scenario(SCENARIO1).timeline
    assert [p.at for p in timeline.phases_before(250)] == [0, 125]
    assert [p.at for p in timeline.phases_before(Fraction(1, 10))] == [0]
    kv = Change("MyFollowerController", "Kv", 0.2)
    started = timeline.with_start([kv])
    assert started.initial == (kv,)  # in place of phase 0's, later phases kept
    assert started.phases[1:] == timeline.phases[1:]
    added = timeline.with_initial([kv])
    # the file's values but its Kv, then the given Kv (the one in force)
    assert added.initial[:-1] == tuple(c for c in timeline.initial if c.key != kv.key)
    assert added.initial[-1] == kv
    assert timeline.initial != started.initial  # frozen: the given one is untouched


def test_a_replaced_timeline_is_what_the_scenario_reports() -> None:
    scenario = load_scenario(SCENARIO1)
    shorter = dataclasses.replace(scenario, timeline=scenario.timeline.cut(Fraction(100)))
    assert shorter.duration == 100
    assert [p.at for p in shorter.timeline.phases] == [0]
    assert scenario.duration == 500
