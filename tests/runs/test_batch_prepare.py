"""A batch prepares each grid point's scenario once and gives it each job's seed: every job's
scenario is the one ``prepare_job`` makes for it alone, and a point that breaks a rule is
every one of its jobs' error row."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.errors import AmsaError
from amsa_phys.runs.batched import prepare_jobs, run_batch
from amsa_phys.runs.sweep import Axis, SweepPlan, prepare_job

ROOT = Path(__file__).resolve().parents[2]
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"
CONTEXTS = {"calm": {"Leader.behavior": 1}, "lossy": {"LeaderGPS.lostDataGPS": 30}}


def _plan(kv: tuple[object, ...], duration: float = 2.0) -> SweepPlan:
    return SweepPlan(
        SCENARIO1,
        [Axis("context", tuple(CONTEXTS)), Axis("MyFollowerController.Kv", kv)],
        seeds=3,
        base_seed=11,
        contexts=CONTEXTS,
        duration=duration,
    )


def test_each_jobs_scenario_is_the_one_it_has_alone() -> None:
    jobs = _plan((0.05, 0.2)).jobs()
    prepared = prepare_jobs(jobs)
    assert len(prepared) == len(jobs) == 12
    for job, scenario in zip(jobs, prepared, strict=True):
        alone = prepare_job(job)
        assert not isinstance(scenario, str)
        assert scenario.seed == job.seed
        assert scenario == alone


def test_a_point_that_breaks_a_rule_is_each_of_its_jobs_error() -> None:
    jobs = _plan((0.05, "fast")).jobs()
    prepared = prepare_jobs(jobs)
    bad = [job for job in jobs if dict(job.point)["MyFollowerController.Kv"] == "fast"]
    assert len(bad) == 6
    for job, scenario in zip(jobs, prepared, strict=True):
        if job in bad:
            with pytest.raises((AmsaError, ValueError)) as alone:
                prepare_job(job)
            assert scenario == str(alone.value)
        else:
            assert scenario == prepare_job(job)
    rows = run_batch(jobs)
    assert [r["run"] for r in rows] == [j.index for j in jobs]
    assert all(r["error"] == prepared[i] for i, r in enumerate(rows) if jobs[i] in bad)
    assert all(r["error"] == "" for i, r in enumerate(rows) if jobs[i] not in bad)
