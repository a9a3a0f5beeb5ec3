"""Batched sweeps: 1,000 and 10,000 runs of scenario1 (60 s each, Kv × context × seeds).

Run: ``python benchmarks/bench_batch.py [--runs 1000] [--pool-runs 200] [--big 10000]``.
Prints PASS/MISS lines for its targets and the ratio to today's process-pool
sweep (``--executor local``) measured in the same run. The pool is timed on ``--pool-runs``
spread over the same grid (its throughput is flat in the number of runs: one run per task) and
scaled to the batch's run count; the memory of each sweep is the largest resident set of
any of its processes, measured in a fresh interpreter per sweep.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"
CONTEXTS = {
    "nominal": {"Leader.behavior": 1},
    "degraded": {
        "Leader.behavior": 1,
        "LeaderGPS.lostDataGPS": 10,
        "MyNormalizePower.motorCoef": 60,
    },
    "random leader": {"Leader.behavior": 4, "LeaderGPS.lostDataGPS": 10},
    "lossy": {"LeaderGPS.lostDataGPS": 30, "FollowerGPS.lostDataGPS": 10},
}
KV = tuple(round(0.02 + 0.015 * i, 4) for i in range(25))


def plan(runs: int):  # type: ignore[no-untyped-def]
    """25 Kv × 4 contexts × ``runs / 100`` seeds of scenario1, 60 s each."""
    from amsa_phys.runs.sweep import Axis, SweepPlan

    seeds = max(1, runs // (len(KV) * len(CONTEXTS)))
    return SweepPlan(
        SCENARIO,
        [Axis("context", tuple(CONTEXTS)), Axis("MyFollowerController.Kv", KV)],
        seeds=seeds,
        base_seed=1,
        contexts=CONTEXTS,
        duration=60.0,
    )


def sweep(runs: int, workers: int, executor: str, limit: int | None = None) -> dict:
    """Wall time of one sweep (in this process and its workers) and what it did."""
    from amsa_phys.runs.batched import iter_batched, plan_units
    from amsa_phys.runs.sweep import iter_local

    jobs = plan(runs).jobs()
    if limit:  # spread over the grid: every context and Kv, as in the batched sweep
        jobs = jobs[:: max(1, len(jobs) // limit)][:limit]
    t0 = time.perf_counter()
    if executor == "local":
        rows = list(iter_local(jobs, workers))
    else:
        units, _ = plan_units(jobs, workers)
        rows = list(iter_batched(units, workers, iter_local))
    wall = time.perf_counter() - t0
    failed = sum(1 for r in rows if r["error"])
    return {"runs": len(rows), "wall": wall, "failed": failed}


def child(runs: int, workers: int, executor: str, limit: int | None) -> None:
    """One sweep in this fresh process; prints its numbers and the largest RSS (KiB)."""
    out = sweep(runs, workers, executor, limit)
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    out["rss_kib"] = max(own, kids)
    print(json.dumps(out))


def measure(
    runs: int, workers: int, executor: str, limit: int | None = None, pure: bool = False
) -> dict:
    """:func:`child` in a fresh interpreter (so RSS is this sweep's alone); ``pure``: with
    ``AMSA_PHYS_PURE=1`` (the numpy column forces, the pure step for runs made alone)."""
    argv = [sys.executable, __file__, "--child", str(runs), str(workers), executor]
    argv.append(str(limit) if limit else "0")
    env = {**os.environ, "AMSA_PHYS_PURE": "1"} if pure else None
    proc = subprocess.run(argv, capture_output=True, text=True, check=True, env=env)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def verdict(ok: bool) -> str:
    return "PASS" if ok else "MISS"


def main() -> None:
    """Measure and print."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=1000)
    ap.add_argument("--pool-runs", type=int, default=200)
    ap.add_argument("--big", type=int, default=10000, help="0: skip the 10,000-run sweep")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        runs, workers, executor, limit = args.child
        child(int(runs), int(workers), executor, int(limit) or None)
        return
    targets(args.runs, args.pool_runs, args.big, args.jobs)


def targets(runs: int = 1000, pool_runs: int = 200, big: int = 10000, j: int = 2) -> None:
    """Measure the batched sweep against the pool and print the PASS/MISS lines."""
    pool = measure(runs, j, "local", pool_runs)
    pool_rate = pool["runs"] / pool["wall"]
    batch = measure(runs, j, "batch")
    rate = batch["runs"] / batch["wall"]
    pool_wall = batch["runs"] / pool_rate
    print(
        f"process pool -j {j}: {pool['runs']} runs of 60 s in {pool['wall']:.2f} s "
        f"({pool_rate:.1f} runs/s; {batch['runs']} runs would take {pool_wall:.1f} s)"
    )
    print(
        f"batched -j {j}: {batch['runs']} runs of 60 s in {batch['wall']:.2f} s "
        f"({rate:.0f} runs/s, {rate * 60:,.0f}x real time in aggregate, "
        f"{batch['failed']} failed, RSS {batch['rss_kib'] / 1024:.0f} MiB)"
    )
    print(
        f"{verdict(batch['wall'] <= 5.0)} {batch['runs']:,} runs of scenario1 in "
        f"{batch['wall']:.2f} s on {j} cores (target <= 5 s)"
    )
    ratio = pool_wall / batch["wall"]
    print(f"{verdict(ratio >= 10)} batched / process pool -j {j}: {ratio:.1f}x (target >= 10x)")
    from amsa_phys.physics.compiled import columns_compiled

    if columns_compiled():  # what the compiled column forces bring, measured alongside
        pure = measure(runs, j, "batch", pure=True)
        print(
            f"batched -j {j}, pure path (AMSA_PHYS_PURE=1, numpy column forces): "
            f"{pure['runs']} runs in {pure['wall']:.2f} s; compiled "
            f"{pure['wall'] / batch['wall']:.1f}x faster"
        )
    if big:
        large = measure(big, j, "batch")
        grow = large["rss_kib"] / batch["rss_kib"]
        print(
            f"batched -j {j}: {large['runs']:,} runs in {large['wall']:.1f} s "
            f"({large['runs'] / large['wall']:.0f} runs/s, RSS {large['rss_kib'] / 1024:.0f} MiB)"
        )
        print(
            f"{verdict(large['wall'] <= 60)} {large['runs']:,} runs in {large['wall']:.1f} s "
            "(<= 60 s)"
        )
        print(
            f"{verdict(grow <= 1.5)} RSS {large['runs']:,} / {batch['runs']:,} runs: "
            f"{grow:.2f}x (target <= 1.5x)"
        )


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    main()
