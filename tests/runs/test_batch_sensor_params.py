"""Sensor copies in one batch whose parameters differ (a sweep's axis): some quantise and
some do not, some have a latency and some not. Each row must still be its run's made
alone (the group's shortcuts for "every copy quantises" hold only when every copy does)."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.physics.step_path import extension
from amsa_phys.runs.batched import run_batch
from amsa_phys.runs.sweep import Axis, SweepPlan, run_job

ROOT = Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


@pytest.mark.skipif(extension() is None, reason="the compiled step was not built")
@pytest.mark.parametrize(
    "axis",
    [
        Axis("LeaderGPS.precision", (0.0, 0.5)),
        Axis("FollowerCompass.precision", (0.2, 0.0)),
        Axis("LeaderGPS.latency", (0.0, 0.5)),
    ],
    ids=["gps-precision", "compass-precision", "gps-latency"],
)
def test_mixed_sensor_parameters_in_one_batch_equal_the_runs_alone(
    tmp_path: Path, axis: Axis
) -> None:
    path = tmp_path / "s.yaml"
    path.write_text(
        f"world: {WORLD}\nduration: 12\nseed: 2\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15, "
        "tolerance: 1.5}\n"
        "set: {MyFollowerController.Kv: 0.3}\n"
    )
    jobs = SweepPlan(path, [axis], seeds=2, base_seed=7).jobs()
    stats: dict[str, int] = {}
    batched = run_batch(jobs, stats)
    # no run faulted inside the batch (a faulted run is made alone: its row would be right
    # but the batch's step of that sensor wrong)
    assert stats["faults"] == 0
    alone = [run_job(job) for job in jobs]
    assert all(not r["error"] for r in alone)
    for a, b in zip(alone, batched, strict=True):
        assert a == b
    # the parameter matters: the two values give different runs
    assert alone[0]["rms_error"] != alone[2]["rms_error"]
