"""Frozen specs and pure configuration (issue 32 item 3): nothing shared changes under a run."""

from __future__ import annotations

import dataclasses
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from amsa_phys.model.changes import set_frequency
from amsa_phys.model.metrics import METRICS, block_metrics
from amsa_phys.model.scenario import load_scenario, shortened
from amsa_phys.model.world import load_world
from amsa_phys.runs import sweep
from amsa_phys.runs.resolve import resolved_scenario
from amsa_phys.runs.sweep import Job, apply_setting, prepare_job

ROOT = Path(__file__).resolve().parent.parent.parent
SCEN = ROOT / "tests" / "fixtures" / "mde_short.yaml"


def test_world_and_leaf_specs_are_frozen() -> None:
    world = load_world(ROOT / "worlds" / "mde_challenge.yaml")
    leaf = next(iter(world.leaves.values()))
    with pytest.raises(dataclasses.FrozenInstanceError):
        leaf.freq = Fraction(3)  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        world.order = []  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        leaf.timing.latency = Fraction(1)  # type: ignore[misc]


def test_set_frequency_returns_a_new_world_and_leaves_the_shared_one() -> None:
    world = load_world(ROOT / "worlds" / "mde_challenge.yaml")
    path = "LeaderGPS"
    before = world.leaves[path]
    faster = set_frequency(f"{path}.freq", 8, world)
    assert faster.leaves[path].freq == 8
    assert world.leaves[path] is before
    assert before.freq != 8
    # the component tree carries the new Leaf too (describe and graph read it)
    tree = [c for c in faster.root.children if getattr(c, "path", None) == path]
    assert tree == [faster.leaves[path]]
    late = set_frequency(f"{path}.latency", "1/8", world)
    assert late.leaves[path].timing.latency == Fraction(1, 8)
    assert world.leaves[path].timing.latency == 0


def test_configuring_and_sweeping_never_change_the_loaded_scenario() -> None:
    base = load_scenario(SCEN)
    phases = [(p.at, list(p.changes), list(p.within)) for p in base.timeline.phases]
    world = base.world
    cut = shortened(base, Fraction(5))
    assert cut.duration == 5
    assert base.duration != 5
    swept = apply_setting(base, "MyFollowerController.Kv", 0.2)
    physics = apply_setting(base, "physics.ground.friction", 0.3)
    assert swept.timeline.initial[-1].value == 0.2
    assert physics.world.physics["ground"]["friction"] == 0.3
    assert [(p.at, list(p.changes), list(p.within)) for p in base.timeline.phases] == phases
    assert base.world is world
    assert world.physics["ground"]["friction"] != 0.3


def test_two_jobs_of_one_cached_scenario_do_not_see_each_others_values() -> None:
    def job(i: int, kv: float) -> Job:
        return Job(i, str(SCEN), (("MyFollowerController.Kv", kv),), 0, i + 1, (), 5.0)

    a, b = prepare_job(job(0, 0.1)), prepare_job(job(1, 0.3))
    # the job's own Kv in place of the file's: never the other job's
    assert [c.value for c in a.timeline.initial if c.param == "Kv"] == [0.1]
    assert [c.value for c in b.timeline.initial if c.param == "Kv"] == [0.3]
    assert (a.seed, b.seed) == (1, 2)


def test_a_scenario_is_frozen_down_to_its_sequences() -> None:
    scenario = load_scenario(SCEN)
    for name, value in (("seed", 3), ("timeline", None)):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(scenario, name, value)
    with pytest.raises(AttributeError):  # the duration is the timeline's: no second copy
        scenario.duration = Fraction(1)  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        scenario.timeline.duration = Fraction(1)  # type: ignore[misc]
    with pytest.raises(AttributeError):  # a tuple: nobody appends to a shared one
        scenario.timeline.phases.append(scenario.timeline.phases[0])  # type: ignore[attr-defined]
    with pytest.raises(AttributeError):
        scenario.expect.append(None)  # type: ignore[attr-defined]
    with pytest.raises(dataclasses.FrozenInstanceError):
        scenario.quality.reference = 1.0  # type: ignore[union-attr,misc]
    # a list given to the constructor (the builder's, a user's replace) is stored as a tuple
    again = dataclasses.replace(scenario, trace_columns=["*"])
    assert again.trace_columns == ("*",)


def test_runs_of_a_sweep_leave_its_cached_scenario_as_loaded() -> None:
    def job(i: int, point: tuple[tuple[str, object], ...]) -> Job:
        return Job(i, str(SCEN), point, 0, i + 1, (), 3.0)

    shared = sweep._shortened(str(SCEN), 3.0)  # what every job of this process starts from
    before = resolved_scenario(shared)
    timeline = shared.timeline
    rows = [
        sweep.run_job(job(0, (("MyFollowerController.Kv", 0.1),))),
        sweep.run_job(job(1, (("MyFollowerController.Kv", 0.3), ("physics.gravity", 3.0)))),
    ]
    assert [r["error"] for r in rows] == ["", ""]
    assert sweep._shortened(str(SCEN), 3.0) is shared  # the cache was used, not reloaded
    assert resolved_scenario(shared) == before  # world, parameters, timeline, expectations
    assert shared.timeline is timeline
    assert shared.seed == load_scenario(SCEN).seed


def test_every_metric_name_is_computed_and_no_other() -> None:
    t = np.linspace(0, 10, 101)
    out = block_metrics(t, 15 + np.sin(t), 0.0, 10.0, 15.0, 1.5, [])
    assert set(out) == set(METRICS)
