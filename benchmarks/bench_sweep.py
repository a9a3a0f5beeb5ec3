"""Sweep throughput: runs per second at -j 1 and -j N, and the speed-up.

Run: ``python benchmarks/bench_sweep.py [--reps 3]``. The sweep is 16 runs of 60 s of the MDE
challenge (Kv × GPS noise × 2 seeds), executed through the same code as ``amsa-phys sweep``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

from amsa_phys.runs.sweep import Axis, SweepPlan, iter_local

ROOT = Path(__file__).resolve().parent.parent


def one(workers: int) -> float:
    """Runs per second of one sweep."""
    plan = SweepPlan(
        ROOT / "scenarios" / "scenario1.yaml",
        [
            Axis("MyFollowerController.Kv", (0.05, 0.1, 0.2, 0.35)),
            Axis("LeaderGPS.noise", (0.0, 0.5)),
        ],
        seeds=2,
        base_seed=1,
        duration=60.0,
    )
    jobs = plan.jobs()
    t0 = time.perf_counter()
    rows = list(iter_local(jobs, workers))
    wall = time.perf_counter() - t0
    assert all(not r["error"] for r in rows)
    return len(jobs) / wall


def main() -> None:
    """Measure and print."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args()
    cores = os.cpu_count() or 1
    single = [one(1) for _ in range(args.reps)]
    multi = [one(cores) for _ in range(args.reps)]
    for name, xs in (("-j 1", single), (f"-j {cores}", multi)):
        print(
            f"sweep {name:6s} median {statistics.median(xs):5.2f} runs/s "
            f"(min {min(xs):.2f}, max {max(xs):.2f})"
        )
    speedup = statistics.median(multi) / statistics.median(single)
    print(
        f"speed-up -j {cores} / -j 1: {speedup:.2f} (ideal {cores}; {args.reps} repetitions,"
        f" 16 runs of 60 s each)"
    )


if __name__ == "__main__":
    main()
