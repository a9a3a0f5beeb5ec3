"""A batch's set-up and end do each thing once: requirements judged once per set of samples,
a random stream made only for a component that draws.

Both are what makes a batched sweep's per-run cost, not what it computes: the verdicts and
streams must stay those of each run alone (checked here against a second, fresh judging and
against ``component_rng``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from amsa_phys.engine import multirun
from amsa_phys.engine.multirun import MultiRun
from amsa_phys.physics.columns import ColumnPhysics
from amsa_phys.runs.sweep import Axis, SweepPlan, prepare_job
from amsa_phys.stl import requirement

ROOT = Path(__file__).resolve().parents[2]
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def _batch(runs: int = 3, duration: float = 4.0) -> MultiRun:
    plan = SweepPlan(
        SCENARIO1,
        [Axis("MyFollowerController.Kv", (0.05, 0.2, 0.35)[:runs])],
        seeds=1,
        base_seed=7,
        duration=duration,
    )
    return MultiRun([prepare_job(job) for job in plan.jobs()], columns=ColumnPhysics())


def test_a_finished_batch_judges_its_requirements_once(monkeypatch: pytest.MonkeyPatch) -> None:
    calls = []
    real = requirement.judge

    def counting(*args, **kwargs):  # type: ignore[no-untyped-def]
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(requirement, "judge", counting)
    sim = _batch()
    first = sim.run().requirements  # run() ends with result(): run 0's verdicts
    shares = sim.outcomes()  # every run's: the same samples, not judged again
    assert len(calls) == 1
    assert shares[0].result.requirements == first
    # each caller has its own dicts: editing one run's verdicts changes no other answer
    shares[0].result.requirements["no_contact"]["verdict"] = "edited"
    again = sim.outcomes()
    assert again[0].result.requirements == first
    assert len(calls) == 1
    # the memo holds the fresh judging's verdicts for every run
    t, cols = sim.watch.sampler.table()
    fresh = real(sim.watch.requirements, t, cols, sim.watch.period, sim.watch.runs)
    assert [s.result.requirements for s in again] == fresh


def test_new_samples_are_judged_again(monkeypatch: pytest.MonkeyPatch) -> None:
    sim = _batch(runs=2, duration=30.0)
    sim.initialize()
    sim.advance(sim.grid.ticks(10))
    early = sim.outcomes()
    sim.advance(sim.grid.ticks(30))
    late = sim.outcomes()
    t, cols = sim.watch.sampler.table()
    fresh = requirement.judge(sim.watch.requirements, t, cols, sim.watch.period, 2)
    assert [s.result.requirements for s in late] == fresh
    assert len(late[0].result.samples_t) > len(early[0].result.samples_t)


def test_a_stream_is_made_only_for_a_component_that_draws(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    made: list[str] = []
    real = multirun.component_rng

    def counting(seed: int, path: str) -> np.random.Generator:
        made.append(path)
        return real(seed, path)

    monkeypatch.setattr(multirun, "component_rng", counting)
    sim = _batch(runs=2)
    sim.initialize()
    drawing = {"Leader", "LeaderGPS", "FollowerGPS", "FollowerCompass"}
    assert set(made) == drawing  # the controller, monitor, follower robot draw nothing
    assert len(made) == 2 * len(drawing)


def test_a_runs_stream_is_the_one_it_has_alone() -> None:
    sim = _batch(runs=2)
    for run, seed in enumerate(sim.seeds):
        ctx = multirun.RunContext(sim, "FollowerGPS", run)
        alone = multirun.component_rng(seed, "FollowerGPS")
        assert ctx.rng is ctx.rng  # made once
        np.testing.assert_array_equal(ctx.rng.random(5), alone.random(5))
    with pytest.raises(AttributeError):
        _ = multirun.RunContext(sim, "FollowerGPS", 0).nope
