"""The engine's targets: batched sweeps, the 1,000-rover platoon, the API.

* batched sweep against the process pool, 1,000 runs of 60 s, for scenario1 and scenario2
  (random leader, GPS loss): 25 Kv values x 40 seeds; targets >= 5x the pool, and 1,000
  scenario2 runs <= 5 s on 2 cores. The pool is timed on ``--pool-runs`` spread over the
  same grid and scaled (its throughput is flat in the run count: one run per task); each
  sweep runs in a fresh interpreter;
* the platoon (``worlds/platoon.yaml``) at 200 and 1,000 rovers: CPU microseconds per
  rover-step (flat from 200 to 1,000) and real-time factor at 1,000 (target >= 40x);
* ``amsa_phys.run`` of scenario1 (300 s, trace in memory): real-time factor, CPU;
* the vector Gymnasium env (``FollowVecEnv``) at 1,000 envs: env-steps a second (CPU).

Run: ``python benchmarks/bench_engine.py [--reps 3] [--only batch platoon api vec]``. The
script uses only APIs that predate the column store, so the same file measures an older
checkout (``PYTHONPATH=/path/to/old python benchmarks/bench_engine.py``) in one sitting.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import yaml

if TYPE_CHECKING:
    from amsa_phys.runs.sweep import SweepPlan

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = {name: ROOT / "scenarios" / f"{name}.yaml" for name in ("scenario1", "scenario2")}
KV = tuple(round(0.02 + 0.015 * i, 4) for i in range(25))


def med(xs: list[float]) -> str:
    """``median (min..max)``."""
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def verdict(ok: bool) -> str:
    return "PASS" if ok else "MISS"


# -- batched sweeps ---------------------------------------------------------------------------
def sweep_plan(scenario: str, runs: int) -> SweepPlan:
    """The benchmarks' sweep: 25 Kv x seeds (``runs`` in all), 60 s runs of ``scenario``."""
    from amsa_phys.runs.sweep import Axis, SweepPlan

    return SweepPlan(
        SCENARIOS[scenario],
        [Axis("MyFollowerController.Kv", KV)],
        seeds=max(1, runs // len(KV)),
        base_seed=1,
        duration=60.0,
    )


def sweep(scenario: str, runs: int, workers: int, executor: str, limit: int) -> dict:
    """Wall and CPU seconds of one sweep (this process and its workers), 25 Kv x seeds,
    60 s runs."""
    from amsa_phys.runs.batched import iter_batched, plan_units
    from amsa_phys.runs.sweep import iter_local

    jobs = sweep_plan(scenario, runs).jobs()
    if limit:  # spread over the grid
        jobs = jobs[:: max(1, len(jobs) // limit)][:limit]
    cpu0 = _cpu()
    t0 = time.perf_counter()
    if executor == "local":
        rows = list(iter_local(jobs, workers))
    else:
        units, _ = plan_units(jobs, workers)
        rows = list(iter_batched(units, workers, iter_local))
    wall = time.perf_counter() - t0
    cpu = _cpu() - cpu0
    failed = sum(1 for r in rows if r["error"])
    return {"runs": len(rows), "wall": wall, "cpu": cpu, "failed": failed}


def _cpu() -> float:
    """CPU seconds of this process and of its children that have ended (the sweep's
    workers: the pool joins them before it returns)."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def measure(scenario: str, runs: int, workers: int, executor: str, limit: int = 0) -> dict:
    """:func:`sweep` in a fresh interpreter."""
    argv = [sys.executable, __file__, "--child", scenario, str(runs), str(workers), executor]
    argv.append(str(limit))
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run(argv, capture_output=True, text=True, check=True, env=env)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def batch(reps: int, runs: int = 1000, pool_runs: int = 200, j: int = 2) -> None:
    """Batched sweep vs process pool, scenario1 and scenario2."""
    for scenario in SCENARIOS:
        walls, ratios, cpu_ratios = [], [], []
        failed = 0
        for _ in range(reps):
            pool = measure(scenario, runs, j, "local", pool_runs)
            got = measure(scenario, runs, j, "batch")
            pool_wall = got["runs"] / (pool["runs"] / pool["wall"])
            walls.append(got["wall"])
            ratios.append(pool_wall / got["wall"])
            if "cpu" in got:  # CPU of the sweep and its workers: steadier on a busy machine
                pool_cpu = got["runs"] / (pool["runs"] / pool["cpu"])
                cpu_ratios.append(pool_cpu / got["cpu"])
            failed += got["failed"] + pool["failed"]
        print(
            f"{verdict(statistics.median(ratios) >= 5)}  {scenario} batched / pool -j {j}, "
            f"{runs} runs of 60 s: {med(ratios)}x (target >= 5x); failed rows {failed}",
            flush=True,
        )
        if cpu_ratios:
            print(f"info  {scenario} batched / pool, by CPU (all processes): {med(cpu_ratios)}x")
        print(
            f"{verdict(statistics.median(walls) <= 5)}  {scenario} batched, {runs} runs: "
            f"{med(walls)} s (target <= 5 s)",
            flush=True,
        )


# -- platoon -----------------------------------------------------------------------------------
def platoon_cost(cars: int, tmp: Path, duration: float) -> tuple[float, int]:
    """(CPU microseconds per rover-step, rovers) of the loop of a platoon run."""
    from amsa_phys.engine.runner import Simulation
    from amsa_phys.model.scenario import load_scenario

    world = yaml.safe_load((ROOT / "worlds" / "platoon.yaml").read_text())
    world["components"]["Car"]["count"] = cars
    (tmp / f"platoon{cars}.yaml").write_text(yaml.safe_dump(world))
    scen = tmp / f"platoon{cars}_scenario.yaml"
    scen.write_text(f"world: platoon{cars}.yaml\nduration: {duration}\nseed: 1\n")
    sim = Simulation.from_scenario(load_scenario(scen))
    sim.initialize()
    rovers = len(sim.shared["physics"].rovers)
    t0 = time.process_time()
    sim.run()
    cpu = time.process_time() - t0
    return cpu / (rovers * duration * 100) * 1e6, rovers


def platoon(reps: int) -> None:
    """Cost per rover-step at 200 and 1,000 rovers; real-time factor at 1,000."""
    costs: dict[int, list[float]] = {}
    with tempfile.TemporaryDirectory() as d:
        for _ in range(reps):  # interleaved: drifting load hits both sizes alike
            for cars, duration in ((199, 20.0), (999, 10.0)):
                cost, rovers = platoon_cost(cars, Path(d), duration)
                costs.setdefault(rovers, []).append(cost)
    for rovers, xs in costs.items():
        rt = [1e6 / (c * rovers * 100) for c in xs]
        print(f"info  platoon {rovers:4d} rovers: {med(xs)} us/rover-step, {med(rt)}x real time")
    growth = statistics.median(costs[1000]) / statistics.median(costs[200])
    print(
        f"{verdict(growth <= 1.05)}  platoon cost per rover-step 1,000 / 200 rovers: "
        f"{growth:.2f}x (target flat)",
        flush=True,
    )
    rt = [1e6 / (c * 1000 * 100) for c in costs[1000]]
    ok = statistics.median(rt) >= 40
    print(f"{verdict(ok)}  platoon 1,000 rovers: {med(rt)}x real time (CPU; target >= 40x)")


# -- the API -----------------------------------------------------------------------------------
def api(reps: int) -> None:
    """``amsa_phys.run`` of scenario1, 300 s, trace in memory: real-time factor by CPU."""
    import amsa_phys as ap

    ap.run(str(SCENARIOS["scenario1"]), duration=10)  # first-call costs out of the way
    rts = []
    for _ in range(reps):
        t0 = time.process_time()
        ap.run(str(SCENARIOS["scenario1"]), duration=300)
        rts.append(300 / (time.process_time() - t0))
    print(f"info  API run of scenario1 (300 s): {med(rts)}x real time (CPU)", flush=True)


# -- the vector env ----------------------------------------------------------------------------
def vec(reps: int, n: int = 1000, steps: int = 40) -> None:
    """Env-steps a second of ``FollowVecEnv`` with ``n`` envs, constant action (CPU)."""
    import numpy as np

    from amsa_phys.gym.vector import FollowVecEnv

    rates = []
    for i in range(reps):
        env = FollowVecEnv(n, str(SCENARIOS["scenario1"]), duration=300)
        env.reset(seed=i)
        actions = np.full((n, 2), 0.5)
        t0 = time.process_time()
        for _ in range(steps):
            env.step(actions)
        rates.append(n * steps / (time.process_time() - t0))
        env.close()
    ok = statistics.median(rates) >= 50000
    print(f"{verdict(ok)}  vector env, {n} envs: {med(rates)} env-steps/s (target >= 50,000)")


TARGETS = {"batch": batch, "platoon": platoon, "api": api, "vec": vec}


def main() -> None:
    """Measure and print."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--only", nargs="*", choices=list(TARGETS), default=list(TARGETS))
    ap.add_argument("--child", nargs=5, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        scenario, runs, workers, executor, limit = args.child
        print(json.dumps(sweep(scenario, int(runs), int(workers), executor, int(limit))))
        return
    import amsa_phys

    print(f"# {amsa_phys.__file__}; {os.cpu_count()} cores; median of {args.reps}", flush=True)
    for name in args.only:
        TARGETS[name](args.reps)


if __name__ == "__main__":
    main()
